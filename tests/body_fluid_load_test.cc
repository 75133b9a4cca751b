// The fluid's load on rigid bodies (engine/forces/body_fluid_load.h): a
// floating cylinder rests at the draft where buoyancy balances its weight
// and heaves with the period of its mass, added mass and waterplane
// stiffness; a held body in a regular Airy wave feels the closed-form
// Morison drag and inertia (and, piercing the surface, the buoyancy of
// the wave elevation); the drag's tangent is its velocity derivative; the
// energy balance closes with drag and waves; validation names the fields.

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/forces/waves.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81, kRho = 1025;

using ::testing::HasSubstr;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// The floating cylinder: d = 2 m, H = 4 m, 5000 kg, heave added mass 0.8.
constexpr double kD = 2, kH = 4, kMass = 5000, kCav = 0.8;
const double kArea = kPi * kD * kD / 4;
// Draft where rho g A s = m g, and the centre's height there.
const double kDraft = kMass / (kRho * kArea);
const double kZeq = kH / 2 - kDraft;

// One body (spatial, gravity -z; planar, gravity -y) in still water with
// the given hydrodynamics, waves and solver; `vertical` is its centre's
// height.
std::string BuoyJson(bool planar, double vertical, const std::string& hydro,
                     const std::string& fluid_extra, const std::string& solver,
                     const std::string& extra = "") {
  const char* up = planar ? "y" : "z";
  return absl::StrFormat(R"({
    "gravity": {"%s": -9.81},
    "fluid": {"density": %.17g %s},
    "bodies": [{"name": "buoy", "mass": %.17g, "inertia": {"x": 4000, "y": 6000, "z": 6000},
                "position": {"%s": %.17g}, "hydrodynamics": %s}],
    "probes": [{"name": "b", "body": "buoy"}],
    "solver": %s %s})",
                         up, kRho, fluid_extra, kMass, up, vertical, hydro, solver, extra);
}

std::string Hydro(double cd = 0, double cdv = 0, double ca = 0, double cav = kCav) {
  return absl::StrFormat(
      R"({"diameter": %.17g, "height": %.17g, "drag_coefficient": %.17g,
          "heave_drag_coefficient": %.17g, "added_mass": %.17g, "heave_added_mass": %.17g})",
      kD, kH, cd, cdv, ca, cav);
}

// The generalized force f (on the model's z) on the first body's centre,
// the first 3 full coordinates: f . dz/dr_c (S^T maps r_c to z).
Eigen::Vector3d ForceOnCentre(const MultibodyModel& model, const Eigen::VectorXd& f) {
  const int n = model.dofs(), nq = model.coordinates();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n), col(nq);
    e(j) = 1;
    model.RateToFull(e, &col);
    force += f(j) * col.head<3>();
  }
  return force;
}

// Statics from the centre at the still level (too much buoyancy): the body
// settles where buoyancy balances weight. Buoyancy is linear in the height
// while the body pierces the surface, so Newton lands on it to rounding.
TEST(BodyFluidLoadTest, FloatsAtTheDraftWhereBuoyancyBalancesWeight) {
  for (bool planar : {true, false}) {
    SCOPED_TRACE(planar ? "planar" : "spatial");
    const Scene scene =
        SceneFromJson(BuoyJson(planar, 0, Hydro(), "", R"({"analysis": "STATIC"})"));
    CollectingSink sink;
    RunOk(scene, &sink);
    ASSERT_FALSE(sink.frames().empty());
    const Eigen::Vector3d r = sink.frames().back().probes[0].position_m;
    std::printf("centre %.15g m, closed form %.15g m (draft %.9g m)\n", r(planar ? 1 : 2), kZeq,
                kDraft);
    EXPECT_NEAR(r(planar ? 1 : 2), kZeq, 1e-9 * kH);
    EXPECT_NEAR(r(0), 0, 1e-12);
  }
}

