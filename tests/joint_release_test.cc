// Line failure (Joint.release): a joint lets go at a time or when its force
// first exceeds a breaking load; the run goes on with the part free, the
// summary lists the event, and the energy stays booked.

#include <cmath>
#include <string>
#include <vector>

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

using ::testing::HasSubstr;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kG = 9.81;

// A body of 2 kg pinned to ground 1 m to the left of its centre of mass,
// starting horizontal at rest: a physical pendulum swinging down, its pin
// letting go per `release` (a JSON object). Frames every step.
std::string Pendulum(const std::string& release, const std::string& integrator = "HHT") {
  return absl::StrFormat(R"({"model": "PLANAR", "gravity": {"y": -9.81},
    "bodies": [{"name": "bob", "mass": 2, "inertia": {"x": 0.02, "y": 0.02, "z": 0.03}}],
    "joints": [{"name": "pivot", "type": "PIN", "a": {"body": "bob", "point": {"x": -1}}%s}],
    "probes": [{"name": "c", "body": "bob"}],
    "output": {"reactions": true},
    "solver": {"duration": 0.6, "step": 0.01, "output_interval": 0.01,
               "integrator": "%s"}})",
                         release.empty() ? "" : absl::StrCat(", \"release\": ", release),
                         integrator);
}

const Frame& FrameAt(const CollectingSink& sink, double t) {
  for (const Frame& f : sink.frames())
    if (std::abs(f.t - t) < 1e-9) return f;
  ADD_FAILURE() << "no frame at t = " << t;
  return sink.frames().front();
}

// Released at t = 0.3 s, on a step end: from there the centre of mass
// falls freely from the position and velocity it had, r(t) = r0 + v0 (t -
// t0) + g (t - t0)^2 / 2. The centre of mass's equations are linear with
// a constant force (the joint was the only thing coupling them to the
// axes), and the Newmark-family update reproduces a constant acceleration
// exactly, so the tolerance is rounding: 1e-9 m on positions of order 1 m
// (Newton stops on a relative residual, 1e-10 by default, of a linear
// equation it solves in one iteration). Backward Euler's update is
// first order: under a constant g it lands exactly g h (t - t0) / 2 off
// the parabola (x_n = x0 + v0 t + g t^2 / 2 + g h t / 2, summing x_{k+1} =
// x_k + h v_{k+1}, v_{k+1} = v_k + h g), which the test adds. The pendulum
// before the release is the intact one's, frame for frame (bit for bit:
// the same steps).
TEST(JointReleaseTest, PendulumReleasedAtATimeFallsFreely) {
  for (const char* integrator : {"HHT", "GENERALIZED_ALPHA", "IMPLICIT_EULER"}) {
    SCOPED_TRACE(integrator);
    CollectingSink intact, sink;
    RunOk(SceneFromJson(Pendulum("", integrator)), &intact);
    const RunSummary summary = RunOk(SceneFromJson(Pendulum(R"({"time": 0.3})", integrator)),
                                     &sink);
    ASSERT_EQ(summary.releases.size(), 1u);
    const JointReleaseEvent& e = summary.releases[0];
    EXPECT_EQ(e.joint, 0);
    EXPECT_EQ(e.name, "pivot");
    EXPECT_EQ(e.cause, "time");
    EXPECT_NEAR(e.time_s, 0.3, 1e-12);
    const Frame& at = FrameAt(sink, 0.3);
    // The force it let go with is the one the frame at the release shows.
    EXPECT_NEAR(e.force_n, at.reactions[0].force.norm(), 1e-9 * e.force_n);
    EXPECT_GT(e.force_n, 1);  // a swinging pendulum's pin carries a force
    ASSERT_EQ(sink.frames().size(), intact.frames().size());
    for (size_t k = 0; k < sink.frames().size(); ++k) {
      const Frame& f = sink.frames()[k];
      if (f.t > 0.3 + 1e-9) {
        EXPECT_EQ(f.reactions[0].force.norm(), 0) << f.t;
        continue;
      }
      EXPECT_EQ(f.probes[0].position_m, intact.frames()[k].probes[0].position_m) << f.t;
    }
    const Eigen::Vector3d r0 = at.probes[0].position_m, v0 = at.probes[0].velocity_m_s;
    const Eigen::Vector3d g(0, -kG, 0);
    for (const Frame& f : sink.frames()) {
      if (f.t <= 0.3 + 1e-9) continue;
      const double dt = f.t - 0.3;
      Eigen::Vector3d expected = r0 + v0 * dt + 0.5 * g * dt * dt;
      if (std::string(integrator) == "IMPLICIT_EULER") expected += 0.5 * g * 0.01 * dt;
      EXPECT_LT((f.probes[0].position_m - expected).norm(), 1e-9) << f.t;
      EXPECT_LT((f.probes[0].velocity_m_s - (v0 + g * dt)).norm(), 1e-8) << f.t;
    }
    // It has left the intact pendulum's path.
    const Frame& last = sink.frames().back();
    EXPECT_GT((last.probes[0].position_m - intact.frames().back().probes[0].position_m).norm(), 0.1);
  }
}

