// A FIXED joint to ground that turns (Joint.rotation, rotation_axis): the
// held body's axes or cable slope turn by R(theta(t)) about the axis,
// through rows n(t) . x = 0 whose normals turn with the support; their
// Phi_t and Phi_tt enter the initial velocity and the consistent
// acceleration, and the support's work enters the energy balance.

#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using Eigen::Vector3d;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kPi = std::numbers::pi;

// theta(t) = s t + h sin(W t) + k (1 - cos W t), W = pi rad/s.
constexpr double kW = 2 * kPi * 0.5;
struct Law {
  double s, h, k;
  double Theta(double t) const { return s * t + h * std::sin(kW * t) + k * (1 - std::cos(kW * t)); }
  double Rate(double t) const { return s + h * kW * std::cos(kW * t) + k * kW * std::sin(kW * t); }
  double Accel(double t) const {
    return -h * kW * kW * std::sin(kW * t) + k * kW * kW * std::cos(kW * t);
  }
  std::string Json(const Vector3d& axis) const {
    // (%.17g: StrCat's 6 digits would shift theta by 5e-8 rad.)
    return absl::StrFormat(
        R"("rotation": {"constant": %.17g, "ramp": {"slope": %.17g}, "sum": [
              {"harmonic": {"amplitude": %.17g, "frequency": 0.5}},
              {"harmonic": {"amplitude": %.17g, "frequency": 0.5, "phase": %.17g}}]},
            "rotation_axis": {"x": %.17g, "y": %.17g, "z": %.17g})",
        k, s, h, -k, kPi / 2, axis.x(), axis.y(), axis.z());
  }
};
// From rest without a jolt: theta' = A (1 - cos W t), theta'' = A W sin W t
// (A = 0.5 rad/s), both 0 at t = 0.
constexpr Law kFromRest{0.5, -0.5 / kW, 0};
// Already turning at t = 0 (theta'(0) = 0.5 rad/s, theta''(0) = 0.99
// rad/s^2), so the support's Phi_t enters the initial velocity and its
// Phi_tt the initial acceleration.
constexpr Law kTurning{1.0, -0.5 / kW, 0.1};

Vector3d Rotate(const Vector3d& axis, double angle, const Vector3d& v) {
  return Eigen::AngleAxisd(angle, axis.normalized()) * v;
}

struct BodyCase {
  const char* integrator;
  Vector3d axis;  // (0, 0, 1): the planar model; otherwise spatial
};

class TurningBodyTest : public ::testing::TestWithParam<BodyCase> {};