// Started at its floating equilibrium with a heave velocity of 0.1 m/s
// (amplitude 0.053 m, well inside the hull), the body is an undamped linear
// oscillator of period T = 2 pi sqrt((m + C_av rho A s) / (rho g A)).
// Generalized-alpha at rho_infinity 1 is the trapezoidal rule, whose period
// elongation is (omega h)^2 / 12 = 8.2e-5 at h = T / 200; zero crossings
// interpolated linearly between steps add O((omega h)^3). Tolerance 2e-4.
TEST(BodyFluidLoadTest, HeavesWithTheHydrostaticPeriod) {
  const double added = kCav * kRho * kArea * kDraft;
  const double period = 2 * kPi * std::sqrt((kMass + added) / (kRho * kG * kArea));
  const double h = period / 200;
  const Scene scene = SceneFromJson(BuoyJson(
      false, kZeq, Hydro(), "",
      absl::StrFormat(R"({"duration": %.17g, "step": %.17g, "integrator": "GENERALIZED_ALPHA",
                          "rho_infinity": 1})",
                      4 * period, h),
      R"(, "initial_velocity": {"linear": {"z": 0.1}})"));
  CollectingSink sink;
  RunOk(scene, &sink);
  std::vector<double> up_crossings;
  const auto& frames = sink.frames();
  for (size_t i = 1; i < frames.size(); ++i) {
    const double z0 = frames[i - 1].probes[0].position_m.z() - kZeq;
    const double z1 = frames[i].probes[0].position_m.z() - kZeq;
    if (z0 < 0 && z1 >= 0)
      up_crossings.push_back(frames[i - 1].t + (frames[i].t - frames[i - 1].t) * -z0 / (z1 - z0));
  }
  ASSERT_GE(up_crossings.size(), 3u);
  const double measured =
      (up_crossings.back() - up_crossings.front()) / (up_crossings.size() - 1);
  std::printf("heave period %.9g s, measured %.9g s (relative %.3g)\n", period, measured,
              measured / period - 1);
  EXPECT_NEAR(measured / period, 1, 2e-4);
}

// A body held still in a regular wave (h = 20 m, H = 2 m, T = 8 s, phase
// 0.3, current 0.3 m/s along x): the generalized force on its centre is
// Morison's with the Airy kinematics at the centre (Dean and Dalrymple eq.
// 4.13), written here from the closed forms, drag and inertia with
// separate coefficients across and along the vertical; piercing the
// surface, the wave elevation adds rho g A eta. Tolerance 1e-12 of the
// force: the same sums in another order.
TEST(BodyFluidLoadTest, HeldBodyFeelsTheClosedFormMorisonForceInAnAiryWave) {
  constexpr double kDepth = 20, kHeight = 2, kPeriod = 8, kPhase = 0.3, kU = 0.3, kX = 3;
  constexpr double kCd = 1.1, kCdv = 2.5, kCa = 0.9;
  const double omega = 2 * kPi / kPeriod;
  const double k = WaveField::Wavenumber(omega, kDepth, kG);
  const double a = kHeight / 2;
  const std::string fluid = absl::StrFormat(
      R"(, "current": {"x": %.17g}, "water_depth": %.17g,
         "waves": {"regular": [{"height": %.17g, "period": %.17g, "phase": %.17g}]})",
      kU, kDepth, kHeight, kPeriod, kPhase);
  // Centre heights: fully submerged (-5: the wave never uncovers it) and
  // piercing (0.2: the kinematics are those at the still level).
  for (double zc : {-5.0, 0.2}) {
    SCOPED_TRACE(absl::StrFormat("centre at %g", zc));
    const std::string json = BuoyJson(false, zc, Hydro(kCd, kCdv, kCa, kCav), fluid,
                                      R"({"duration": 1})");
    std::string moved = json;
    moved.replace(moved.find(R"("position": {"z")"), 16,
                  absl::StrFormat(R"("position": {"x": %.17g, "z")", kX));
    auto model = MultibodyModel::Build(SceneFromJson(moved));
    ASSERT_TRUE(model.ok()) << model.status();
    const int n = model->dofs(), nq = model->coordinates();
    Eigen::VectorXd q(nq), qd = Eigen::VectorXd::Zero(nq), f(n);
    model->ToFull(model->initial_z(), &q);
    const double s = std::clamp(kH / 2 - zc, 0.0, kH);
    const double z = std::min(zc, 0.0);
    const double ch = std::cosh(k * (z + kDepth)) / std::sinh(k * kDepth);
    const double sh = std::sinh(k * (z + kDepth)) / std::sinh(k * kDepth);
    for (double t : {0.7, 2.9, 5.3, 7.1}) {
      model->SetTime(t);
      f.setZero();
      model->DampingForce(q, qd, &f);
      const Eigen::Vector3d force = ForceOnCentre(*model, f);
      const double theta = k * kX - omega * t + kPhase;
      const double ux = kU + a * omega * ch * std::cos(theta);
      const double uz = a * omega * sh * std::sin(theta);
      const double ax = a * omega * omega * ch * std::sin(theta);
      const double az = -a * omega * omega * sh * std::cos(theta);
      const double eta = a * std::cos(theta);
      const double s_wave = std::clamp(kH / 2 - (zc - eta), 0.0, kH);
      Eigen::Vector3d expected;
      expected.x() = 0.5 * kRho * kCd * kD * s * std::abs(ux) * ux +
                     kRho * kArea * s * (1 + kCa) * ax;
      expected.y() = 0;
      expected.z() = 0.5 * kRho * kCdv * kArea * std::abs(uz) * uz +
                     kRho * kArea * s * (1 + kCav) * az + kRho * kG * kArea * (s_wave - s);
      const double scale = expected.lpNorm<Eigen::Infinity>();
      EXPECT_LT((force - expected).lpNorm<Eigen::Infinity>(), 1e-12 * scale)
          << "t " << t << ": " << force.transpose() << " vs " << expected.transpose();
      if (zc > 0) {
        // Piercing: the wave's buoyancy is rho g A eta exactly.
        EXPECT_NEAR(kRho * kG * kArea * (s_wave - s), kRho * kG * kArea * eta, 1e-9);
      }
    }
    // The drag's tangent is -df/d(zdot) (central differences), and the
    // damping power is the load's work.
    double size = 0;
    const double error = testing::DampingTangentError(*model, Eigen::VectorXd(), 1e-6, &size);
    EXPECT_LT(error, 1e-6 * size);
  }
}

