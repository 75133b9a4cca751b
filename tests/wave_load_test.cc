// Waves in the fluid load (engine/forces/wave_load.h): the Morison drag on
// the flow relative to the cable and the flow's inertia (1 + C_a) rho A
// du/dt, integrated along cables held still in a regular Airy wave, against
// the closed-form integrals of the kinematics; the decay with depth seen in
// the load; the drag's velocity tangent; a scene whose waves are zero runs
// exactly as one without; a riser in waves steps as in still water with its
// energy balance closed; the scene fields' validation.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/forces/waves.h"
#include "engine/model/model_choice.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/linear/skyline_ldlt.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;
// Water and wave of the tests: rho 1025, depth h = 20 m below the still
// level y = 0 (gravity -y, so the planar model runs), a regular wave of
// height 2 m and period 8 s along +x with phase 0.3.
constexpr double kRho = 1025, kDepth = 20, kHeight = 2, kPeriod = 8, kPhase = 0.3;
// Cable section: hydrodynamic diameter d = 0.1 m, C_dn 1.2, C_dt 0.4, C_a 1.
constexpr double kD = 0.1, kCdn = 1.2, kCdt = 0.4, kCa = 1;
const double kOmega = 2 * kPi / kPeriod;
const double kWavenumber = WaveField::Wavenumber(kOmega, kDepth, kG);
const double kArea = kPi * kD * kD / 4;
const double kKn = 0.5 * kRho * kCdn * kD, kKt = 0.5 * kRho * kCdt * kPi * kD;
const double kMi = (1 + kCa) * kRho * kArea;

// A scene with one straight cable from `a` to `b` (planar, no joints: the
// unknowns are the coordinates), in the test's water and wave with current
// `current_x` along x and tangential drag factor `cdt`.
std::string CableInWaveJson(const Eigen::Vector2d& a, const Eigen::Vector2d& b, int elements,
                            double current_x, double cdt, const std::string& waves) {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": %.17g, "current": {"x": %.17g}, "water_depth": %.17g,
              "waves": %s},
    "cables": [{"name": "c", "points": [{"x": %.17g, "y": %.17g}, {"x": %.17g, "y": %.17g}],
                "elements": %d, "density": 3000, "youngs_modulus": 1e9, "diameter": 0.05,
                "hydrodynamics": {"normal_drag": %.17g, "tangential_drag": %.17g,
                                  "added_mass": %.17g, "diameter": %.17g}}],
    "solver": {"duration": 1}})",
                         kRho, current_x, kDepth, waves, a.x(), a.y(), b.x(), b.y(), elements,
                         kCdn, cdt, kCa, kD);
}

std::string RegularWave(double ramp = 0) {
  return absl::StrFormat(
      R"({"regular": [{"height": %.17g, "period": %.17g, "phase": %.17g}], "ramp_time": %.17g})",
      kHeight, kPeriod, kPhase, ramp);
}

// The resultant fluid force [N] on a scene's (free, unjoined) cable held
// still at its initial shape at time t: the sum of the position entries of
// the generalized force (the position shape functions sum to 1).
Eigen::Vector2d Resultant(const Scene& scene, double t) {
  auto built = MultibodyModel::Build(scene);
  EXPECT_TRUE(built.ok()) << built.status();
  if (!built.ok()) return Eigen::Vector2d::Zero();
  MultibodyModel& model = *built;
  EXPECT_EQ(model.dimension(), 2);
  EXPECT_EQ(model.dofs(), model.coordinates());
  Eigen::VectorXd q(model.coordinates()), qd = Eigen::VectorXd::Zero(model.coordinates());
  model.ToFull(model.initial_z(), &q);
  model.SetTime(t);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.dofs());
  model.DampingForce(q, qd, &f);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < f.size(); i += 4) sum += f.segment<2>(i);
  return sum;
}

// Airy amplitudes at the phase theta: the factor A = a omega / sinh(k h).
const double kA = 0.5 * kHeight * kOmega / std::sinh(kWavenumber * kDepth);

