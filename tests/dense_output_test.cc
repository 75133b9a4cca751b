// Frames between steps (dense output, simulation.cc RunDynamic): asking for
// frames never changes the steps, and an interpolated frame is as accurate
// as a step's own end state.

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// The paper's falling pendulum (12 elements, released horizontal) for
// `duration` s with HHT at `step`, frames every `interval` s.
std::string Pendulum(double duration, double step, double interval,
                     const std::string& extra = "") {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "beam", "length": 1.2, "elements": 12,
                "start": {"x": 0, "y": 0}, "direction": {"x": 1},
                "density": 5540, "youngs_modulus": 0.7e6,
                "area": 0.0018, "second_moment": 1.215e-8}],
    "joints": [{"type": "PIN", "a": {"cable": "beam", "s": 0}}],
    "probes": [{"name": "tip", "cable": "beam", "s": 1.2}],
    "solver": {"analysis": "DYNAMIC", "duration": %.17g, "step": %.17g,
               "output_interval": %.17g, "integrator": "HHT" %s}})",
                         duration, step, interval, extra);
}

// Frames every 1 ms with steps of 0.625 ms: 1,600 steps for 1 s, not the
// 2,000 that landing on every frame took, and the last frame (t = 1 s, a
// step's end) is the state of the run with a frame every step, to the
// rounding of the last step's length (t is kept on each run's own frame
// grid, so the final h differs in its last bits): 1e-12 m.
TEST(DenseOutputTest, FramesDoNotChangeTheSteps) {
  CollectingSink dense, every_step;
  const RunSummary a = RunOk(SceneFromJson(Pendulum(1.0, 6.25e-4, 1e-3)), &dense);
  const RunSummary b = RunOk(SceneFromJson(Pendulum(1.0, 6.25e-4, 6.25e-4)), &every_step);
  EXPECT_EQ(a.steps, 1600);
  EXPECT_EQ(b.steps, 1600);
  EXPECT_EQ(a.frames, 1001);
  EXPECT_EQ(dense.frames().back().t, 1.0);
  EXPECT_LE((dense.frames().back().probes[0].position_m -
             every_step.frames().back().probes[0].position_m)
                .norm(),
            1e-12);
}

// Frames may come faster than the steps: four per step.
TEST(DenseOutputTest, FramesMayBeCloserThanTheStep) {
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(Pendulum(0.1, 1e-3, 2.5e-4)), &sink);
  EXPECT_EQ(s.steps, 100);
  ASSERT_EQ(sink.frames().size(), 401u);
  for (size_t k = 0; k < sink.frames().size(); ++k)
    EXPECT_NEAR(sink.frames()[k].t, 2.5e-4 * k, 1e-12);
}

// The tip at frames between steps against a converged reference (h = 1e-5,
// a frame every step), beside the error at the steps' own ends: the
// interpolant's error, O(h^4), must not show above the stepper's, O(h^2).
// Steps of 2e-3 s, frames every 5e-4 s: a quarter of the frames are step
// ends. Tolerance: the worst interpolated frame within 1.5 times the worst
// step end (the interpolant adds, at most, a small fraction).
TEST(DenseOutputTest, InterpolatedFramesAreAsAccurateAsStepEnds) {
  CollectingSink ref, run;
  RunOk(SceneFromJson(Pendulum(0.5, 1e-5, 5e-4)), &ref);
  RunOk(SceneFromJson(Pendulum(0.5, 2e-3, 5e-4)), &run);
  ASSERT_EQ(ref.frames().size(), run.frames().size());
  double at_steps = 0, between = 0, v_at_steps = 0, v_between = 0;
  for (size_t k = 1; k < run.frames().size(); ++k) {
    const ProbeSample& p = run.frames()[k].probes[0];
    const ProbeSample& q = ref.frames()[k].probes[0];
    const double e = (p.position_m - q.position_m).norm();
    const double ev = (p.velocity_m_s - q.velocity_m_s).norm();
    if (k % 4 == 0) {
      at_steps = std::max(at_steps, e);
      v_at_steps = std::max(v_at_steps, ev);
    } else {
      between = std::max(between, e);
      v_between = std::max(v_between, ev);
    }
  }
  std::printf("tip error: step ends %.3g m, between %.3g m; velocity %.3g, %.3g m/s\n", at_steps,
              between, v_at_steps, v_between);
  EXPECT_GT(at_steps, 0);
  EXPECT_LE(between, 1.5 * at_steps);
  EXPECT_LE(v_between, 1.5 * v_at_steps);
}