// A rod (along_axis): a horizontal cylinder (axis x, d 0.5 m, 4 m, 300 kg)
// wholly under water, released from rest, rises across its axis: the
// added mass is its transverse coefficient, C_a = 1, not the heave one
// (0.3, along the axis), so it accelerates at the constant
// a = (rho V - m) g / (m + C_a rho V) (Newton's second law with
// Archimedes). z(t) = z0 + a t^2 / 2 is quadratic, which the trapezoidal
// rule (generalized-alpha at rho_infinity 1) integrates exactly: tolerance
// 1e-9 of the rise (Newton's tolerance). The vertical law would give
// a = (rho V - m) g / (m + 0.3 rho V), 37 % more.
TEST(BodyFluidLoadTest, RodAlongItsAxisRisesWithItsTransverseAddedMass) {
  const double d = 0.5, length = 4, mass = 300, volume = kPi * d * d / 4 * length;
  const std::string json = absl::StrFormat(R"({
    "gravity": {"z": -9.81}, "fluid": {"density": %.17g},
    "bodies": [{"name": "rod", "mass": %.17g, "inertia": {"x": 10, "y": 400, "z": 400},
                "position": {"z": -20}, "axis": {"x": 1},
                "hydrodynamics": {"diameter": %.17g, "height": %.17g, "added_mass": 1,
                                  "heave_added_mass": 0.3, "along_axis": true}}],
    "probes": [{"name": "c", "body": "rod"}],
    "solver": {"duration": 1, "step": 0.01, "integrator": "GENERALIZED_ALPHA",
               "rho_infinity": 1}})",
                                           kRho, mass, d, length);
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_FALSE(sink.frames().empty());
  const double a = (kRho * volume - mass) * kG / (mass + kRho * volume);
  const Frame& last = sink.frames().back();
  const double rise = last.probes[0].position_m.z() + 20;
  std::printf("rise in %.3g s: %.12g m, closed form %.12g m\n", last.t, rise,
              a * last.t * last.t / 2);
  EXPECT_NEAR(rise, a * last.t * last.t / 2, 1e-9 * rise);
  EXPECT_NEAR(last.probes[0].position_m.x(), 0, 1e-12);
}

