// Winches (Cable.winch, MultibodyModel's axially moving mesh): a stiff,
// light cable reeled in with a swinging payload against the variable-length
// pendulum with the cable as a rigid rod; a vertical cable reeled in and
// paid out: its mass rho A L(t), its tension (m + rho A L(t)) g once the
// start's transient is damped, the payload back at its start after paying
// out and reeling in the same length; the scene validation; planar and
// spatial.

#include <cmath>
#include <ostream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/scene/time_function.h"
#include "test_util.h"

namespace cablesim {
namespace {

constexpr double kG = 9.81;

using testing::BuildStatus;
using testing::CollectingSink;
using testing::ProbeIndex;
using testing::RunOk;
using testing::SceneFromJson;
using ::testing::HasSubstr;

// --- The pendulum -----------------------------------------------------------
//
// A payload m on a cable of mass per length mu whose free length L(t)
// shrinks, swinging about the winch: as a rigid rod of length L(t) with a
// point mass at its end, the angular momentum about the winch is
// H = (m L^2 + mu L^3 / 3) theta' (the material's radial velocity carries
// none), the material leaves through the winch itself (no angular momentum
// leaves with it), so dH/dt = -(m L + mu L^2 / 2) g sin theta. With mu = 0
// it is the variable-length pendulum d/dt(m L^2 theta') = -m g L sin theta.
struct Pendulum {
  double m, mu, l0;
  TimeFunction speed;
  double L(double t) const { return l0 + speed.Integral(t); }
  // y = (theta, H).
  Eigen::Vector2d Rate(double t, const Eigen::Vector2d& y) const {
    const double l = L(t), inertia = m * l * l + mu * l * l * l / 3;
    return {y(1) / inertia, -(m * l + mu * l * l / 2) * kG * std::sin(y(0))};
  }
  // theta(t) by classical Runge-Kutta with n steps from theta0 at rest.
  double Theta(double theta0, double t_end, int n) const {
    Eigen::Vector2d y(theta0, 0);
    const double h = t_end / n;
    for (int i = 0; i < n; ++i) {
      const double t = i * h;
      const Eigen::Vector2d k1 = Rate(t, y), k2 = Rate(t + h / 2, y + h / 2 * k1),
                            k3 = Rate(t + h / 2, y + h / 2 * k2), k4 = Rate(t + h, y + h * k3);
      y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return y(0);
  }
};

// The winch at the origin, the cable (2 m, 8 elements) from a 10 kg payload
// at angle theta0 from the downward vertical up to it; reeled in from rest
// at 0.4 m/s^2 to 0.4 m/s (speed -0.4 min(t, 1)), so L(3 s) = 1.0 m. Steel
// (E = 2e11 Pa) of diameter 8 mm and density 1000 kg/m^3: EA = 1.0e7 N,
// mu = 0.0503 kg/m (0.5 % of the payload's mass per metre).
std::string ReelInPendulum(double theta0, const std::string& model) {
  const double x = 2 * std::sin(theta0), y = -2 * std::cos(theta0);
  return absl::StrCat(R"({"gravity": {"y": -9.81}, "model": ")", model, R"(",
    "cables": [{"name": "rope", "start": {"x": )", x, R"(, "y": )", y,
                      R"(}, "direction": {"x": )", -x / 2, R"(, "y": )", -y / 2, R"(},
                "length": 2, "elements": 8,
                "density": 1000, "youngs_modulus": 2e11, "diameter": 0.008,
                "winch": {"speed": {"ramp": {"slope": -0.4}, "sum": [{"ramp": {"slope": 0.4, "start": 1}}]}}}],
    "bodies": [{"name": "load", "mass": 10, "inertia": {"x": 1e-3, "y": 1e-3, "z": 1e-3},
                "position": {"x": )", x, R"(, "y": )", y, R"(}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 2}},
               {"type": "PIN", "a": {"cable": "rope", "s": 0}, "b": {"body": "load"}}],
    "probes": [{"name": "load", "body": "load"}, {"name": "winch", "cable": "rope", "s": 2}],
    "solver": {"duration": 3, "step": 0.0005, "output_interval": 0.1}})");
}

class PendulumTest : public ::testing::TestWithParam<const char*> {};

// theta(t) = atan2(x, -y) of the payload against the rigid-rod reference at
// every 0.1 s over 3 s (two swings, L from 2 m to 1 m). Expected error: the
// cable stretches by eps = (m + mu L) g / EA ~ 1e-5 (plus the swing's
// centrifugal share), which lengthens the period by eps / 2 and shifts
// the phase by about 2 pi (t / T) eps / 2 ~ 3e-5 rad times the amplitude
// (0.45 rad at most): ~1.5e-5 rad; halving the step changes the error by
// less than 1e-6 (measured: 2.38e-5 at h = 5e-4 s, 2.3e-5 at 2.5e-4 s), so
// the stretch it is. Tolerance 1e-4 rad. Leaving the cable's mass out of
// the reference (the massless variable-length pendulum) is 2e-3 rad off:
// the test sees the cable's mass and its ALE inertia.
TEST_P(PendulumTest, FollowsTheVariableLengthPendulum) {
  const double theta0 = 0.3;
  const Scene scene = SceneFromJson(ReelInPendulum(theta0, GetParam()));
  CollectingSink sink;
  RunOk(scene, &sink);
  const int p = ProbeIndex(sink.info(), "load");
  ASSERT_GE(p, 0);
  ASSERT_EQ(sink.frames().size(), 31u);
  const double mu = 1000 * std::acos(-1.0) * 0.008 * 0.008 / 4;
  const Pendulum ref{10, mu, 2, scene.cables[0].winch.speed};
  const Pendulum massless{10, 0, 2, scene.cables[0].winch.speed};
  EXPECT_NEAR(ref.L(3), 1.0, 1e-15);
  double worst = 0, worst_massless = 0;
  for (const Frame& f : sink.frames()) {
    const Eigen::Vector3d r = f.probes[p].position_m;
    const double theta = std::atan2(r.x(), -r.y());
    const int n = std::max(1, static_cast<int>(std::ceil(f.t / 1e-4)));
    const double a = ref.Theta(theta0, f.t, n);
    // The reference's own error: halving its step changes it by < 1e-10.
    EXPECT_NEAR(a, ref.Theta(theta0, f.t, 2 * n), 1e-10) << "t = " << f.t;
    EXPECT_NEAR(theta, a, 1e-4) << "t = " << f.t;
    worst = std::max(worst, std::abs(theta - a));
    worst_massless = std::max(worst_massless, std::abs(theta - massless.Theta(theta0, f.t, n)));
  }
  std::printf("%s: largest |theta - theta_ref| %.3g rad (massless reference: %.3g rad)\n",
              GetParam(), worst, worst_massless);
  EXPECT_GT(worst_massless, 10 * 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Models, PendulumTest, ::testing::Values("PLANAR", "SPATIAL"));

// --- The vertical cable -----------------------------------------------------
//
// A 200 kg hook on a vertical steel cable (E = 1e11 Pa, d = 20 mm, 7850
// kg/m^3: EA = 3.14e7 N, mu = 2.47 kg/m), 5 m from the hook up to the
// winch at the origin, with axial Kelvin-Voigt damping (1 ms), starting
// from its static equilibrium. `speed` is the winch's speed function.
std::string VerticalCable(const std::string& speed, double duration, const std::string& model,
                          const std::string& integrator = "HHT") {
  return absl::StrCat(R"({"gravity": {"y": -9.81}, "model": ")", model, R"(",
    "cables": [{"name": "rope", "start": {"y": -5}, "direction": {"y": 1}, "length": 5,
                "elements": 10, "density": 7850, "youngs_modulus": 1e11, "diameter": 0.02,
                "damping": {"axial_time": 1e-3}, "winch": {"speed": )", speed, R"(}}],
    "bodies": [{"name": "hook", "mass": 200, "inertia": {"x": 5, "y": 5, "z": 5},
                "position": {"y": -5.3}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 5}},
               {"type": "PIN", "a": {"cable": "rope", "s": 0},
                "b": {"body": "hook", "point": {"y": 0.3}}}],
    "probes": [{"name": "hook", "body": "hook"}, {"name": "winch", "cable": "rope", "s": 5}],
    "solver": {"duration": )", duration, R"(, "step": 0.001, "output_interval": 0.25,
               "integrator": ")", integrator, R"(", "initial_state": "STATIC"}})");
}