// A vertical cable from the bed (y = -h) to 2 m above the still level, at
// x = 3, held still at t = 0.2 s in the wave and a current U = 0.3 m/s.
// At the phase theta = k x - omega t + phase (cos, sin > 0 here, so neither
// drag changes sign along the cable) and zeta = y + h the flow is
//   u_x = U + A cosh(k zeta) cos(theta),  u_y = A sinh(k zeta) sin(theta),
//   a_x = A omega cosh(k zeta) sin(theta), a_y = -A omega sinh(k zeta) cos(theta)
// below the level and its value at zeta = h above it (WaveField::At). The
// normal is x, the tangent y, so per unit length
//   q_x = kn u_x^2 + mi a_x,  q_y = kt u_y^2 + mi a_y,
// whose integrals over zeta in [0, h] are closed:
//   int (U + B cosh)^2 = U^2 h + 2 U B sinh(kh) / k + B^2 (h / 2 + sinh(2kh) / (4k)),
//   int (C sinh)^2 = C^2 (sinh(2kh) / (4k) - h / 2),
//   int cosh = sinh(kh) / k,  int sinh = (cosh(kh) - 1) / k,
// plus 2 m times the values at the level.
TEST(WaveLoadTest, VerticalCableLoadIsTheClosedFormIntegralOfTheAiryFlow) {
  const double x = 3, t = 0.2, u = 0.3, above = 2;
  const Scene scene = SceneFromJson(CableInWaveJson({x, -kDepth}, {x, above}, 44, u, kCdt,
                                                    RegularWave()));
  const double k = kWavenumber, h = kDepth;
  const double theta = k * x - kOmega * t + kPhase;
  ASSERT_GT(std::cos(theta), 0);
  ASSERT_GT(std::sin(theta), 0);
  const double b = kA * std::cos(theta), c = kA * std::sin(theta);
  const double ux_top = u + b * std::cosh(k * h), uy_top = c * std::sinh(k * h);
  const double drag_x = u * u * h + 2 * u * b * std::sinh(k * h) / k +
                        b * b * (h / 2 + std::sinh(2 * k * h) / (4 * k)) +
                        above * ux_top * ux_top;
  const double drag_y = c * c * (std::sinh(2 * k * h) / (4 * k) - h / 2) + above * uy_top * uy_top;
  const double accel_x = kA * kOmega * std::sin(theta) * (std::sinh(k * h) / k + above * std::cosh(k * h));
  const double accel_y =
      -kA * kOmega * std::cos(theta) * ((std::cosh(k * h) - 1) / k + above * std::sinh(k * h));
  const Eigen::Vector2d expected(kKn * drag_x + kMi * accel_x, kKt * drag_y + kMi * accel_y);
  const Eigen::Vector2d got = Resultant(scene, t);
  // 44 elements of 0.5 m (a node at the still level, where the flow's
  // depth profile has its kink), 5 Gauss points each: the quadrature error
  // of these smooth integrands is of order (k l)^10 ~ 1e-15, so the
  // tolerance is rounding over the sum (1e-12 relative, with margin).
  EXPECT_NEAR(got.x(), expected.x(), 1e-12 * expected.norm());
  EXPECT_NEAR(got.y(), expected.y(), 1e-12 * expected.norm());
  // Each part matters: the drag across, the drag along and the inertia are
  // each more than 1 % of the total.
  EXPECT_GT(kKt * drag_y, 0.01 * expected.norm());
  EXPECT_GT(kMi * std::abs(accel_x), 0.01 * expected.norm());
}

// Integral over theta in [t0, t1] of |sin| sin, splitting at the zeros.
double IntegralAbsSinSin(double t0, double t1) {
  auto f = [](double t) { return t / 2 - std::sin(2 * t) / 4; };  // int sin^2
  double sum = 0, a = t0;
  while (a < t1) {
    const double zero = (std::floor(a / kPi) + 1) * kPi;
    const double b = std::min(zero, t1);
    const double s = std::sin(0.5 * (a + b)) >= 0 ? 1 : -1;
    sum += s * (f(b) - f(a));
    a = b;
  }
  return sum;
}