// The drag along a tilted rod's axis: the damping tangent is -df/d(zdot)
// (central differences) and the force splits across and along the axis.
TEST(BodyFluidLoadTest, RodDragSplitsAlongItsAxis) {
  auto model = MultibodyModel::Build(SceneFromJson(R"({
    "gravity": {"z": -9.81}, "fluid": {"density": 1025, "current": {"x": 0.7, "z": 0.2}},
    "bodies": [{"name": "rod", "mass": 300, "inertia": {"x": 10, "y": 400, "z": 400},
                "position": {"z": -20}, "axis": {"x": 1, "z": 1},
                "hydrodynamics": {"diameter": 0.5, "height": 4, "drag_coefficient": 1.2,
                                  "heave_drag_coefficient": 0.4, "along_axis": true}}],
    "solver": {"duration": 1}})"));
  ASSERT_TRUE(model.ok()) << model.status();
  const int nq = model->coordinates();
  Eigen::VectorXd q(nq), qd = Eigen::VectorXd::Zero(nq), f = Eigen::VectorXd::Zero(model->dofs());
  model->ToFull(model->initial_z(), &q);
  model->DampingForce(q, qd, &f);
  const Eigen::Vector3d force = ForceOnCentre(*model, f);
  // The current (0.7, 0, 0.2) against the axis (1, 0, 1)/sqrt(2): along
  // it 0.9/sqrt(2) m/s, across it the rest; the drag on 0.5 x 4 m across
  // and on the end area along.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 0, 1).normalized();
  const Eigen::Vector3d v(0.7, 0, 0.2);
  const Eigen::Vector3d along = v.dot(axis) * axis, across = v - along;
  const Eigen::Vector3d expected =
      0.5 * kRho * 1.2 * 0.5 * 4 * across.norm() * across +
      0.5 * kRho * 0.4 * (kPi * 0.25 / 4) * along.norm() * along;
  EXPECT_LT((force - expected).norm(), 1e-12 * expected.norm())
      << force.transpose() << " vs " << expected.transpose();
  double size = 0;
  const double error = testing::DampingTangentError(*model, Eigen::VectorXd(), 1e-6, &size);
  EXPECT_LT(error, 1e-6 * size);
}

// The hydrostatic force is minus the gradient of the energy in the loads'
// part, and its tangent rho g A on the vertical (central differences).
TEST(BodyFluidLoadTest, BuoyancyIsTheGradientOfItsEnergy) {
  for (double zc : {-3.5, -1.0, 0.4, 1.9, 3.0}) {
    SCOPED_TRACE(zc);
    auto model = MultibodyModel::Build(
        SceneFromJson(BuoyJson(false, zc, Hydro(), "", R"({"duration": 1})")));
    ASSERT_TRUE(model.ok()) << model.status();
    const int nq = model->coordinates();
    Eigen::VectorXd q(nq), qd = Eigen::VectorXd::Zero(nq);
    model->ToFull(model->initial_z(), &q);
    constexpr double kStep = 1e-5;
    const double force = kRho * kG * kArea * std::clamp(kH / 2 - zc, 0.0, kH);
    Eigen::VectorXd up = q, down = q;
    up(2) += kStep;
    down(2) -= kStep;
    const double buoyancy_energy_rate =
        (model->Energy(up, qd, 1).potential - model->Energy(down, qd, 1).potential) /
            (2 * kStep) -
        kMass * kG;  // the potential includes gravity m g z
    EXPECT_NEAR(-buoyancy_energy_rate, force, 1e-6 * force + 1e-3);
    // Its energy, rho g A P(z), is the loads' part.
    const double hz = kH / 2;
    const double p = zc >= hz    ? 0.0
                     : zc > -hz ? 0.5 * (zc - hz) * (zc - hz)
                                : 0.5 * kH * kH - kH * (zc + hz);
    EnergyParts parts;
    model->Energy(q, qd, 1, &parts);
    EXPECT_NEAR(parts.loads, kRho * kG * kArea * p, 1e-12 * kRho * kG * kArea * kH * kH);
  }
}

