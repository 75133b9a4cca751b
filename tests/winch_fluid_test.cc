// A winch cable in water and on the seabed (issue 34): its buoyancy (with
// and without a free surface) and the bed's contact follow the paid-out
// length L(t), the winch's work in the energy balance counts the
// buoyancy's, and the loads that need the material velocity (drag, added
// mass, the bed's damping and friction) are refused naming the field.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/scene/time_function.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::BuildStatus;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;
using ::testing::HasSubstr;

constexpr double kG = 9.81;
const double kPi = std::acos(-1.0);
// The steel line of tests/winch_test.cc: d = 20 mm, 7850 kg/m^3, E = 1e11
// Pa; sea water 1025 kg/m^3.
const double kArea = kPi * 0.02 * 0.02 / 4;
const double kMu = 7850 * kArea;         // 2.466 kg/m
const double kDisplaced = 1025 * kArea;  // 0.322 kg/m
const double kEa = 1e11 * kArea;

// A 200 kg hook (no volume: its wet weight is its weight) on a vertical
// line from a fixed winch at the origin (y up), `length` long, 10
// elements, axial Kelvin-Voigt damping 1 ms, from its static equilibrium,
// in water of `fluid` (a JSON object's members), the winch's speed
// `speed`.
std::string Lowering(double length, const std::string& speed, const std::string& fluid,
                     double duration, const std::string& integrator = "HHT") {
  return absl::StrCat(R"({"gravity": {"y": -9.81}, "model": "PLANAR",
    "fluid": {)", fluid, R"(},
    "cables": [{"name": "rope", "start": {"y": )", -length, R"(}, "direction": {"y": 1},
                "length": )", length, R"(, "elements": 10, "density": 7850,
                "youngs_modulus": 1e11, "diameter": 0.02, "damping": {"axial_time": 1e-3},
                "winch": {"speed": )", speed, R"(}}],
    "bodies": [{"name": "hook", "mass": 200, "inertia": {"x": 5, "y": 5, "z": 5},
                "position": {"y": )", -length - 0.3, R"(}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": )", length, R"(}},
               {"type": "PIN", "a": {"cable": "rope", "s": 0},
                "b": {"body": "hook", "point": {"y": 0.3}}}],
    "probes": [{"name": "winch", "cable": "rope", "s": )", length, R"(}],
    "solver": {"duration": )", duration, R"(, "step": 0.001, "output_interval": 0.25,
               "integrator": ")", integrator, R"(", "initial_state": "STATIC"}})");
}

// `json` with its first `from` replaced by `to`.
std::string Edit(std::string json, const std::string& from, const std::string& to) {
  const size_t at = json.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? json : json.replace(at, from.size(), to);
}

// Paying out at 0.4 m/s, reached at 0.5 s (L = L0 + 0.4 (t - 0.25) after).
const char kPayOut[] = R"({"ramp": {"slope": 0.8}, "sum": [{"ramp": {"slope": -0.8, "start": 0.5}}]})";

// (a) Slow lowering in still water filling all space: once the start's
// transient has decayed (by t = 2 s, as in winch_test.cc's vertical case:
// the axial mode decays as exp(-16 t)), the tension at the winch is the
// hook's weight and the line's submerged weight, (m + (mu - rho_f A) L(t))
// g: the material does not accelerate at constant speed. The cubic
// elements are exact for a tension linear in s, so the dry case's
// tolerance holds, 1e-6 of the tension (2.1 kN): the buoyancy is 3.2 N/m
// x 5 to 7 m, 7e-3 to 1e-2 of the tension, so a buoyancy left on the
// elements' initial length (5 m) would be 4.7 N (2e-3) off at 7 m.
TEST(WinchFluidTest, LoweringInStillWaterCarriesTheSubmergedWeight) {
  const Scene scene =
      SceneFromJson(Lowering(5, kPayOut, R"("density": 1025)", 5));
  CollectingSink sink;
  RunOk(scene, &sink);
  const TimeFunction& speed = scene.cables[0].winch.speed;
  int checked = 0;
  double worst = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t < 2) continue;
    const double l = 5 + speed.Integral(f.t);
    const double tension = (200 + (kMu - kDisplaced) * l) * kG;
    ASSERT_EQ(f.support_forces.size(), 1u);
    EXPECT_NEAR(f.support_forces[0].y(), tension, 1e-6 * tension) << "t = " << f.t;
    worst = std::max(worst, std::abs(f.support_forces[0].y() / tension - 1));
    ++checked;
  }
  EXPECT_EQ(checked, 13);
  std::printf("submerged lowering: tension relative error %.3g\n", worst);
}