// A horizontal cable along the wave, 30 m (a third of the wavelength) at
// depth 5 m, held still at t = 0.9 s, no current, normal drag and inertia
// (tangential drag 0). theta(x) = k x - omega t + phase runs over 2.1 rad;
// the normal is y, the tangent x:
//   F_x = mi int a_x dx = mi A omega cosh(k zeta) int sin(theta) dx,
//   F_y = kn (A sinh(k zeta))^2 int |sin(theta)| sin(theta) dx
//         - mi A omega sinh(k zeta) int cos(theta) dx,
// with dx = dtheta / k.
TEST(WaveLoadTest, HorizontalCableLoadFollowsThePhaseAlongIt) {
  const double y = -5, length = 30, t = 0.9;
  const Scene scene =
      SceneFromJson(CableInWaveJson({0, y}, {length, y}, 60, 0, 0, RegularWave()));
  const double k = kWavenumber, zeta = y + kDepth;
  const double t0 = -kOmega * t + kPhase, t1 = k * length + t0;
  const double ch = std::cosh(k * zeta), sh = std::sinh(k * zeta);
  const double fx = kMi * kA * kOmega * ch * (std::cos(t0) - std::cos(t1)) / k;
  const double fy = kKn * kA * kA * sh * sh * IntegralAbsSinSin(t0, t1) / k -
                    kMi * kA * kOmega * sh * (std::sin(t1) - std::sin(t0)) / k;
  const Eigen::Vector2d got = Resultant(scene, t);
  // The drag |sin| sin changes sign once along the cable: its second
  // derivative jumps there, so the Gauss rule of the element holding the
  // zero errs by about (1/2) kn (A sh k)^2 l^3 / 12 ~ 1e-6 N (l = 0.5 m),
  // 1e-8 of the load; 1e-7 relative leaves a margin. The inertia terms are
  // smooth (rounding only).
  const double size = std::hypot(fx, fy);
  EXPECT_NEAR(got.x(), fx, 1e-12 * size);
  EXPECT_NEAR(got.y(), fy, 1e-7 * size);
  // The wave's phase varies along the cable: the same cable 1/4 period
  // later carries another load.
  EXPECT_GT((Resultant(scene, t + kPeriod / 4) - got).norm(), 0.1 * size);
}

// The load decays with depth as the Airy profile: the horizontal inertia
// force on a short horizontal cable (F_x, tangential drag 0) scales with
// cosh(k (y + h)), the vertical drag with sinh(k (y + h))^2.
TEST(WaveLoadTest, LoadDecaysWithDepthAsTheAiryProfile) {
  const double t = 0.1, shallow = -1, deep = -19, length = 1;
  auto load = [&](double y) {
    return Resultant(SceneFromJson(CableInWaveJson({0, y}, {length, y}, 4, 0, 0, RegularWave())),
                     t);
  };
  const Eigen::Vector2d top = load(shallow), bottom = load(deep);
  const double k = kWavenumber;
  const double ratio_x = std::cosh(k * (shallow + kDepth)) / std::cosh(k * (deep + kDepth));
  // Rounding only: both resultants are the same quadrature of the same
  // phase function times the depth factor.
  EXPECT_NEAR(top.x() / bottom.x(), ratio_x, 1e-12 * ratio_x);
  EXPECT_GT(ratio_x, 2);  // the decay is large enough to see
  // (theta stays in (0, pi / 2) along the cable: no drag changes sign.)
  // The vertical load: drag kn (C sinh)^2 int sin^2 minus inertia
  // mi A omega sinh int cos, each scaling with its own power of sinh.
  const double theta0 = -kOmega * t + kPhase, theta1 = theta0 + k * length;
  auto fy = [&](double y) {
    const double sh = std::sinh(k * (y + kDepth));
    return kKn * kA * kA * sh * sh * IntegralAbsSinSin(theta0, theta1) / k -
           kMi * kA * kOmega * sh * (std::sin(theta1) - std::sin(theta0)) / k;
  };
  EXPECT_NEAR(top.y(), fy(shallow), 1e-10 * std::abs(fy(shallow)));
  EXPECT_NEAR(bottom.y(), fy(deep), 1e-10 * std::abs(fy(shallow)));
}

// The drag's share of the Newton matrix with waves is still its velocity
// derivative (central differences, as tests/drag_test.cc for the current),
// and the damping power is -zdot . f: the waves' work lands in
// energy.damped.
TEST(WaveLoadTest, TangentIsMinusForceDerivativeInRatesAndPowerIsTheLoadsWork) {
  const Scene scene = SceneFromJson(R"({
    "model": "SPATIAL", "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "current": {"x": 0.2}, "water_depth": 30, "still_water_level": 1,
              "waves": {"regular": [{"height": 1.5, "period": 7, "direction": {"x": 1, "z": 0.5}},
                                    {"height": 0.7, "period": 4, "direction": {"z": 1}, "phase": 1}],
                        "jonswap": [{"significant_height": 1, "peak_period": 6, "seed": 5,
                                     "components": 20}]}},
    "cables": [{"name": "c", "points": [{"x": 0, "y": -3}, {"x": 0.3, "y": -4}, {"x": 0.5, "y": -5}],
                "elements": 5, "density": 1500, "youngs_modulus": 1e8, "diameter": 0.03,
                "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.3,
                                  "added_mass": 1, "diameter": 0.04}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": {"duration": 1}})");
  auto built = MultibodyModel::Build(scene);
  ASSERT_TRUE(built.ok()) << built.status();
  MultibodyModel& model = *built;
  ASSERT_TRUE(model.has_damping());
  model.SetTime(2.3);
  double size = 0;
  const double worst = testing::DampingTangentError(model, {}, 1e-6, &size);
  EXPECT_GT(size, 0);
  // Central differences of a smooth function: O(step^2) = 1e-12 relative,
  // plus rounding eps |f| / step = 1e-10 relative.
  EXPECT_LE(worst, 1e-7 * size);
}