// A body bobbing and drifting with drag across and along the vertical, in
// still water and then in waves: energy.total + energy.damped stays what
// it was (the damping power integrated by the trapezoidal rule: second
// order, so halving the step quarters the drift).
TEST(BodyFluidLoadTest, EnergyBalanceClosesWithDragAndWaves) {
  for (const std::string& waves :
       {std::string(), std::string(R"(, "water_depth": 30,
            "waves": {"regular": [{"height": 1.5, "period": 6}], "ramp_time": 3})")}) {
    SCOPED_TRACE(waves.empty() ? "still water" : "waves");
    double drift[2], damped = 0;
    for (int refine = 0; refine < 2; ++refine) {
      const double h = refine == 0 ? 0.02 : 0.01;
      const Scene scene = SceneFromJson(BuoyJson(
          false, kZeq + 0.3, Hydro(1.0, 2.0, 0.5, kCav), waves,
          absl::StrFormat(R"({"duration": 10, "step": %.17g})", h),
          R"(, "initial_velocity": {"linear": {"x": 1.0, "z": -0.2}})"));
      CollectingSink sink;
      const RunSummary summary = RunOk(scene, &sink);
      EXPECT_EQ(summary.rejected_steps, 0);
      const auto& frames = sink.frames();
      const double balance0 = frames.front().energy.total + frames.front().energy.damped;
      double worst = 0;
      for (const Frame& fr : frames)
        worst = std::max(worst, std::abs(fr.energy.total + fr.energy.damped - balance0));
      EXPECT_GT(frames.back().energy.damped, 100) << "the drag must have worked";
      drift[refine] = worst;
      damped = frames.back().energy.damped;
      std::printf("h %g: %lld steps, %lld Newton; balance drift %.3g J of %.4g J damped\n", h,
                  static_cast<long long>(summary.steps),
                  static_cast<long long>(summary.newton_iterations), worst,
                  frames.back().energy.damped);
    }
    // Second order (measured ratios 3.9 and 4.0), and small against the
    // drag's work (measured 3.5e-5 and 3.5e-4 of it at h = 0.01).
    EXPECT_LT(drift[1], 0.3 * drift[0]);
    EXPECT_LT(drift[1], 1e-3 * std::abs(damped));
  }
}

TEST(BodyFluidLoadTest, ValidationNamesTheField) {
  auto error = [](const std::string& json) {
    auto proto = ParseSceneJson(json);
    EXPECT_TRUE(proto.ok()) << proto.status();
    auto scene = SceneFromProto(*proto);
    EXPECT_FALSE(scene.ok());
    return std::string(scene.status().message());
  };
  EXPECT_THAT(error(BuoyJson(false, 0, R"({"diameter": 1, "height": 1, "drag_coefficient": -1})",
                             "", "{}")),
              HasSubstr("bodies[0].hydrodynamics.drag_coefficient: must be >= 0"));
  EXPECT_THAT(error(BuoyJson(false, 0, R"({"diameter": 1, "height": 1, "heave_added_mass": -2})",
                             "", "{}")),
              HasSubstr("bodies[0].hydrodynamics.heave_added_mass: must be >= 0"));
  EXPECT_THAT(error(BuoyJson(false, 0, R"({"height": 1})", "", "{}")),
              HasSubstr("bodies[0].hydrodynamics.diameter: required for a body given by mass"));
  EXPECT_THAT(error(BuoyJson(false, 0, R"({"diameter": 0, "height": 1})", "", "{}")),
              HasSubstr("bodies[0].hydrodynamics.diameter: must be > 0"));
  std::string dry = BuoyJson(false, 0, Hydro(), "", "{}");
  dry.replace(dry.find(R"("density": 1025)"), 15, R"("density": 0)");
  EXPECT_THAT(error(dry), HasSubstr("bodies[0].hydrodynamics: needs a fluid"));
}

// Drag areas (BodyHydrodynamics.drag_area) in the body's axes, no
// cylinder, no gravity: a body moving at v along its axis k in still water
// feels -(1/2) rho A_k |v| v (closed form, to rounding: 1e-12), and turned
// 90 degrees about z (its x axis along the world's y) the areas of x and y
// swap; an oblique velocity feels -(1/2) rho diag(A) |v| v.
std::string AreaBodyJson(const std::string& axis, const std::string& hydro,
                         const std::string& extra = "") {
  return absl::StrFormat(R"({
    "fluid": {"density": %.17g},
    "bodies": [{"name": "b", "mass": 100, "inertia": {"x": 10, "y": 20, "z": 25},
                "position": {"z": -20}, "axis": %s, "hydrodynamics": %s}],
    "probes": [{"name": "c", "body": "b"}],
    "solver": {"duration": 1} %s})",
                         kRho, axis, hydro, extra);
}