// 0.4 m/s, reached at 0.5 s: in (sign -1) or out (+1).
std::string SteadySpeed(int sign) {
  return absl::StrCat(R"({"ramp": {"slope": )", 0.8 * sign, R"(}, "sum": [{"ramp": {"slope": )",
                      -0.8 * sign, R"(, "start": 0.5}}]})");
}

struct VerticalCase {
  int sign;
  const char* model;
  const char* integrator;
};

// Readable, stable test names (the default prints the struct's bytes,
// pointers included, which change from run to run).
void PrintTo(const VerticalCase& c, std::ostream* os) {
  *os << (c.sign < 0 ? "reel_in_" : "pay_out_") << c.model << "_" << c.integrator;
}

class VerticalTest : public ::testing::TestWithParam<VerticalCase> {};

// The winch tension (the winch-end probe's force) against (m + mu L(t)) g
// once the start's transient has decayed: at constant speed the material
// does not accelerate and the tension at the winch carries the hook and the
// cable below it. The axial mode (omega = sqrt(EA / (m L)) ~ 180 rad/s,
// damping ratio tau omega / 2 ~ 0.09) decays as exp(-16 t): by 2 s, 1.5 s
// after the speed's last kink, to 4e-11. The strain at the winch end of a
// cubic element is exact for a tension linear in s. Tolerance 1e-6 of the
// tension; the cable's mass is 5 to 6 % of it, so a mass that lagged L(t)
// by one step of 4e-4 m would show as 5e-7 ... and a mass fixed at L(0)
// as 2e-2. The probe's force points along the cable into the winch.
TEST_P(VerticalTest, TensionCarriesPayloadAndCableWeight) {
  const VerticalCase c = GetParam();
  const Scene scene = SceneFromJson(VerticalCable(SteadySpeed(c.sign), 5, c.model, c.integrator));
  CollectingSink sink;
  RunOk(scene, &sink);
  ASSERT_EQ(sink.info().force_probe_names.size(), 1u);
  EXPECT_EQ(sink.info().force_probe_names[0], "winch");
  const double mu = 7850 * std::acos(-1.0) * 0.02 * 0.02 / 4;
  const TimeFunction& speed = scene.cables[0].winch.speed;
  const int hook = ProbeIndex(sink.info(), "hook");
  int checked = 0;
  double worst_tension = 0, worst_y = 0, worst_v = 0;
  for (const Frame& f : sink.frames()) {
    const double l = 5 + speed.Integral(f.t);
    const double tension = (200 + mu * l) * kG;
    ASSERT_EQ(f.support_forces.size(), 1u);
    const Eigen::Vector3d force = f.support_forces[0];
    if (f.t >= 2) {
      EXPECT_NEAR(force.y(), tension, 1e-6 * tension) << "t = " << f.t;
      EXPECT_NEAR(force.x(), 0, 1e-9 * tension);
      // The hook rises or sinks with the winch: its height is -(L(t) + 0.3)
      // less the cable's static stretch int_0^L T(s) / EA ds (4e-4 m; to
      // L (T / EA)^2 ~ 3e-8 m).
      const double ea = 1e11 * std::acos(-1.0) * 0.02 * 0.02 / 4;
      const double stretch = (200 * kG * l + mu * kG * l * l / 2) / ea;
      EXPECT_NEAR(f.probes[hook].position_m.y(), -(l + 0.3 + stretch), 1e-7) << "t = " << f.t;
      // The hook's speed is the winch's times the stretch |r_s| = 1 + T / EA
      // (to (T / EA)^2 ~ 4e-9) of the material entering or leaving the
      // winch: the stretch of the material already out does not change.
      EXPECT_NEAR(f.probes[hook].velocity_m_s.y(), -c.sign * 0.4 * (1 + tension / ea), 1e-7)
          << "t = " << f.t;
      worst_tension = std::max(worst_tension, std::abs(force.y() / tension - 1));
      worst_y = std::max(worst_y, std::abs(f.probes[hook].position_m.y() + l + 0.3 + stretch));
      worst_v = std::max(worst_v, std::abs(f.probes[hook].velocity_m_s.y() +
                                           c.sign * 0.4 * (1 + tension / ea)));
      ++checked;
    }
  }
  EXPECT_EQ(checked, 13);
  std::printf("%s %s %s: tension relative error %.3g, hook height %.3g m, speed %.3g m/s\n",
              c.sign < 0 ? "reel-in" : "pay-out", c.model, c.integrator, worst_tension, worst_y,
              worst_v);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, VerticalTest,
    ::testing::Values(VerticalCase{-1, "PLANAR", "HHT"}, VerticalCase{+1, "PLANAR", "HHT"},
                      VerticalCase{-1, "SPATIAL", "HHT"},
                      VerticalCase{-1, "PLANAR", "GENERALIZED_ALPHA"},
                      VerticalCase{+1, "PLANAR", "IMPLICIT_EULER"}));

