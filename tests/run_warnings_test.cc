// Every DYNAMIC run's error estimate and warnings (engine/run/run_warnings.h,
// docs/honest-runs.md): the estimate against an analytic local error, the
// issue's reproducer (a 20 m steel wire lifting 500 kg at `step: 2`, a unit
// slip for 2 ms) warns and fails under strict, inexact solves warn, and a
// sound sample scene does not warn.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "absl/strings/match.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

class NullSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame&) override { return absl::OkStatus(); }
};

RunSummary RunJson(const std::string& json) {
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  NullSink sink;
  absl::StatusOr<RunSummary> summary = RunScene(*scene, &sink);
  EXPECT_TRUE(summary.ok()) << summary.status();
  return *summary;
}

bool HasWarning(const RunSummary& s, const std::string& part) {
  for (const std::string& w : s.warnings)
    if (absl::StrContains(w, part)) return true;
  return false;
}

// The reproducer of issue 32, `solver` appended to its solver section.
std::string Wire(const std::string& solver) {
  return R"({"name": "wire-lift", "gravity": {"y": -9.81},
    "cables": [{"name": "wire", "start": {"x": 0, "y": 0}, "direction": {"y": -1},
                "length": 20, "elements": 20, "density": 7850, "youngs_modulus": 2e11,
                "diameter": 0.02, "bending": "NONE"}],
    "bodies": [{"name": "load", "mass": 500, "inertia": {"x": 20, "y": 20, "z": 20},
                "position": {"x": 0, "y": -20.4}}],
    "joints": [{"type": "PIN", "a": {"cable": "wire", "s": 0}},
               {"type": "PIN", "a": {"cable": "wire", "s": 20},
                "b": {"body": "load", "point": {"y": 0.4}}}],
    "probes": [{"name": "top", "cable": "wire", "s": 0}],
    "solver": {"analysis": "DYNAMIC", )" +
         solver + "}}";
}

// Backward Euler's local position error for a body under constant gravity
// is exactly g h^2 / 2 (z1 = z0 + h v0 - g h^2 against z0 + h v0 - g h^2 / 2),
// and so is its estimate h |v1 - v0| / 2: they agree to rounding.
TEST(RunWarningsTest, LocalErrorEstimateOfAFreeFallIsAnalytic) {
  const RunSummary s = RunJson(R"({"name": "free-fall", "gravity": {"y": -9.81},
      "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 1, "y": 1, "z": 1}}],
      "probes": [{"name": "b", "body": "b"}],
      "solver": {"duration": 0.1, "step": 0.01, "integrator": "IMPLICIT_EULER"}})");
  ASSERT_EQ(s.status, "ok");
  const double h = 0.01, g = 9.81;
  EXPECT_NEAR(s.local_error_estimate_m, g * h * h / 2, 1e-15);
  EXPECT_EQ(s.error_tolerance_m, 0.01);  // no cable: 1 % of the 1 m floor
  EXPECT_TRUE(s.warnings.empty());
  // Held to a tolerance below it: one warning naming both numbers.
  const RunSummary tight = RunJson(R"({"name": "free-fall", "gravity": {"y": -9.81},
      "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 1, "y": 1, "z": 1}}],
      "probes": [{"name": "b", "body": "b"}],
      "solver": {"duration": 0.1, "step": 0.01, "integrator": "IMPLICIT_EULER",
                 "tolerance": 1e-4}})");
  EXPECT_EQ(tight.status, "ok");
  ASSERT_EQ(tight.warnings.size(), 1u);
  EXPECT_TRUE(HasWarning(tight, "(0.000491 m, local_error_estimate_m) exceeds the tolerance 0.0001 m"))
      << tight.warnings[0];
}

TEST(RunWarningsTest, TheWireAtStepTwoWarnsAndFailsUnderStrict) {
  const RunSummary s = RunJson(Wire(R"("duration": 10, "step": 2, "output_interval": 2)"));
  EXPECT_EQ(s.status, "ok");  // what it was before: finished, status ok
  EXPECT_DOUBLE_EQ(s.error_tolerance_m, 0.2);  // 1 % of the 20 m wire
  EXPECT_GT(s.local_error_estimate_m, s.error_tolerance_m);
  EXPECT_TRUE(HasWarning(s, "exceeds the tolerance")) << ::testing::PrintToString(s.warnings);
  EXPECT_TRUE(HasWarning(s, "steps were cut to")) << ::testing::PrintToString(s.warnings);

  const RunSummary strict =
      RunJson(Wire(R"("duration": 10, "step": 2, "output_interval": 2, "strict": true)"));
  EXPECT_EQ(strict.status, "failed");
  EXPECT_TRUE(absl::StartsWith(strict.error, "solver.strict: ")) << strict.error;
  EXPECT_EQ(strict.failure_time_s, strict.end_time_s);
  EXPECT_EQ(strict.warnings, s.warnings);
}

TEST(RunWarningsTest, InexactSolvesAccepted) {
  const RunSummary s = RunJson(Wire(R"("duration": 0.2, "step": 0.01, "output_interval": 0.1,
      "linear_solver": "MINRES", "max_linear_iterations": 2, "accept_inexact_solves": true)"));
  EXPECT_EQ(s.status, "ok");
  ASSERT_GT(s.inexact_linear_solves, 0);
  EXPECT_TRUE(HasWarning(s, "linear solves were accepted inexact"))
      << ::testing::PrintToString(s.warnings);
}

// The sample falling pendulum (its trajectory checked against the
// published one in scene_validation_test) raises no warning, and its
// estimate is reported with the tolerance it is held to.
TEST(RunWarningsTest, TheFallingPendulumIsQuiet) {
  absl::StatusOr<v1::Scene> proto =
      ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/falling-pendulum.json");
  ASSERT_TRUE(proto.ok()) << proto.status();
  proto->mutable_solver()->set_duration(0.2);
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  NullSink sink;
  absl::StatusOr<RunSummary> s = RunScene(*scene, &sink);
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->status, "ok");
  EXPECT_GT(s->local_error_estimate_m, 0);
  EXPECT_DOUBLE_EQ(s->error_tolerance_m, 0.012);  // 1 % of the 1.2 m beam
  // No run warning: only the scene's one plausibility warning (the paper's
  // soft beam would stretch 9 % hanging, tests/plausibility_warnings_test.cc).
  ASSERT_EQ(s->warnings, scene->warnings);
  ASSERT_EQ(s->warnings.size(), 1u) << ::testing::PrintToString(s->warnings);
  EXPECT_TRUE(absl::StrContains(s->warnings[0], "static strain"));
}

}  // namespace
}  // namespace cablesim