// (c) Through the splash zone: the still water level 4 m below the winch,
// the line paid out from 2 m to 5.9 m; its end reaches the water at L = 4
// m (t = 5.25 s, the static stretch of 0.3 mm aside). The tension at the
// winch is (m + mu L) g less the buoyancy of the wet length, rho_f A g
// max(L - 4, 0): it grows by mu g per metre paid out in the air, (mu -
// rho_f A) g in the water. With the free surface each Gauss point is wet
// or dry by its own position (free_surface.h): the buoyancy differs from
// the exact wet length's by at most one point's share, rho_f A g w_g l
// (w_g <= 0.285 for 5 points, l = L / 10 <= 0.59 m: 0.53 N), and each
// point's switch rings the axial mode, damped as exp(-16 t), with an
// amplitude of the jump. Tolerance 1.1 N, twice the jump (5e-4 of the
// tension). Measured: 0.36 N. Without the free surface the line would be
// 12.6 N light at 2 m in the air; with the free surface's Gauss points
// left on the elements' initial length (0.2 m, a first version's
// CableSurfaceBuoyancy kept a copy of the elements) 8.7 N off.
// The splash zone's water: its still level 4 m below the winch.
const char kSplashFluid[] = R"("density": 1025, "still_water_level": -4, "free_surface": true)";

double SplashTolerance() { return 2 * 1025 * kArea * kG * 0.2847 * 0.59; }

TEST(WinchFluidTest, SplashZoneTensionChangesByTheDisplacedWeightPerMetre) {
  const Scene scene = SceneFromJson(Lowering(2, kPayOut, kSplashFluid, 10));
  CollectingSink sink;
  RunOk(scene, &sink);
  const TimeFunction& speed = scene.cables[0].winch.speed;
  int dry = 0, wet = 0;
  double worst = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t < 2) continue;
    const double l = 2 + speed.Integral(f.t);
    const double tension = (200 + kMu * l - kDisplaced * std::max(l - 4, 0.0)) * kG;
    EXPECT_NEAR(f.support_forces[0].y(), tension, SplashTolerance()) << "t = " << f.t;
    worst = std::max(worst, std::abs(f.support_forces[0].y() - tension));
    (l > 4 ? wet : dry) += 1;
  }
  EXPECT_EQ(dry + wet, 33);  // t = 2, 2.25, ..., 10
  EXPECT_GE(wet, 18);
  std::printf("splash zone: worst tension error %.3g N (tolerance %.3g N)\n", worst,
              SplashTolerance());
}

// (b) The energy balance through the splash zone: energy.total (which
// subtracts the winch's work, the free surface's buoyancy's share
// included) plus energy.damped is conserved up to what HHT removes (1e-3
// J on the dry crane, winch_energy_test.cc) and the free surface's
// switches: a Gauss point crossing the level within a step changes the
// force by rho_f A g w_g l <= 0.53 N over a step's 4e-4 m of travel, at
// most 2e-4 J each, for the ~20 points that cross. Bound 1e-2 J (1.3e-6
// of the 8 kJ of work). Measured 2.4e-4 J; without the buoyancy's share
// of the winch's power (CableSurfaceBuoyancy::AddExternalPower) 25.6 J.
TEST(WinchFluidTest, SplashZoneEnergyBalances) {
  const Scene scene = SceneFromJson(Lowering(2, kPayOut, kSplashFluid, 10));
  CollectingSink sink;
  RunOk(scene, &sink);
  const Frame& first = sink.frames().front();
  const Frame& last = sink.frames().back();
  const double lost = first.energy.total - last.energy.total - last.energy.damped;
  const double work = -last.energy_parts.loads;
  std::printf("splash zone: lost %.3g J of work %.6g J, damped %.3g J\n", lost, work,
              last.energy.damped);
  EXPECT_GT(std::abs(work), 7e3);  // the line and hook lowered, less the buoyancy
  EXPECT_LT(std::abs(lost), 1e-2);
}