// A body welded at its point p = (0.5, 0, 0) (body axes = world axes at
// t = 0) to a support at the origin that turns about `axis` (already
// turning at t = 0, kTurning): the body is then wholly prescribed. Its
// centre is at c(t) = R(theta) c0 with velocity theta' a x c and
// acceleration theta'' a x c + theta'^2 a x (a x c) (exact), and the
// support's force on it is m (c'' - g). Positions are held to Newton's
// tolerance (1e-10 asked), tolerance 1e-9 m. Velocities, accelerations
// and the force are the steppers', second order in h = 1e-3: measured
// 5.5e-7 m/s and 5.4e-6 m/s^2 (force / m likewise); tolerances 1e-5 and
// 1e-4, against values of order 0.5. HHT's accelerations are those of its
// shifted equilibrium, first order in h (measured 1.6e-3 m/s^2, tolerance
// 2e-3), while its force is second order like the others. A normal that
// did not turn leaves the body where it was (0.39 m off or more); without
// the support's Phi_t in the initial velocity the velocity is off by 0.25
// m/s, without its Phi_tt in gamma the acceleration by 0.49 m/s^2
// (measured by removing each).
TEST_P(TurningBodyTest, BodyFollowsTheSupportsRotation) {
  const BodyCase& c = GetParam();
  const Vector3d a = c.axis.normalized();
  const std::string json = absl::StrCat(R"({"gravity": {"y": -9.81},
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 0.1, "y": 0.15, "z": 0.2},
                "position": {"x": -0.5}}],
    "joints": [{"type": "FIXED", "a": {"body": "b", "point": {"x": 0.5}}, )",
                                        kTurning.Json(c.axis), R"(}],
    "probes": [{"name": "centre", "body": "b"}, {"name": "support", "body": "b",
                "point": {"x": 0.5}}],
    "solver": {"duration": 2, "step": 1e-3, "output_interval": 0.05,
               "newton_tolerance": 1e-10, "integrator": ")",
                                        c.integrator, R"("}})");
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  EXPECT_EQ(sink.info().model, c.axis.head<2>().isZero() ? "planar" : "spatial");
  ASSERT_EQ(sink.info().force_probe_names, std::vector<std::string>{"support"});
  const Vector3d c0(-0.5, 0, 0), g(0, -9.81, 0);
  double worst_v = 0, worst_a = 0, worst_f = 0, turned = 0;
  for (const Frame& f : sink.frames()) {
    const Law& law = kTurning;
    const Vector3d r = Rotate(a, law.Theta(f.t), c0);
    const Vector3d v = law.Rate(f.t) * a.cross(r);
    const Vector3d acc = law.Accel(f.t) * a.cross(r) +
                         law.Rate(f.t) * law.Rate(f.t) * a.cross(a.cross(r));
    EXPECT_LT((f.probes[0].position_m - r).norm(), 1e-9) << f.t;
    EXPECT_LT(f.probes[1].position_m.norm(), 1e-9) << f.t;
    worst_v = std::max(worst_v, (f.probes[0].velocity_m_s - v).norm());
    worst_a = std::max(worst_a, (f.probes[0].acceleration_m_s2 - acc).norm());
    ASSERT_EQ(f.support_forces.size(), 1u);
    worst_f = std::max(worst_f, (f.support_forces[0] / 2 - (acc - g)).norm());
    turned = std::max(turned, (r - c0).norm());
  }
  EXPECT_GT(turned, 0.3);  // the support did turn the body (0.39 m or more)
  EXPECT_LT(worst_v, 1e-5) << c.integrator;
  EXPECT_LT(worst_a, std::string(c.integrator) == "HHT" ? 2e-3 : 1e-4) << c.integrator;
  EXPECT_LT(worst_f, 1e-4) << c.integrator;
  // The support's work is in the balance: the body's kinetic energy
  // reaches 0.5 J and its potential changes by up to m g 0.5 = 9.8 J,
  // while the total holds to the work formula's second-order error
  // (measured 4e-6 J; tolerance 1e-5 J).
  EXPECT_NEAR(s.energy_final, s.energy_initial, 1e-5) << c.integrator;
}

INSTANTIATE_TEST_SUITE_P(
    Steppers, TurningBodyTest,
    ::testing::Values(BodyCase{"HHT", Vector3d(0, 0, 1)},
                      BodyCase{"GENERALIZED_ALPHA", Vector3d(0, 0, 1)},
                      BodyCase{"HHT", Vector3d(1, 1, 1)},
                      BodyCase{"GENERALIZED_ALPHA", Vector3d(0, 0.6, 0.8)}),
    [](const ::testing::TestParamInfo<BodyCase>& info) {
      return absl::StrCat(info.param.integrator,
                          info.param.axis.head<2>().isZero() ? "_Planar" : "_Spatial",
                          info.index);
    });

// A steel rod (1 m, d = 0.02 m) clamped at its root to a support that
// turns it, without gravity: a slewing boom. The rod is stiff (first
// bending frequency 14 Hz against the 0.5 Hz of theta''), so it turns
// rigidly but for the quasi-static lag that its own inertia bends into
// it: the load rho A theta'' x per unit length, a triangular load, bends
// the tip back by w = 11 q0 L^4 / (120 EI), q0 = rho A theta'' L (Euler-
// Bernoulli; 2.3e-4 m at most). The tip is then at R(theta) (L e_x) - w
// (a x R(theta) e_x), up to the vibration the smooth start excites
// (theta''' / (omega_1 theta'') times w, about 1e-5 m), the stretch by
// the centrifugal force (1e-9 m) and the steppers' error: measured 8.3e-6
// m with 6 elements and h = 1e-3, tolerance 2e-5 m: without the lag the error is 2.3e-4 m; a clamp that held the
// initial slope would not turn the rod at all (1 m off).
class TurningClampTest : public ::testing::TestWithParam<BodyCase> {};