// The cable's mass, from its element mass matrices, is rho A L(t) at any
// time the model is set to (every stepper sets it before each step), and
// the free length is the initial length plus the speed's integral.
TEST(WinchTest, MassIsDensityTimesAreaTimesFreeLength) {
  const Scene scene = SceneFromJson(VerticalCable(SteadySpeed(-1), 5, "PLANAR"));
  auto model = MultibodyModel::Build(scene);
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->winches(), 1);
  const double mu = 7850 * std::acos(-1.0) * 0.02 * 0.02 / 4;
  for (double t : {0.0, 0.25, 0.5, 0.7385, 2.0, 4.999}) {
    model->SetTime(t);
    // L = 5 - 0.4 t^2 (t < 0.5), 5 - 0.1 - 0.4 (t - 0.5) after.
    const double l = t < 0.5 ? 5 - 0.4 * t * t : 4.9 - 0.4 * (t - 0.5);
    EXPECT_NEAR(model->WinchLength(0), l, 1e-14) << "t = " << t;
    EXPECT_NEAR(model->CableMass(0), mu * l, 1e-12 * mu * l) << "t = " << t;
  }
}

// Paying 0.8 m out and reeling it back in (speed 0 -> 0.4 -> -0.4 -> 0 m/s
// in 5 s) brings the hook back to its start: the same length holds the same
// static stretch. The axial transient of the last kink (at 5 s) decays as
// exp(-16 t) to 1e-14 by 7 s. Tolerance 1e-7 m: 1/3000 of the cable's
// static stretch (3e-4 m), so a mass or length that did not return would
// show.
TEST(WinchTest, PayOutThenReelInReturnsThePayload) {
  const std::string speed =
      R"({"table": {"times": [0, 0.5, 2, 3, 4.5, 5], "values": [0, 0.4, 0.4, -0.4, -0.4, 0]}})";
  const Scene scene = SceneFromJson(VerticalCable(speed, 7, "PLANAR"));
  EXPECT_NEAR(scene.cables[0].winch.speed.Integral(2.5), 0.8, 1e-15);
  EXPECT_NEAR(scene.cables[0].winch.speed.Integral(5), 0, 1e-15);
  CollectingSink sink;
  RunOk(scene, &sink);
  const int hook = ProbeIndex(sink.info(), "hook");
  const Frame& first = sink.frames().front();
  const Frame& last = sink.frames().back();
  ASSERT_NEAR(last.t, 7, 1e-12);
  const double back = (last.probes[hook].position_m - first.probes[hook].position_m).norm();
  EXPECT_NEAR(back, 0, 1e-7);
  std::printf("hook back at its start to %.3g m\n", back);
  double lowest = 0;
  for (const Frame& f : sink.frames()) lowest = std::min(lowest, f.probes[hook].position_m.y());
  EXPECT_NEAR(lowest, first.probes[hook].position_m.y() - 0.8, 1e-3);  // it did go down
}