// A wave of zero height takes the wave path (WaveLoad) with a zero flow
// field: every frame of a run equals, to the bit, the run of the same scene
// without waves (which takes AncfCableElement::AddDrag, the code of before).
TEST(WaveLoadTest, ZeroWavesRunExactlyAsNoWaves) {
  Scene still = SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": 1000, "current": {"x": 0.5}},
    "cables": [{"name": "line", "length": 10, "elements": 10, "direction": {"y": -1},
                "density": 2000, "youngs_modulus": 1e9, "diameter": 0.02, "bending": "NONE",
                "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.1, "added_mass": 1}}],
    "joints": [{"type": "PIN", "a": {"cable": "line", "s": 0}}],
    "probes": [{"name": "end", "cable": "line", "s": 10}],
    "solver": {"duration": 5, "step": 0.05, "output_interval": 0.5}})");
  Scene zero = still;
  zero.fluid.water_depth_m = 30;
  RegularWaveSpec flat;
  flat.height_m = 0;  // the engine takes it; the scene format asks for > 0
  flat.period_s = 5;
  zero.fluid.waves.regular.push_back(flat);
  CollectingSink a, b;
  const RunSummary sa = RunOk(still, &a), sb = RunOk(zero, &b);
  EXPECT_EQ(sa.newton_iterations, sb.newton_iterations);
  ASSERT_EQ(a.frames().size(), b.frames().size());
  for (size_t i = 0; i < a.frames().size(); ++i) {
    const Frame &fa = a.frames()[i], &fb = b.frames()[i];
    EXPECT_EQ(fa.probes[0].position_m, fb.probes[0].position_m) << "frame " << i;
    EXPECT_EQ(fa.probes[0].velocity_m_s, fb.probes[0].velocity_m_s) << "frame " << i;
    EXPECT_EQ(fa.energy.total, fb.energy.total) << "frame " << i;
    EXPECT_EQ(fa.energy.damped, fb.energy.damped) << "frame " << i;
  }
  // The end did move (the run is not trivially equal).
  EXPECT_GT(std::abs(a.frames().back().probes[0].position_m.x()), 1);
}