TEST_P(TurningClampTest, SlewedRodTurnsWithItsQuasiStaticLag) {
  const BodyCase& c = GetParam();
  const Vector3d a = c.axis.normalized();
  const std::string json = absl::StrCat(R"({
    "cables": [{"name": "rod", "points": [{"x": 0}, {"x": 1}], "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.02, "elements": 6}],
    "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}, )",
                                        kFromRest.Json(c.axis), R"(}],
    "probes": [{"name": "tip", "cable": "rod", "s": 1}, {"name": "root", "cable": "rod", "s": 0}],
    "solver": {"duration": 2, "step": 1e-3, "output_interval": 0.02,
               "newton_tolerance": 1e-10, "integrator": ")",
                                        c.integrator, R"("}})");
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  EXPECT_EQ(sink.info().model, c.axis.head<2>().isZero() ? "planar" : "spatial");
  const double area = kPi * 0.02 * 0.02 / 4, inertia = kPi * std::pow(0.02, 4) / 64;
  const double rho_a = 7850 * area, ei = 2e11 * inertia;
  double worst = 0, lag = 0;
  for (const Frame& f : sink.frames()) {
    const Vector3d along = Rotate(a, kFromRest.Theta(f.t), Vector3d::UnitX());
    const double w = 11 * rho_a * kFromRest.Accel(f.t) / (120 * ei);
    const Vector3d tip = along - w * a.cross(along);
    worst = std::max(worst, (f.probes[0].position_m - tip).norm());
    lag = std::max(lag, w);
    EXPECT_LT(f.probes[1].position_m.norm(), 1e-9) << f.t;
  }
  EXPECT_GT(lag, 2e-4);  // the lag is there to be compared
  EXPECT_LT(worst, 2e-5) << c.integrator;
  // Energy: the rod gains (1/2) (rho A L^3 / 3) theta'^2 = 0.41 J at
  // theta' = 1 rad/s, all of it the support's work; the total holds to
  // the steppers' and the work formula's error (measured 2e-9 J;
  // tolerance 1e-4 of the kinetic energy).
  double kinetic = 0;
  for (const Frame& f : sink.frames()) kinetic = std::max(kinetic, f.energy.kinetic);
  EXPECT_GT(kinetic, 0.3);
  EXPECT_NEAR(s.energy_final, s.energy_initial, 1e-4 * kinetic) << c.integrator;
}

INSTANTIATE_TEST_SUITE_P(
    Steppers, TurningClampTest,
    ::testing::Values(BodyCase{"HHT", Vector3d(0, 0, 1)},
                      BodyCase{"GENERALIZED_ALPHA", Vector3d(0, 0, 1)},
                      BodyCase{"HHT", Vector3d(0, 1, 0)},
                      BodyCase{"GENERALIZED_ALPHA", Vector3d(0, 0.6, 0.8)}),
    [](const ::testing::TestParamInfo<BodyCase>& info) {
      return absl::StrCat(info.param.integrator,
                          info.param.axis.head<2>().isZero() ? "_Planar" : "_Spatial",
                          info.index);
    });

// Bad input names the field: only a FIXED joint to ground turns, from 0 at
// t = 0, about a non-zero axis given only with a rotation.
TEST(TurningSupportValidationTest, NamesTheField) {
  auto validate = [](const std::string& joint) {
    const std::string json = absl::StrCat(
        R"({"cables": [{"name": "rod", "length": 1, "density": 7850, "youngs_modulus": 2e11,
                        "diameter": 0.02}], "joints": [)",
        joint, R"(], "solver": {"duration": 1}})");
    auto proto = ParseSceneJson(json);
    if (!proto.ok()) return proto.status();
    return SceneFromProto(*proto).status();
  };
  EXPECT_TRUE(validate(R"({"type": "FIXED", "a": {"cable": "rod"},
                           "rotation": {"ramp": {"slope": 1}}})")
                  .ok());
  absl::Status s = validate(R"({"type": "PIN", "a": {"cable": "rod"},
                                "rotation": {"ramp": {"slope": 1}}})");
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), ::testing::HasSubstr("joints[0].rotation: only a FIXED joint to ground"));
  s = validate(R"({"type": "FIXED", "a": {"cable": "rod"}, "rotation": {"constant": 0.1}})");
  EXPECT_THAT(s.message(), ::testing::HasSubstr("joints[0].rotation: must be 0 at t = 0"));
  s = validate(R"({"type": "FIXED", "a": {"cable": "rod"}, "rotation": {"ramp": {"slope": 1}},
                   "rotation_axis": {}})");
  EXPECT_THAT(s.message(), ::testing::HasSubstr("joints[0].rotation_axis: must be non-zero"));
  s = validate(R"({"type": "FIXED", "a": {"cable": "rod"}, "rotation_axis": {"y": 1}})");
  EXPECT_THAT(s.message(), ::testing::HasSubstr("joints[0].rotation_axis: only with rotation"));
}

}  // namespace
}  // namespace cablesim