// The body of AreaBodyJson, its x axis along the world's x or (turned 90
// degrees about z) y, and its initial full configuration into `q`.
absl::StatusOr<MultibodyModel> AreaBodyModel(bool turned, const std::string& hydro,
                                             Eigen::VectorXd* q) {
  auto model = MultibodyModel::Build(
      SceneFromJson(AreaBodyJson(turned ? R"({"y": 1})" : R"({"x": 1})", hydro)));
  if (model.ok()) {
    q->resize(model->coordinates());
    model->ToFull(model->initial_z(), q);
  }
  return model;
}
// The body's axis along the world's axis k: k, or (turned) y for x and x
// for y.
constexpr int kBodyAxis[2][3] = {{0, 1, 2}, {1, 0, 2}};

TEST(BodyFluidLoadTest, DragAreasActAlongTheBodysAxes) {
  const Eigen::Vector3d areas(1, 2, 3);
  const std::string hydro = R"({"drag_area": {"x": 1, "y": 2, "z": 3}})";
  for (const bool turned : {false, true}) {
    SCOPED_TRACE(turned ? "turned 90 degrees about z" : "world axes");
    Eigen::VectorXd q;
    auto model = AreaBodyModel(turned, hydro, &q);
    ASSERT_TRUE(model.ok()) << model.status();
    ASSERT_EQ(model->body_fluid_loads().size(), 1u);
    EXPECT_EQ(model->body_fluid_loads()[0].waterplane_area(), 0) << "no cylinder";
    const int nq = model->coordinates();
    for (int k = 0; k < 3; ++k) {
      Eigen::VectorXd qd = Eigen::VectorXd::Zero(nq), f = Eigen::VectorXd::Zero(model->dofs());
      qd(k) = 1.5;
      model->DampingForce(q, qd, &f);
      const Eigen::Vector3d force = ForceOnCentre(*model, f);
      const double a = areas(kBodyAxis[turned ? 1 : 0][k]);
      const Eigen::Vector3d expected = -0.5 * kRho * a * 1.5 * 1.5 * Eigen::Vector3d::Unit(k);
      EXPECT_LT((force - expected).norm(), 1e-12 * expected.norm())
          << "axis " << k << ": " << force.transpose() << " vs " << expected.transpose();
    }
    if (turned) continue;
    Eigen::VectorXd qd = Eigen::VectorXd::Zero(nq), f = Eigen::VectorXd::Zero(model->dofs());
    const Eigen::Vector3d v(0.4, -1.1, 0.7);
    qd.head<3>() = v;
    model->DampingForce(q, qd, &f);
    const Eigen::Vector3d expected = -0.5 * kRho * v.norm() * areas.cwiseProduct(v);
    EXPECT_LT((ForceOnCentre(*model, f) - expected).norm(), 1e-12 * expected.norm());
  }
}

// Rotational drag areas: a body turning at omega about its axis k in
// still water feels the moment -(1/2) rho A_k |omega| omega, so the drag
// takes the power (1/2) rho A_k |omega|^3 (to rounding); turned 90 degrees
// about z, turning about the world's x is turning about its y.
TEST(BodyFluidLoadTest, RotationalDragAreasActAboutTheBodysAxes) {
  const Eigen::Vector3d areas(4, 5, 6);
  const std::string hydro = R"({"rotational_drag_area": {"x": 4, "y": 5, "z": 6}})";
  for (const bool turned : {false, true}) {
    SCOPED_TRACE(turned ? "turned 90 degrees about z" : "world axes");
    Eigen::VectorXd q;
    auto model = AreaBodyModel(turned, hydro, &q);
    ASSERT_TRUE(model.ok()) << model.status();
    const int nq = model->coordinates();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d omega = 0.8 * Eigen::Vector3d::Unit(k);
      Eigen::VectorXd qd = Eigen::VectorXd::Zero(nq);
      // The axes' rates edot_a = omega x e_a (natural coordinates 3..11).
      for (int a = 0; a < 3; ++a) qd.segment<3>(3 + 3 * a) = omega.cross(q.segment<3>(3 + 3 * a));
      const double expected = 0.5 * kRho * areas(kBodyAxis[turned ? 1 : 0][k]) * std::pow(0.8, 3);
      EXPECT_NEAR(model->DampingPower(q, qd), expected, 1e-12 * expected) << "axis " << k;
    }
  }
}