// A riser: a buoyant vertical line (density 500 in water 1025) pinned at the
// bed 20 m down, its top 1 m below the still level, in a regular wave of
// 2 m and 8 s ramped in over one period.
//  - It runs at the step it takes in still water, no step halved or
//    rejected, with the defaults (factorization reuse).
//  - The Newton matrix leaves out the flow's position derivative (and the
//    drag's through the cable's direction): with a fresh factorization at
//    every iteration (reuse_factorization false) Newton takes the same
//    iterations per step in waves as in still water, so the left-out terms
//    do not slow it. (With reuse the waves cost refactorizations, since the
//    drag's velocity derivative changes as the flow swings.)
//  - It moves with the wave.
//  - energy.total + energy.damped stays at the initial energy to the
//    accuracy of the trapezoidal rule on the damping power
//    (GENERALIZED_ALPHA with rho_infinity 1 removes no energy of its own):
//    second order in h, so halving the step divides the imbalance by about 4.
TEST(WaveLoadTest, RiserInWavesStepsAsInStillWaterWithItsEnergyBalanced) {
  auto riser = [](bool waves, double step, bool reuse) {
    Scene scene = SceneFromJson(absl::StrFormat(R"({
      "gravity": {"y": -9.81},
      "fluid": {"density": 1025, "water_depth": 20 %s},
      "cables": [{"name": "riser", "points": [{"y": -20}, {"y": -1}], "elements": 19,
                  "density": 500, "youngs_modulus": 1e9, "diameter": 0.1,
                  "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.1, "added_mass": 1}}],
      "joints": [{"type": "PIN", "a": {"cable": "riser", "s": 0}}],
      "probes": [{"name": "top", "cable": "riser", "s": 19}],
      "solver": {"duration": 16, "step": %.17g, "output_interval": 0.1,
                 "integrator": "GENERALIZED_ALPHA", "rho_infinity": 1}})",
        waves ? R"(, "waves": {"regular": [{"height": 2, "period": 8}], "ramp_time": 8})" : "",
        step));
    scene.solver.reuse_factorization = reuse;
    return scene;
  };
  const double h = 0.02;
  CollectingSink still_sink, wave_sink, fresh_still_sink, fresh_wave_sink, fine_sink;
  const RunSummary still = RunOk(riser(false, h, true), &still_sink);
  const RunSummary waves = RunOk(riser(true, h, true), &wave_sink);
  EXPECT_EQ(waves.rejected_steps, 0);
  EXPECT_EQ(waves.min_step_s, h);
  EXPECT_EQ(waves.steps, still.steps);
  const RunSummary fresh_still = RunOk(riser(false, h, false), &fresh_still_sink);
  const RunSummary fresh_waves = RunOk(riser(true, h, false), &fresh_wave_sink);
  const double per_step_still = double(fresh_still.newton_iterations) / fresh_still.steps;
  const double per_step_waves = double(fresh_waves.newton_iterations) / fresh_waves.steps;
  EXPECT_LE(per_step_waves, per_step_still + 0.05)
      << per_step_still << " Newton iterations per step in still water, " << per_step_waves
      << " in waves";
  // The top moves with the wave: the flow at 1 m depth sweeps
  // A cosh(k 19 m) ~ 0.7 m/s back and forth.
  double sway = 0;
  for (const Frame& f : wave_sink.frames())
    sway = std::max(sway, std::abs(f.probes[0].position_m.x()));
  EXPECT_GT(sway, 0.2);
  // The waves' work: energy.damped reaches the size of the riser's motion
  // energy, and the balance holds to a small part of it.
  auto imbalance = [](const CollectingSink& sink, double* work) {
    const double e0 = sink.frames().front().energy.total;
    double worst = 0;
    *work = 0;
    for (const Frame& f : sink.frames()) {
      worst = std::max(worst, std::abs(f.energy.total + f.energy.damped - e0));
      *work = std::max(*work, std::abs(f.energy.damped));
    }
    return worst;
  };
  double work = 0, fine_work = 0;
  const double coarse = imbalance(wave_sink, &work);
  RunOk(riser(true, h / 2, true), &fine_sink);
  const double finer = imbalance(fine_sink, &fine_work);
  EXPECT_GT(work, 0);
  EXPECT_LT(coarse, 0.01 * work) << "imbalance " << coarse << " J of " << work << " J damped";
  // Second order: a quarter, give or take (2.5 to 6 allows the rule's
  // error constant to shift with the step).
  EXPECT_GT(coarse / finer, 2.5) << coarse << " J at h, " << finer << " J at h / 2";
  EXPECT_LT(coarse / finer, 6) << coarse << " J at h, " << finer << " J at h / 2";
}