// The sample crane runs: its winch lifts the hook by the 4 m it reels in
// while the boom tip slews, and the boom tip's probe reports the line
// tension, which swings about the weight it carries, (500 kg + rho A L) g:
// the lift's acceleration and deceleration (0.5 m/s^2: 5 %) and the
// swing's centripetal pull (measured: 7.7 % at most); bound 10 %.
TEST(WinchTest, CraneSceneRuns) {
  auto proto = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/crane-winch.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  ASSERT_EQ(sink.info().force_probe_names.size(), 1u);
  const int hook = ProbeIndex(sink.info(), "hook"), tip = ProbeIndex(sink.info(), "boom_tip");
  const Frame& first = sink.frames().front();
  const Frame& last = sink.frames().back();
  // 4 m reeled in, the hook's swing about the tip (< 0.1 rad on 4.4 m:
  // < 0.022 m of height) and the change of stretch (< 1e-3 m).
  EXPECT_NEAR(last.probes[hook].position_m.y() - first.probes[hook].position_m.y(), 4, 0.03);
  EXPECT_NEAR(last.probes[tip].position_m.x(), 2.7135254915622333, 1e-9);
  const double mu = 7850 * std::acos(-1.0) * 0.02 * 0.02 / 4;
  for (const Frame& f : sink.frames()) {
    const double weight = (500 + mu * (8 + scene->cables[0].winch.speed.Integral(f.t))) * kG;
    EXPECT_NEAR(f.support_forces[0].norm(), weight, 0.1 * weight) << "t = " << f.t;
  }
}