// The run's clock goes on through the release: the stepper restarted there
// starts at the release time, so a time-varying load keeps its value. A
// horizontal load F_x = 10 t [N] on the 2 kg body: once free, its centre
// of mass accelerates at a_x = F_x(t) / m = 5 t exactly: backward Euler's
// and generalized-alpha's acceleration at a step's end satisfies the
// equations of motion at that time, to Newton's tolerance (1e-9 m/s^2).
// (HHT's is taken at t + alpha h, 5 h / 3 = 0.017 m/s^2 earlier here.) A
// clock restarted at 0 would give 5 (t - 0.3), 1.5 m/s^2 less.
TEST(JointReleaseTest, TimeGoesOnThroughTheRelease) {
  for (const char* integrator : {"IMPLICIT_EULER", "GENERALIZED_ALPHA"}) {
    SCOPED_TRACE(integrator);
    std::string json = Pendulum(R"({"time": 0.3})", integrator);
    const std::string probes = R"("probes": [)";
    json.replace(json.find(probes), probes.size(),
                 R"("loads": [{"at": {"body": "bob"},
                     "varying_force": {"x": {"ramp": {"slope": 10}}}}], "probes": [)");
    CollectingSink sink;
    const RunSummary summary = RunOk(SceneFromJson(json), &sink);
    ASSERT_EQ(summary.releases.size(), 1u);
    int checked = 0;
    for (const Frame& f : sink.frames()) {
      if (f.t <= 0.3 + 1e-9) continue;
      EXPECT_NEAR(f.probes[0].acceleration_m_s2.x(), 5 * f.t, 1e-9) << f.t;
      EXPECT_NEAR(f.probes[0].acceleration_m_s2.y(), -kG, 1e-9) << f.t;
      ++checked;
    }
    EXPECT_EQ(checked, 30);
  }
}

// Releasing does no work: energy.total goes on as before. ENERGY_MOMENTUM
// conserves the energy of the constrained pendulum and of free flight to
// Newton's tolerance and rounding (4e-13 J here), so every frame's total,
// before and after the release, is the initial one to 1e-9 of the largest
// term (m g d = 19.6 J): a release that did work, jumped the state or lost
// the work booked so far would show. The guard is not tripped (status ok).
TEST(JointReleaseTest, EnergyIsContinuousAtTheRelease) {
  CollectingSink sink;
  const RunSummary summary =
      RunOk(SceneFromJson(Pendulum(R"({"time": 0.3})", "ENERGY_MOMENTUM")), &sink);
  ASSERT_EQ(summary.releases.size(), 1u);
  for (const Frame& f : sink.frames()) EXPECT_NEAR(f.energy.total, 0, 1e-9 * 2 * kG) << f.t;
  EXPECT_LT(summary.energy_max_increase, 1e-9 * 2 * kG);
}

// A release time off the steps' grid: a step is cut to end on it, and the
// step after it returns to the grid, so that the frames on the grid stay
// step ends. After it the centre of mass's path is a parabola under g:
// its second differences over the frames are g dt^2 to rounding (1e-12 m
// on differences of positions of order 1 m).
TEST(JointReleaseTest, ReleaseTimeOffTheGridIsHitExactly) {
  CollectingSink sink;
  const RunSummary summary = RunOk(SceneFromJson(Pendulum(R"({"time": 0.3033})")), &sink);
  ASSERT_EQ(summary.releases.size(), 1u);
  EXPECT_NEAR(summary.releases[0].time_s, 0.3033, 1e-12);
  const std::vector<Frame>& frames = sink.frames();
  int checked = 0;
  for (size_t k = 1; k + 1 < frames.size(); ++k) {
    if (frames[k - 1].t < 0.3033) continue;
    const double dt = frames[k].t - frames[k - 1].t;
    const Eigen::Vector3d second =
        frames[k + 1].probes[0].position_m - 2 * frames[k].probes[0].position_m +
        frames[k - 1].probes[0].position_m;
    EXPECT_NEAR(second.y(), -kG * dt * dt, 1e-12) << frames[k].t;
    EXPECT_NEAR(second.x(), 0, 1e-12) << frames[k].t;
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

// A body of 10 kg hanging on a 2 m cable from a support, pulled down by a
// load growing at 100 N/s; the support's breaking load is 300 N. The
// support lets go at the end of the first step whose force exceeds it:
// every frame before (frames at every step) shows at most 300 N, and the
// reported force, above 300 N, is the frame's at the release.
TEST(JointReleaseTest, BreakingLoadLetsGoAtTheFirstStepAbove) {
  const std::string json = R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rope", "length": 2, "elements": 4, "density": 1000,
                "youngs_modulus": 1e9, "diameter": 0.01, "bending": "NONE",
                "points": [{"x": 0, "y": 0}, {"x": 0, "y": -2}]}],
    "bodies": [{"name": "weight", "mass": 10, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"y": -2}}],
    "joints": [
      {"name": "support", "type": "PIN", "a": {"cable": "rope", "s": 0},
       "release": {"breaking_load": 300}},
      {"type": "PIN", "a": {"cable": "rope", "s": 2}, "b": {"body": "weight"}}],
    "loads": [{"at": {"body": "weight"},
               "varying_force": {"y": {"ramp": {"slope": -100}}}}],
    "probes": [{"name": "w", "body": "weight"}],
    "output": {"reactions": true},
    "solver": {"duration": 3, "step": 0.005, "output_interval": 0.005,
               "initial_state": "STATIC"}})";
  CollectingSink sink;
  const RunSummary summary = RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(summary.releases.size(), 1u);
  const JointReleaseEvent& e = summary.releases[0];
  EXPECT_EQ(e.joint, 0);
  EXPECT_EQ(e.cause, "breaking_load");
  EXPECT_GT(e.force_n, 300);
  // The quasi-static support force is m g + rho A L g + F(t) = 98.1 + 1.54 +
  // 100 t: it passes 300 N near t = 2.0 s (the cable's stretch oscillation
  // adds a little): the release is there, not at the start nor never.
  EXPECT_NEAR(e.time_s, 2.0, 0.1);
  for (const Frame& f : sink.frames()) {
    if (f.t < e.time_s - 1e-9) {
      EXPECT_LE(f.reactions[0].force.norm(), 300) << f.t;
    } else if (std::abs(f.t - e.time_s) <= 1e-9) {
      EXPECT_NEAR(f.reactions[0].force.norm(), e.force_n, 1e-9 * e.force_n);
    } else {
      EXPECT_EQ(f.reactions[0].force.norm(), 0) << f.t;
    }
  }
  // Free: the weight accelerates down faster than g once the line is slack
  // (the load adds to its weight); 0.5 s after the release it has fallen
  // by more than g t^2 / 2.
  const Frame& at = FrameAt(sink, std::round(e.time_s / 0.005) * 0.005);
  const Frame& later = FrameAt(sink, std::round((e.time_s + 0.5) / 0.005) * 0.005);
  EXPECT_LT(later.probes[0].position_m.y() - at.probes[0].position_m.y(), -0.5 * kG * 0.25);
}