// energy.damped between step ends: the trapezoidal rule's own interpolant
// (the dissipated power linear between the two ends, FrameRecorder::Damped),
// which costs no evaluation of the damping at a frame. Measured on what a
// step adds (energy.damped at a frame minus at the step's start, which
// removes the error accumulated over earlier steps) against a converged
// reference (h = 1e-5, a frame every step): its worst error at the frames
// between steps must stay within 1.5 times its worst at the step ends (the
// rule's O(h^3) per step; an interpolant of lower order, the power held at
// the step's start, is O(h^2) and shows as several times that). The step
// ends are the values of the run with a frame every step, to the last bit.
TEST(DenseOutputTest, DampedEnergyBetweenStepsIsAsAccurateAsAtStepEnds) {
  const std::string damped = R"(, "rho_infinity": 1)";
  const auto pendulum = [&](double step, double interval) {
    std::string json = Pendulum(0.5, step, interval, damped);
    const std::string density = R"("density": 5540,)";
    json.replace(json.find(density), density.size(),
                 R"("density": 5540, "damping": {"bending_time": 0.01},)");
    return json;
  };
  CollectingSink ref, run, every_step;
  RunOk(SceneFromJson(pendulum(1e-5, 5e-4)), &ref);
  RunOk(SceneFromJson(pendulum(2e-3, 5e-4)), &run);
  RunOk(SceneFromJson(pendulum(2e-3, 2e-3)), &every_step);
  ASSERT_EQ(ref.frames().size(), run.frames().size());
  ASSERT_EQ(every_step.frames().size(), (run.frames().size() - 1) / 4 + 1);
  double at_steps = 0, between = 0;
  for (size_t k = 1; k < run.frames().size(); ++k) {
    const size_t k0 = k - (k - 1) % 4 - 1;  // the step's start
    const double e = std::abs((run.frames()[k].energy.damped - run.frames()[k0].energy.damped) -
                              (ref.frames()[k].energy.damped - ref.frames()[k0].energy.damped));
    if (k % 4 == 0) {
      at_steps = std::max(at_steps, e);
      EXPECT_EQ(run.frames()[k].energy.damped, every_step.frames()[k / 4].energy.damped) << k;
    } else {
      between = std::max(between, e);
    }
  }
  std::printf("energy.damped added per step, error: step ends %.3g J, between %.3g J (of %.3g J)\n", at_steps,
              between, ref.frames().back().energy.damped);
  EXPECT_GT(ref.frames().back().energy.damped, 0);
  EXPECT_GT(at_steps, 0);
  EXPECT_LE(between, 1.5 * at_steps);
}

// A body thrown in gravity: HHT and generalized-alpha integrate a constant
// acceleration exactly at the step ends (backward Euler does not), and the cubic Hermite interpolant
// is exact for a parabola, so a frame between steps must be the parabola
// to rounding (linear interpolation of positions would be off by
// g h^2 / 8 = 3 mm mid-step with h = 0.05 s). Tolerance 1e-12 m over
// displacements of order 1 m.
TEST(DenseOutputTest, FramesBetweenStepsFollowAThrownBodyExactly) {
  for (const char* integrator : {"HHT", "GENERALIZED_ALPHA"}) {
    const std::string json = absl::StrFormat(R"({
      "gravity": {"y": -9.81},
      "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 0.1, "y": 0.1, "z": 0.1}}],
      "probes": [{"name": "p", "body": "b"}],
      "initial_velocity": {"linear": {"x": 1, "y": 3}},
      "solver": {"analysis": "DYNAMIC", "duration": 0.5, "step": 0.05,
                 "output_interval": 0.01, "integrator": "%s"}})",
                                             integrator);
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    ASSERT_EQ(sink.frames().size(), 51u);
    for (const Frame& f : sink.frames()) {
      const double t = f.t;
      const ProbeSample& p = f.probes[0];
      EXPECT_NEAR(p.position_m.x(), t, 1e-12) << integrator << " t = " << t;
      EXPECT_NEAR(p.position_m.y(), 3 * t - 0.5 * 9.81 * t * t, 1e-12) << integrator;
      EXPECT_NEAR(p.velocity_m_s.y(), 3 - 9.81 * t, 1e-11) << integrator;
      EXPECT_NEAR(p.acceleration_m_s2.y(), -9.81, 1e-11) << integrator;
    }
  }
}

// Adaptive steps go where the error controller sends them, whatever the
// frames: the same steps and the same end state with frames every 1 ms or
// every 50 ms.
TEST(DenseOutputTest, AdaptiveStepsIgnoreTheFrames) {
  const std::string adaptive = R"(, "adaptive": true, "tolerance": 1e-4)";
  CollectingSink fine, coarse;
  const RunSummary a = RunOk(SceneFromJson(Pendulum(0.5, 1e-3, 1e-3, adaptive)), &fine);
  const RunSummary b = RunOk(SceneFromJson(Pendulum(0.5, 1e-3, 5e-2, adaptive)), &coarse);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.rejected_steps, b.rejected_steps);
  EXPECT_EQ(fine.frames().back().probes[0].position_m,
            coarse.frames().back().probes[0].position_m);
}

}  // namespace
}  // namespace cablesim