// Coasting in still water with no other load (closed form of
// m dv/dt = -(1/2) rho A v^2: v = v0 / (1 + rho A v0 t / (2 m)), and the
// same for the spin, I domega/dt = -(1/2) rho A_w omega^2), spatial (along
// z, turning about x) and planar (along x, turning about z). HHT at
// h = 1e-3 s over 4 s (the drag takes 95 % of the speed): the velocity within 1e-6 of v0, the spin's from the
// kinetic energy within 1e-6 of omega0 (measured 4e-8 and 5e-8 of them: second
// order in h, and the closed form is smooth).
TEST(BodyFluidLoadTest, CoastingBodySlowsAsTheClosedForm) {
  const double v0 = 2, w0 = 1.5, t_end = 4, m = 100;
  for (const bool planar : {false, true}) {
    SCOPED_TRACE(planar ? "planar" : "spatial");
    const double a = planar ? 0.3 : 0.5, aw = planar ? 0.9 : 0.7;
    const double inertia = planar ? 25 : 10;  // about z (planar), about x
    const std::string hydro = absl::StrFormat(
        R"({"drag_area": {"x": %.17g, "y": %.17g, "z": %.17g},
            "rotational_drag_area": {"x": %.17g, "y": %.17g, "z": %.17g}})",
        a, a, a, aw, aw, aw);
    std::string json = absl::StrFormat(
        R"({"fluid": {"density": %.17g},
            "bodies": [{"name": "b", "mass": 100, "inertia": {"x": 10, "y": 20, "z": 25},
                        "position": {"z": %s}, "hydrodynamics": %s}],
            "probes": [{"name": "c", "body": "b"}],
            "initial_velocity": {"linear": {"%s": %.17g}, "angular": {"%s": %.17g},
                                 "origin": {"z": %s}},
            "solver": {"duration": %.17g, "step": 0.001, "integrator": "HHT",
                       "output_interval": 0.5}})",
        kRho, planar ? "0" : "-20", hydro, planar ? "x" : "z", v0, planar ? "z" : "x", w0,
        planar ? "0" : "-20", t_end);
    const Scene scene = SceneFromJson(json);
    CollectingSink sink;
    RunOk(scene, &sink);
    const Frame& last = sink.frames().back();
    const double t = last.t;
    ASSERT_NEAR(t, t_end, 1e-9);
    const double v = v0 / (1 + 0.5 * kRho * a * v0 * t / m);
    const double w = w0 / (1 + 0.5 * kRho * aw * w0 * t / inertia);
    const Eigen::Vector3d vel = last.probes[0].velocity_m_s;
    const double along = planar ? vel.x() : vel.z();
    EXPECT_NEAR(along, v, 1e-6 * v0);
    EXPECT_LT(vel.norm() - std::abs(along), 1e-9) << "it keeps its direction";
    const double spin = std::sqrt(2 * (last.energy.kinetic - 0.5 * m * along * along) / inertia);
    EXPECT_NEAR(spin, w, 1e-6 * w0);
    std::printf("%s: v %.9g (closed form %.9g), omega %.9g (closed form %.9g), damped %.6g J\n",
                planar ? "planar" : "spatial", along, v, spin, w, last.energy.damped);
    // The drag's work is the kinetic energy lost (the trapezoidal rule on
    // its power: within 1e-4 of it).
    const double lost = 0.5 * m * (v0 * v0 - along * along) + 0.5 * inertia * (w0 * w0 - spin * spin);
    EXPECT_NEAR(last.energy.damped, lost, 1e-4 * lost);
  }
}