// --- Validation --------------------------------------------------------------

TEST(WinchValidationTest, NamesTheField) {
  EXPECT_TRUE(BuildStatus(VerticalCable(SteadySpeed(-1), 5, "PLANAR")).ok());
  absl::Status s = BuildStatus(
      VerticalCable(R"({"harmonic": {"amplitude": 1, "frequency": -1}})", 5, "PLANAR"));
  EXPECT_THAT(s.message(), HasSubstr("cables[0].winch.speed.harmonic.frequency: must be >= 0"));
  // Reeling 5 m in at 2 m/s takes 2.5 s.
  s = BuildStatus(VerticalCable(R"({"constant": -2})", 5, "PLANAR"));
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(s.message(), HasSubstr("cables[0].winch.speed: reels in the whole cable"));
  EXPECT_THAT(s.message(), HasSubstr("reaches 0 at t = 2.5 s"));
  // ... but not within 2 s.
  EXPECT_TRUE(BuildStatus(VerticalCable(R"({"constant": -2})", 2, "PLANAR")).ok());
  s = BuildStatus(VerticalCable(SteadySpeed(-1), 5, "PLANAR", "ENERGY_MOMENTUM"));
  EXPECT_THAT(s.message(), HasSubstr("solver.integrator: ENERGY_MOMENTUM does not take winches"));
  auto edit = [](std::string json, const std::string& from, const std::string& to) {
    const size_t at = json.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? json : json.replace(at, from.size(), to);
  };
  const std::string base = VerticalCable(SteadySpeed(-1), 5, "PLANAR");
  s = BuildStatus(edit(base, R"({"type": "PIN", "a": {"cable": "rope", "s": 5}},)", ""));
  EXPECT_THAT(s.message(), HasSubstr("cables[0].winch: the winch holds the cable's last point"));
  s = BuildStatus(edit(base, R"("name": "winch", "cable": "rope", "s": 5)",
                    R"("name": "winch", "cable": "rope", "s": 2)"));
  EXPECT_THAT(s.message(), HasSubstr("probes[1].at: a winch cable (cables[0].winch)"));
  s = BuildStatus(edit(base, R"("axial_time": 1e-3)", R"("bending_time": 1e-3)"));
  EXPECT_THAT(s.message(), HasSubstr("cables[0].damping: a winch cable takes axial_time"));
}

}  // namespace
}  // namespace cablesim