// Wave fields are validated with errors naming the field.
TEST(WaveLoadTest, ValidationNamesTheField) {
  auto error = [](const std::string& fluid, const std::string& gravity = R"({"y": -9.81})") {
    auto proto = ParseSceneJson(absl::StrCat(R"({"gravity": )", gravity, R"(, "fluid": )", fluid,
                                             R"(, "cables": [{"name": "c", "length": 1,
        "density": 1000, "youngs_modulus": 1e9, "diameter": 0.01}], "solver": {"duration": 1}})"));
    EXPECT_TRUE(proto.ok()) << proto.status();
    if (!proto.ok()) return std::string();
    auto scene = SceneFromProto(*proto);
    EXPECT_FALSE(scene.ok());
    if (scene.ok()) return std::string();
    EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(scene.status().message());
  };
  EXPECT_EQ(error(R"({"density": 1025, "water_depth": 20,
                      "waves": {"regular": [{"height": 1, "period": 0}]}})"),
            "fluid.waves.regular[0].period: must be > 0 (got 0)");
  EXPECT_EQ(error(R"({"density": 1025, "water_depth": 20,
                      "waves": {"regular": [{"height": 1, "period": 5}, {"height": -1, "period": 5}]}})"),
            "fluid.waves.regular[1].height: must be > 0 (got -1)");
  EXPECT_THAT(error(R"({"water_depth": 20, "waves": {"regular": [{"height": 1, "period": 5}]}})"),
              HasSubstr("fluid.waves: needs a fluid (fluid.density > 0)"));
  EXPECT_THAT(error(R"({"density": 1025, "waves": {"regular": [{"height": 1, "period": 5}]}})"),
              HasSubstr("fluid.water_depth: must be > 0 with waves"));
  EXPECT_THAT(error(R"({"density": 1025, "water_depth": 20,
                        "waves": {"regular": [{"height": 1, "period": 5}]}})",
                    "{}"),
              HasSubstr("fluid.waves: needs gravity"));
  EXPECT_THAT(error(R"({"density": 1025, "water_depth": 20,
                        "waves": {"regular": [{"height": 1, "period": 5, "direction": {"y": 2}}]}})"),
              HasSubstr("fluid.waves.regular[0].direction: must have a horizontal part"));
  EXPECT_EQ(error(R"({"density": 1025, "water_depth": 20,
                      "waves": {"jonswap": [{"significant_height": 1, "peak_period": 0}]}})"),
            "fluid.waves.jonswap[0].peak_period: must be > 0 (got 0)");
  EXPECT_THAT(error(R"({"density": 1025, "water_depth": 20,
                        "waves": {"jonswap": [{"significant_height": 1, "peak_period": 6,
                                               "peak_factor": 0.5}]}})"),
              HasSubstr("fluid.waves.jonswap[0].peak_factor: must be >= 1"));
  EXPECT_THAT(error(R"({"density": 1025, "water_depth": 20,
                        "waves": {"jonswap": [{"significant_height": 1, "peak_period": 6,
                                               "components": 2000}]}})"),
              HasSubstr("fluid.waves.jonswap[0].components: must be in [1, 1000]"));
  EXPECT_EQ(error(R"({"density": 1025, "water_depth": 20,
                      "waves": {"regular": [{"height": 1, "period": 5}], "ramp_time": -1}})"),
            "fluid.waves.ramp_time: must be >= 0 (got -1)");
  EXPECT_THAT(error(R"({"density": 1025, "water_depth": -3})"),
              HasSubstr("fluid.water_depth: must be >= 0"));
}

// The fields reach the engine: defaults (peak factor 3.3, 100 components,
// direction x) and the given values.
TEST(WaveLoadTest, FieldsAndDefaultsReachTheEngine) {
  const Scene scene = SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "still_water_level": 2, "water_depth": 30,
              "waves": {"regular": [{"height": 1, "period": 5, "direction": {"x": -2, "y": 1},
                                     "phase": 0.5}],
                        "jonswap": [{"significant_height": 3, "peak_period": 9, "seed": 7}],
                        "ramp_time": 4}},
    "cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e9,
                "diameter": 0.01}],
    "solver": {"duration": 1}})");
  const FluidSpec& f = scene.fluid;
  EXPECT_EQ(f.still_water_level_m, 2);
  EXPECT_EQ(f.water_depth_m, 30);
  EXPECT_EQ(f.waves.ramp_s, 4);
  ASSERT_EQ(f.waves.regular.size(), 1u);
  EXPECT_EQ(f.waves.regular[0].height_m, 1);
  EXPECT_EQ(f.waves.regular[0].period_s, 5);
  EXPECT_EQ(f.waves.regular[0].phase_rad, 0.5);
  EXPECT_EQ(f.waves.regular[0].direction, Eigen::Vector3d(-1, 0, 0));  // horizontal, unit
  ASSERT_EQ(f.waves.jonswap.size(), 1u);
  EXPECT_EQ(f.waves.jonswap[0].significant_height_m, 3);
  EXPECT_EQ(f.waves.jonswap[0].peak_period_s, 9);
  EXPECT_EQ(f.waves.jonswap[0].peak_factor, 3.3);
  EXPECT_EQ(f.waves.jonswap[0].components, 100);
  EXPECT_EQ(f.waves.jonswap[0].seed, 7u);
  EXPECT_EQ(f.waves.jonswap[0].direction, Eigen::Vector3d(1, 0, 0));
  // In the plane; a wave travelling along z makes the scene spatial.
  EXPECT_EQ(OutOfPlaneField(scene), "");
  Scene across = scene;
  across.fluid.waves.regular[0].direction = Eigen::Vector3d(0.6, 0, 0.8);
  EXPECT_EQ(OutOfPlaneField(across), "fluid.waves.regular[0].direction.z");
}

}  // namespace
}  // namespace cablesim