// The drag areas' tangent in the rates against central differences, with
// equal areas (where it is exact) along and about the axes, in a current,
// on a turned body; and the damping power against -zdot . f.
TEST(BodyFluidLoadTest, DragAreaTangentIsItsRateDerivative) {
  auto model = MultibodyModel::Build(SceneFromJson(R"({
    "gravity": {"z": -9.81}, "fluid": {"density": 1025, "current": {"x": 0.6, "y": -0.2}},
    "bodies": [{"name": "b", "mass": 100, "inertia": {"x": 10, "y": 20, "z": 25},
                "position": {"z": -20}, "axis": {"x": 1, "y": 1, "z": 0.5},
                "hydrodynamics": {"drag_area": {"x": 0.8, "y": 0.8, "z": 0.8},
                                  "rotational_drag_area": {"x": 2, "y": 2, "z": 2}}}],
    "solver": {"duration": 1}})"));
  ASSERT_TRUE(model.ok()) << model.status();
  double size = 0;
  const double error = testing::DampingTangentError(*model, Eigen::VectorXd(), 1e-6, &size);
  EXPECT_GT(size, 1);
  EXPECT_LT(error, 1e-6 * size);
}

TEST(BodyFluidLoadTest, DragAreaValidationNamesTheField) {
  auto scene = [](const std::string& json) {
    auto proto = ParseSceneJson(json);
    EXPECT_TRUE(proto.ok()) << proto.status();
    return SceneFromProto(*proto);
  };
  auto error = [&](const std::string& json) {
    auto s = scene(json);
    EXPECT_FALSE(s.ok());
    return s.ok() ? std::string() : std::string(s.status().message());
  };
  EXPECT_THAT(error(AreaBodyJson(R"({"x": 1})", R"({"drag_area": {"y": -1}})")),
              HasSubstr("bodies[0].hydrodynamics.drag_area.y: must be in [0,"));
  EXPECT_THAT(error(AreaBodyJson(R"({"x": 1})", R"({"rotational_drag_area": {"z": -2}})")),
              HasSubstr("bodies[0].hydrodynamics.rotational_drag_area.z: must be in [0,"));
  // No gravity: drag areas alone are fine, a cylinder is not.
  EXPECT_TRUE(scene(AreaBodyJson(R"({"x": 1})", R"({"drag_area": {"x": 1}})")).ok());
  EXPECT_THAT(error(AreaBodyJson(R"({"x": 1})", R"({"diameter": 1, "height": 1})")),
              HasSubstr("bodies[0].hydrodynamics: needs gravity for its cylinder"));
  std::string dry = AreaBodyJson(R"({"x": 1})", R"({"drag_area": {"x": 1}})");
  dry.replace(dry.find(R"("density": 1025)"), 15, R"("density": 0)");
  EXPECT_THAT(error(dry), HasSubstr("bodies[0].hydrodynamics: needs a fluid"));
}

// A cylinder body takes its size from its cylinder.
TEST(BodyFluidLoadTest, CylinderBodyGivesTheDisplacedShape) {
  auto model = MultibodyModel::Build(SceneFromJson(R"({
    "gravity": {"z": -9.81}, "fluid": {"density": 1025},
    "bodies": [{"name": "b", "cylinder": {"diameter": 2, "height": 4}, "density": 500,
                "axis": {"z": 1}, "hydrodynamics": {}}],
    "solver": {"duration": 1}})"));
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->body_fluid_loads().size(), 1u);
  EXPECT_DOUBLE_EQ(model->body_fluid_loads()[0].waterplane_area(), kPi);
}

// A scene without body hydrodynamics holds no body fluid load.
TEST(BodyFluidLoadTest, SceneWithoutHoldsNone) {
  auto model = MultibodyModel::Build(SceneFromJson(R"({
    "gravity": {"z": -9.81}, "fluid": {"density": 1025},
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1}}],
    "solver": {"duration": 1}})"));
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_TRUE(model->body_fluid_loads().empty());
  EXPECT_FALSE(model->has_damping());
}

}  // namespace
}  // namespace cablesim