absl::Status Convert(const std::string& json) {
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  return SceneFromProto(*proto).status();
}

// Bad input is refused naming the field.
TEST(JointReleaseTest, BadReleaseIsRefusedNamingTheField) {
  auto pendulum_with = [](const std::string& joint_extra) {
    return absl::StrFormat(R"({"model": "PLANAR", "gravity": {"y": -9.81},
      "bodies": [{"name": "bob", "mass": 2, "inertia": {"x": 0.02, "y": 0.02, "z": 0.03}}],
      "joints": [{"type": "PIN", "a": {"body": "bob", "point": {"x": -1}}%s}],
      "solver": {"duration": 0.1, "step": 0.01}})",
                           joint_extra);
  };
  struct Case {
    std::string extra, field, says;
  };
  const std::vector<Case> cases = {
      {R"(, "release": {"breaking_load": 0})", "joints[0].release.breaking_load", "must be > 0"},
      {R"(, "release": {"breaking_load": -5})", "joints[0].release.breaking_load", "must be > 0"},
      {R"(, "release": {"time": -1})", "joints[0].release.time", "must be >= 0"},
      {R"(, "release": {})", "joints[0].release", "needs time or breaking_load"},
      {R"(, "release": {"time": 1}, "motion": {"x": {"ramp": {"slope": 1}}})",
       "joints[0].release", "moving"},
  };
  for (const Case& c : cases) {
    const absl::Status s = Convert(pendulum_with(c.extra));
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << c.extra << ": " << s;
    EXPECT_THAT(std::string(s.message()), HasSubstr(c.field)) << c.extra;
    EXPECT_THAT(std::string(s.message()), HasSubstr(c.says)) << c.extra;
  }
  // SLIDE, and a winch's end.
  const absl::Status slide = Convert(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                "diameter": 0.01}],
    "bodies": [{"name": "bob", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 0.5}}],
    "joints": [{"type": "SLIDE", "a": {"body": "bob"}, "b": {"cable": "c", "s": 0.5},
                "release": {"time": 1}}],
    "solver": {"duration": 0.1, "step": 0.01}})");
  EXPECT_EQ(slide.code(), absl::StatusCode::kInvalidArgument) << slide;
  EXPECT_THAT(std::string(slide.message()), HasSubstr("joints[0].release: not with type SLIDE"));
  const absl::Status winch = Convert(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                "diameter": 0.01, "points": [{"x": 0, "y": -1}, {"x": 0, "y": 0}],
                "winch": {"speed": {"constant": 0.1}}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1}, "release": {"time": 1}}],
    "solver": {"duration": 0.1, "step": 0.01}})");
  EXPECT_EQ(winch.code(), absl::StatusCode::kInvalidArgument) << winch;
  EXPECT_THAT(std::string(winch.message()), HasSubstr("joints[0].release: not at a winch's end"));
}

// No release asked: the summary lists none (and the model is the same).
TEST(JointReleaseTest, NoReleaseNoEvent) {
  CollectingSink sink;
  const RunSummary summary = RunOk(SceneFromJson(Pendulum("")), &sink);
  EXPECT_TRUE(summary.releases.empty());
}

}  // namespace
}  // namespace cablesim
