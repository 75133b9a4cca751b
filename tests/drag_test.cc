// Fluid loads (Morison drag, buoyancy, added mass; MultibodyModel::
// DampingForce and ModelBuilder): the terminal inclination of a cable held
// in a current, and the terminal sinking speeds of a free cable across and
// along its axis, against their closed forms.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/linear/skyline_ldlt.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;
// Cable and water of the tests: d = 2 cm, rho = 2000 kg/m^3 in water of
// 1000 kg/m^3: wet weight w = (2000 - 1000) pi d^2 / 4 g = 3.08 N/m.
constexpr double kD = 0.02, kRhoCable = 2000, kRhoWater = 1000;
const double kArea = kPi * kD * kD / 4;
const double kWetWeight = (kRhoCable - kRhoWater) * kArea * kG;

// A cable pinned at its top in a uniform horizontal current U, with normal
// drag only, settles straight. Per unit length the loads are the wet
// weight w (down) and the normal drag q = (1/2) rho C_dn d |v_n| v_n with
// v_n the current's component normal to the cable. Along a straight line
// at angle theta from the vertical |v_n| = U cos(theta), and no load may
// be normal to a straight, free-ended line with no curvature (a cable
// without bending stiffness carries normal loads only by curvature, and
// its tension vanishes at the free end), so
//
//   w sin(theta) = (1/2) rho C_dn d U^2 cos(theta)^2
//
// (tan(theta) = D / w, D the drag of the cable across the flow, holds
// only if the drag did not fall with cos(theta)^2). The steady state of a
// dynamic run is that equilibrium whatever the cable's stiffness; the
// line is straight, so 10 elements represent it exactly. This is the
// sample scene scenes/cable-in-current.json.
TEST(DragTest, CableInCurrentHangsAtTheClosedFormAngle) {
  const double cdn = 1.2, u = 0.5, length = 10;
  // The sample scene: a 10 m cable of 2 cm without bending stiffness,
  // pinned at its top and hanging straight down at t = 0, in a current of
  // U = 0.5 m/s along x; C_dn = 1.2, C_a = 1; 200 s at 0.05 s.
  auto proto = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/cable-in-current.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->solver.duration_s, 200);
  CollectingSink sink;
  RunOk(*scene, &sink);
  // sin(theta) = k cos(theta)^2, k = rho C_dn d U^2 / (2 w):
  // sin(theta) = (sqrt(1 + 4 k^2) - 1) / (2 k).
  const double k = 0.5 * kRhoWater * cdn * kD * u * u / kWetWeight;
  const double theta = std::asin((std::sqrt(1 + 4 * k * k) - 1) / (2 * k));
  const Frame& last = sink.frames().back();
  const Eigen::Vector3d end = last.probes[1].position_m, mid = last.probes[0].position_m;
  // Tolerance 1e-6 rad (measured 5e-11): the cable creeps to its angle,
  // overdamped by the drag, with a time constant of about 10 s (measured:
  // 0.043 rad left at 30 s, 0.0054 at 50 s), so 200 s leave 1e-9 rad;
  // the steady state is a static equilibrium, which backward Euler's step
  // does not shift; Newton's tolerance is 1e-8.
  EXPECT_NEAR(std::atan2(end.x(), -end.y()), theta, 1e-6) << "theta " << theta;
  EXPECT_NEAR(std::atan2(mid.x(), -mid.y()), theta, 1e-6);
  EXPECT_LT(last.probes[1].velocity_m_s.norm(), 1e-6);
  EXPECT_GT(end.norm(), length);  // stretched by its wet weight
}

// The same cable towed through still water: its top is moved at -U along x
// (a ramp from t = 0, scenes/towed-cable.json) instead of the water
// flowing at +U. Drag depends only on the velocity relative to the water,
// so the steady state seen from the tow point is the current's: the
// straight line at the same closed-form angle. The tow force (the probe on
// the moving support) is then the line's tension at the top, which
// carries the whole wet weight along the line: |F| = w L cos(theta), with
// horizontal part w L cos(theta) sin(theta) against the tow.
TEST(DragTest, CableTowedThroughStillWaterTrailsAtTheClosedFormAngle) {
  const double cdn = 1.2, u = 0.5, length = 10;
  auto proto = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/towed-cable.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  const double k = 0.5 * kRhoWater * cdn * kD * u * u / kWetWeight;
  const double theta = std::asin((std::sqrt(1 + 4 * k * k) - 1) / (2 * k));
  const Frame& last = sink.frames().back();
  const Eigen::Vector3d tow = last.probes[0].position_m;
  // The tow point is where the ramp put it (a PIN holds it to 1e-9 m).
  EXPECT_NEAR(tow.x(), -u * scene->solver.duration_s, 1e-9);
  const Eigen::Vector3d mid = last.probes[1].position_m - tow;
  const Eigen::Vector3d end = last.probes[2].position_m - tow;
  // Tolerance 1e-6 rad, as in the current: the same overdamped creep to
  // the angle (time constant about 10 s) over 200 s; backward Euler is
  // exact for the uniform translation the steady state adds.
  EXPECT_NEAR(std::atan2(end.x(), -end.y()), theta, 1e-6) << "theta " << theta;
  EXPECT_NEAR(std::atan2(mid.x(), -mid.y()), theta, 1e-6);
  // Steady: the end moves with the tow point.
  EXPECT_NEAR(last.probes[2].velocity_m_s.x(), -u, 1e-6);
  ASSERT_EQ(last.support_forces.size(), 1u);
  const Eigen::Vector3d force = last.support_forces[0];
  const double tension = kWetWeight * length * std::cos(theta);
  // Tolerance 1e-6 relative: the angle's tolerance carried into sin and cos.
  EXPECT_NEAR(force.norm(), tension, 1e-6 * tension);
  EXPECT_NEAR(force.x(), -tension * std::sin(theta), 1e-6 * tension);
  EXPECT_NEAR(force.y(), tension * std::cos(theta), 1e-6 * tension);
}