// The free surface's share of the winch's power: at rest, ExternalPower -
// DampingPower is the explicit rate dE/dt|_q of the model's energy (as
// winch_energy_test.cc checks on the dry crane), here with the line
// crossing the still level (1 m below the winch, the line 2 m long), where
// the dry Gauss points' buoyancy changes with the elements' length. By
// central differences at 1e-3 and 5e-4 s, extrapolated. The rate is
// mostly the strain's (1.4 MW: the state is off its layout by 1e-4 m a
// coordinate); the free surface's share is 0.32 W (measured by leaving it
// out), and the tolerance, 1e-9 of the rate (1.4e-3 W), as the dry
// crane's 1e-10 but for the buoyancy's kinks, catches it. Measured:
// equal to 12 digits.
TEST(WinchFluidTest, FreeSurfacePotentialRateIsTheEnergysTimeDerivative) {
  const Scene scene = SceneFromJson(
      Lowering(2, kPayOut, R"("density": 1025, "still_water_level": -1, "free_surface": true)",
               2));
  auto model = MultibodyModel::Build(scene);
  ASSERT_TRUE(model.ok()) << model.status();
  const auto [rate, power] = testing::EnergyRateAndWinchPower(*model, 1.0);
  std::printf("dE/dt|_q %.12g W, ExternalPower - DampingPower %.12g W\n", rate, power);
  EXPECT_GT(std::abs(rate), 10);
  EXPECT_NEAR(power, rate, 1e-9 * std::abs(rate));
}

// Drag on the material: paying out at 0.4 m/s in still water, every
// material point of the vertical line sinks at the winch's speed (the
// mesh's nodes do not: node k of N moves at k / N of it, the winch's node
// not at all), so the tangential drag kt v^2 per metre (kt = rho C_dt pi d
// / 2, C_dt = 0.5: 16.1 kg/m^2, 2.58 N/m) holds the line up: the tension
// at the winch is (m + (mu - rho_f A) L) g - kt v^2 L, v = 0.4 (1 + T /
// EA) m/s the speed of the material leaving the winch, stretched (the
// stretch, 7e-5, is 2e-3 N of drag: left out, the check fails at 1.1e-6).
// Reeling in, the drag adds. As the still-water lowering, tolerance 1e-6
// of the tension (2e-3 N); drag on the mesh's velocity (a third of it,
// averaged) would be 10 N off.
TEST(WinchFluidTest, TangentialDragActsOnTheMaterialVelocity) {
  for (int sign : {+1, -1}) {
    const std::string speed = absl::StrCat(R"({"ramp": {"slope": )", 0.8 * sign,
                                           R"(}, "sum": [{"ramp": {"slope": )", -0.8 * sign,
                                           R"(, "start": 0.5}}]})");
    const Scene scene = SceneFromJson(
        Edit(Lowering(5, speed, R"("density": 1025)", 5), R"("winch": {"speed")",
             R"("hydrodynamics": {"tangential_drag": 0.5}, "winch": {"speed")"));
    CollectingSink sink;
    RunOk(scene, &sink);
    const double kt = 0.5 * 1025 * 0.5 * kPi * 0.02;
    const TimeFunction& winch_speed = scene.cables[0].winch.speed;
    int checked = 0;
    double worst = 0, damped_from = 0, damped_to = 0;
    for (const Frame& f : sink.frames()) {
      if (f.t < 2) continue;
      if (std::abs(f.t - 2) < 1e-9) damped_from = f.energy.damped;
      damped_to = f.energy.damped;
      const double l = 5 + winch_speed.Integral(f.t);
      // Every material point moves at the speed of the material leaving
      // the winch, 0.4 (1 + T / EA) (winch_test.cc's hook speed).
      const double weight = (200 + (kMu - kDisplaced) * l) * kG;
      const double v = 0.4 * (1 + weight / kEa);
      const double tension = weight - sign * kt * v * v * l;
      EXPECT_NEAR(f.support_forces[0].y(), tension, 1e-6 * tension) << "t = " << f.t;
      worst = std::max(worst, std::abs(f.support_forces[0].y() / tension - 1));
      ++checked;
    }
    EXPECT_EQ(checked, 13);
    // energy.damped from 2 to 5 s is the drag's power on the material, kt
    // v^3 per metre (1.03 W/m), over the line: kt v^3 int L dt, int L dt =
    // 15 +- 0.2 (4.75^2 - 1.75^2) m s (the axial damping's share is nil at
    // a steady speed: the material's strain does not change). Tolerance
    // 1e-3 (the stretch's 2e-4 in v^3); booked on the mesh's velocity it
    // would be a third.
    const double dissipated = kt * std::pow(0.4, 3) * (15 + sign * 0.2 * (4.75 * 4.75 - 1.75 * 1.75));
    EXPECT_NEAR(damped_to - damped_from, dissipated, 1e-3 * dissipated);
    std::printf("%s with tangential drag: tension relative error %.3g, damped %.6g J (drag's "
                "work on the material %.6g J)\n",
                sign > 0 ? "pay-out" : "reel-in", worst, damped_to - damped_from, dissipated);
  }
}