// A free horizontal cable sinking in still water reaches the speed at which
// its normal drag carries its wet weight: w = (1/2) rho C_dn d v^2. A
// vertical one sinks along its axis at w = (1/2) rho C_dt pi d v^2
// (tangential drag on the wetted perimeter).
struct SinkingCase {
  const char* direction;
  bool across;
};

class SinkingTest : public ::testing::TestWithParam<SinkingCase> {};

TEST_P(SinkingTest, TerminalVelocityMatchesClosedForm) {
  const double cdn = 1.2, cdt = 0.01;
  const Scene scene = SceneFromJson(absl::StrCat(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": 1000},
    "cables": [{"name": "c", "length": 2, "elements": 4, "direction": )",
                                                 GetParam().direction, R"(,
                "density": 2000, "youngs_modulus": 1e9, "diameter": 0.02,
                "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.01,
                                  "added_mass": 1}}],
    "probes": [{"name": "mid", "cable": "c", "s": 1}],
    "solver": {"duration": 60, "step": 0.01, "output_interval": 1,
               "integrator": "GENERALIZED_ALPHA"}})"));
  CollectingSink sink;
  RunOk(scene, &sink);
  const double coefficient = GetParam().across ? cdn * kD : cdt * kPi * kD;
  const double v = std::sqrt(2 * kWetWeight / (kRhoWater * coefficient));
  const Eigen::Vector3d vel = sink.frames().back().probes[0].velocity_m_s;
  // Tolerance 1e-6 relative: the approach to terminal speed is
  // exponential in t / tau with tau = m_eff / (rho C d v) (at most 7 s
  // along the axis), so 60 s leave below 1e-6 of it.
  EXPECT_NEAR(vel.y(), -v, 1e-6 * v);
  EXPECT_NEAR(vel.x(), 0, 1e-6 * v);
}

INSTANTIATE_TEST_SUITE_P(AcrossAndAlong, SinkingTest,
                         ::testing::Values(SinkingCase{R"({"x": 1})", true},
                                           SinkingCase{R"({"y": -1})", false}));

// The drag's share of the Newton matrix is its velocity derivative: central
// differences of the force (smooth where neither part of the relative
// velocity vanishes, as with these rates and this current) on a spatial
// cable in a current with both drag coefficients.
TEST(DragTest, TangentIsMinusForceDerivativeInRates) {
  const Scene scene = SceneFromJson(R"({
    "model": "SPATIAL", "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "current": {"x": 0.7, "z": 0.2}},
    "cables": [{"name": "c", "points": [{"x": 0}, {"x": 0.3, "y": -1}, {"x": 0.5, "y": -2}],
                "elements": 5, "density": 1500, "youngs_modulus": 1e8, "diameter": 0.03,
                "hydrodynamics": {"normal_drag": 1.2, "tangential_drag": 0.3,
                                  "added_mass": 1, "diameter": 0.04}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": {"duration": 1}})");
  auto built = MultibodyModel::Build(scene);
  ASSERT_TRUE(built.ok()) << built.status();
  MultibodyModel& model = *built;
  ASSERT_TRUE(model.has_damping());
  double size = 0;
  const double worst = testing::DampingTangentError(model, {}, 1e-6, &size);
  EXPECT_GT(size, 0);
  // Central differences of a smooth function: O(step^2) = 1e-12 relative,
  // plus rounding eps |f| / step = 1e-10 relative.
  EXPECT_LE(worst, 1e-7 * size);
}

// Drag and buoyancy need a fluid.
TEST(DragTest, HydrodynamicsWithoutFluidIsRejectedByName) {
  auto proto = ParseSceneJson(R"({"cables": [{"name": "c", "length": 1, "density": 1000,
      "youngs_modulus": 1e9, "diameter": 0.01, "hydrodynamics": {"normal_drag": 1}}]})");
  ASSERT_TRUE(proto.ok());
  auto s = SceneFromProto(*proto);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("cables[0].hydrodynamics"), std::string::npos)
      << s.status();
}

}  // namespace
}  // namespace cablesim