// The energy balance with drag in a current through the splash zone: the
// drag's power on the material, -int q . v dx, is energy.damped's (the
// current's work with it; the test above checks that share), and what the
// winch feeds through the moving mesh (f . edot + P_d) the winch's work:
// so energy.total + energy.damped is conserved as without drag (bound of
// the splash-zone test, 1e-2 J; measured 2.7e-4 J). The balance checks
// that the force the steppers apply is the one the winch's power books
// (the split between damped and the winch's work cancels in it).
TEST(WinchFluidTest, SplashZoneEnergyBalancesWithDragInACurrent) {
  const Scene scene = SceneFromJson(Edit(
      Lowering(2, kPayOut, absl::StrCat(kSplashFluid, R"(, "current": {"x": 0.5})"), 10),
      R"("winch": {"speed")",
      R"("hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.5}, "winch": {"speed")"));
  CollectingSink sink;
  RunOk(scene, &sink);
  const Frame& first = sink.frames().front();
  const Frame& last = sink.frames().back();
  const double lost = first.energy.total - last.energy.total - last.energy.damped;
  std::printf("splash zone with drag: lost %.3g J of work %.6g J, damped %.6g J\n", lost,
              -last.energy_parts.loads, last.energy.damped);
  EXPECT_GT(std::abs(last.energy.damped), 1);  // the drag does work
  EXPECT_LT(std::abs(lost), 1e-2);
}

// (d) Paying out onto the seabed: a chain-like line (steel, d = 50 mm,
// bending NONE: w = (7850 - 1025) g pi d^2 / 4 = 131.5 N/m in water, EA =
// 1.96e8 N, 50 elements) from a fixed winch 20 m above a flat bed to an
// anchor on the bed 30 m away, laid on the bed for 9 m and then straight
// up to the winch (38 m). The bed (k = 1e5 N/m^2) sits w / k = 1.3 mm
// above y = -20, so that a grounded line rests at the anchor's height.
// The winch pays 1.5 m out, rests 23 s, pays 1.5 m more and rests (0.25
// m/s; Rayleigh alpha 0.5 /s on the material's motion settles the swing,
// the energy of the pay-out's swing falling by exp(-11) over the rest).
// At the end of each rest (t = 29 and 60 s, L = 39.5 and 41 m) and at the
// static start the line is the inextensible catenary with touchdown and
// no friction: with a = H / w, the suspended length Ls = sqrt(h^2 + 2 h
// a), its span a asinh(Ls / a), and L - Ls + a asinh(Ls / a) = X fixes a
// (the grounded length grows from 2.2 to 13.4 m). The winch holds (H, w
// Ls), the anchor nothing vertical, and the bed carries the grounded
// length's weight w (L - Ls): the line's weight less the joints' vertical
// reactions. The reference's errors: the stretch (T / EA <= 2.5e-5, 1 mm
// of line, 0.4 N on w Ls at most), the mesh (0.4 N between 50 and 100
// elements, measured). Tolerance 3 N (1e-3 of w Ls, 3e-3 of the smallest
// grounded weight); measured 1.2 N at most. A bed integrated over the
// elements' initial length (38 m / 50) would carry 4 % too little at L =
// 39.5 m (43 N); a winch whose mesh lagged L(t) would carry 1.5 m x 131.5
// N/m less on the bed and more on the winch.
struct Catenary {
  double horizontal, suspended;  // H [N], Ls [m]
};
Catenary Touchdown(double w, double h, double span, double length) {
  double lo = 1e-6, hi = 1e6;  // a [m]: the span rises with a
  for (int i = 0; i < 200; ++i) {
    const double a = std::sqrt(lo * hi);
    const double ls = std::sqrt(h * h + 2 * h * a);
    (length - ls + a * std::asinh(ls / a) < span ? lo : hi) = a;
  }
  const double a = std::sqrt(lo * hi);
  return {w * a, std::sqrt(h * h + 2 * h * a)};
}

TEST(WinchFluidTest, PayingOutOntoTheSeabedTheBedCarriesTheGroundedWeight) {
  const double d = 0.05, area = kPi * d * d / 4, w = (7850 - 1025) * area * kG;
  const double length0 = 38;  // 9 m on the bed, 29 m up to the winch
  const Scene scene = SceneFromJson(absl::StrCat(R"({"gravity": {"y": -9.81}, "model": "PLANAR",
    "fluid": {"density": 1025},
    "seabed": {"depth": )", absl::StrFormat("%.17g", 20 - w / 1e5),
                                                 R"(, "normal": {"y": 1}, "stiffness": 1e5},
    "cables": [{"name": "line", "points": [{"x": -30, "y": -20}, {"x": -21, "y": -20},
                                           {"x": 0, "y": 0}],
                "elements": 50, "density": 7850, "youngs_modulus": 1e11, "diameter": 0.05,
                "bending": "NONE", "damping": {"axial_time": 1e-3, "rayleigh_alpha": 0.5},
                "winch": {"speed": {"table": {"times": [0, 1, 6, 7, 30, 31, 36, 37],
                    "values": [0, 0.25, 0.25, 0, 0, 0.25, 0.25, 0]}}}}],
    "joints": [{"name": "anchor", "type": "PIN", "a": {"cable": "line", "s": 0}},
               {"name": "winch", "type": "PIN", "a": {"cable": "line", "s": )",
               absl::StrFormat("%.17g", length0), R"(}}],
    "output": {"reactions": true},
    "solver": {"duration": 60, "step": 0.01, "output_interval": 1,
               "initial_state": "STATIC"}})"));
  EXPECT_NEAR(scene.cables[0].length_m, length0, 1e-12);
  CollectingSink sink;
  RunOk(scene, &sink);
  int checked = 0;
  for (const Frame& f : sink.frames()) {
    // The rests' ends (and the start, from the static solution).
    if (!(f.t == 0 || std::abs(f.t - 29) < 1e-9 || std::abs(f.t - 60) < 1e-9)) continue;
    const double length = length0 + scene.cables[0].winch.speed.Integral(f.t);
    const Catenary c = Touchdown(w, 20, 30, length);
    ASSERT_EQ(f.reactions.size(), 2u);
    const Eigen::Vector3d anchor = f.reactions[0].force, winch = f.reactions[1].force;
    const double bed = w * length - winch.y() - anchor.y();
    std::printf("t = %g s, L = %.4f m: bed %.3f N (grounded weight %.3f N), winch (%.3f, %.3f) "
                "N (catenary (%.3f, %.3f) N), anchor (%.3f, %.3f) N\n",
                f.t, length, bed, w * (length - c.suspended), winch.x(), winch.y(),
                c.horizontal, w * c.suspended, anchor.x(), anchor.y());
    EXPECT_NEAR(bed, w * (length - c.suspended), 3) << "t = " << f.t;
    // The bed's own account: a grounded line at rest penetrates by w / k,
    // storing w^2 / (2 k) per metre, so energy.contact gives the grounded
    // length, short by the touchdown's boundary layer, where the
    // penetration ramps up over ~sqrt(H / k) = 0.11 to 0.17 m. Tolerance
    // 0.25 m; measured 0.08 m at most.
    const double grounded = 2 * 1e5 * f.energy.contact / (w * w);
    std::printf("  grounded length from energy.contact %.4f m, catenary %.4f m\n", grounded,
                length - c.suspended);
    EXPECT_NEAR(grounded, length - c.suspended, 0.25) << "t = " << f.t;
    EXPECT_NEAR(winch.y(), w * c.suspended, 3) << "t = " << f.t;
    EXPECT_NEAR(winch.x(), c.horizontal, 3) << "t = " << f.t;
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

// Added mass and the bed's damping and friction act on the material's
// velocity or acceleration, which on a winch cable is not the mesh's:
// refused in DYNAMIC runs, naming the field; accepted in STATIC (L fixed).
// Drag on the material velocity is modelled in a current, refused in
// waves.
TEST(WinchFluidValidationTest, RefusesTheVelocityLoadsNamingTheField) {
  const std::string base = Lowering(5, kPayOut, R"("density": 1025)", 5);
  EXPECT_TRUE(BuildStatus(base).ok());
  const std::string winch = R"("winch": {"speed")";
  auto hydro = [&](const std::string& h) {
    return Edit(base, winch, absl::StrCat(R"("hydrodynamics": )", h, ", ", winch));
  };
  // Drag is WinchCables' in a current, refused in waves.
  EXPECT_TRUE(BuildStatus(hydro(R"({"normal_drag": 1.2, "tangential_drag": 0.01})")).ok());
  const std::string waves = R"("waves": {"regular": [{"height": 1, "period": 8}]}, )";
  auto in_waves = [&](const std::string& h) {
    return Edit(Edit(hydro(h), R"("density": 1025)", absl::StrCat(waves, R"("density": 1025)")),
                R"("fluid": {)", R"("fluid": {"water_depth": 50, )");
  };
  EXPECT_TRUE(BuildStatus(in_waves(R"({"diameter": 0.02})")).ok());
  absl::Status s = BuildStatus(in_waves(R"({"normal_drag": 1.2})"));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("cables[0].hydrodynamics.normal_drag: drag on a winch "
                                     "cable in waves is not modelled"));
  s = BuildStatus(in_waves(R"({"tangential_drag": 0.01})"));
  EXPECT_THAT(s.message(), HasSubstr("cables[0].hydrodynamics.tangential_drag: drag on a winch"));
  s = BuildStatus(hydro(R"({"added_mass": 1})"));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("cables[0].hydrodynamics.added_mass: added mass on a winch "
                                     "cable is not modelled"));
  s = BuildStatus(hydro(R"({"axial_added_mass": 0.5})"));
  EXPECT_THAT(s.message(), HasSubstr("cables[0].hydrodynamics.axial_added_mass"));
  // A diameter alone (buoyancy on it) is fine.
  EXPECT_TRUE(BuildStatus(hydro(R"({"diameter": 0.03})")).ok());
  // STATIC: L stays fixed, the material moves with the mesh.
  EXPECT_TRUE(BuildStatus(Edit(hydro(R"({"normal_drag": 1.2, "added_mass": 1})"),
                            R"("initial_state": "STATIC")", R"("analysis": "STATIC")"))
                  .ok());
  const std::string bed = R"("seabed": {"depth": 20, "normal": {"y": 1}, "stiffness": 1e5)";
  auto with_bed = [&](const std::string& more) {
    return Edit(base, R"("fluid")", absl::StrCat(bed, more, "}, \"fluid\""));
  };
  EXPECT_TRUE(BuildStatus(with_bed("")).ok());
  s = BuildStatus(with_bed(R"(, "damping": 100)"));
  EXPECT_THAT(s.message(), HasSubstr("seabed.damping: the seabed's damping and friction on a "
                                     "winch cable (cables[0].winch)"));
  s = BuildStatus(with_bed(R"(, "friction_axial": 0.5)"));
  EXPECT_THAT(s.message(), HasSubstr("seabed.friction_axial:"));
  s = BuildStatus(with_bed(R"(, "friction_transverse": 0.5)"));
  EXPECT_THAT(s.message(), HasSubstr("seabed.friction_transverse:"));
}

}  // namespace
}  // namespace cablesim
