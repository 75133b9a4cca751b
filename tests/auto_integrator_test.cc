// solver.integrator AUTO_STEPPER (engine/run/auto_integrator.h): the choice
// and its reason, and that the run it makes is the named stepper's run to
// the bit (the trial start leaves the model as it was).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_replace.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

class KeepSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame& f) override {
    frames.push_back(f);
    return absl::OkStatus();
  }
  std::vector<Frame> frames;
};

struct Result {
  RunSummary summary;
  std::vector<Frame> frames;
};

Result RunJson(const std::string& json) {
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  KeepSink sink;
  absl::StatusOr<RunSummary> summary = RunScene(*scene, &sink);
  EXPECT_TRUE(summary.ok()) << summary.status();
  return {*summary, sink.frames};
}

// A 2 m steel-like rope pinned at one end to ground, falling from the
// horizontal (no constraint rows: the ground pin is eliminated); `extra`
// spliced into its solver section and `more` into the scene.
std::string Rope(const std::string& extra, const std::string& more = "") {
  return R"({"name": "rope", "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "start": {"x": 0, "y": 0}, "direction": {"x": 1},
                "length": 2, "elements": 10, "density": 1000, "youngs_modulus": 1e8,
                "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}}],
    "probes": [{"name": "tip", "cable": "rope", "s": 2}], )" +
         more + R"(
    "solver": {"analysis": "DYNAMIC", "duration": 0.05, "output_interval": 0.005, )" + extra +
         "}}";
}

void ExpectSameFrames(const Result& a, const Result& b) {
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t i = 0; i < a.frames.size(); ++i) {
    EXPECT_EQ(a.frames[i].t, b.frames[i].t);
    ASSERT_EQ(a.frames[i].probes.size(), b.frames[i].probes.size());
    for (size_t k = 0; k < a.frames[i].probes.size(); ++k) {
      EXPECT_EQ(a.frames[i].probes[k].position_m, b.frames[i].probes[k].position_m) << i;
      EXPECT_EQ(a.frames[i].probes[k].velocity_m_s, b.frames[i].probes[k].velocity_m_s) << i;
    }
  }
}

TEST(AutoIntegratorTest, ExplicitWhenNothingRulesItOutAndTheSameRunAsNamed) {
  const Result chosen = RunJson(Rope(R"("step": 1e-4, "integrator": "AUTO_STEPPER")"));
  EXPECT_EQ(chosen.summary.status, "ok");
  EXPECT_EQ(chosen.summary.integrator, "CENTRAL_DIFFERENCE");
  EXPECT_EQ(chosen.summary.integrator_requested, "AUTO");
  EXPECT_TRUE(absl::StrContains(chosen.summary.integrator_reason, "no constraint rows"))
      << chosen.summary.integrator_reason;
  const Result named = RunJson(Rope(R"("step": 1e-4, "integrator": "CENTRAL_DIFFERENCE")"));
  EXPECT_EQ(named.summary.integrator_requested, "CENTRAL_DIFFERENCE");
  EXPECT_TRUE(named.summary.integrator_reason.empty());
  ExpectSameFrames(chosen, named);
}

// omega_max of this rope: c = sqrt(E / rho) = 316 m/s over 0.2 m elements,
// about 1e4 rad/s: a step of 5e-3 s is far beyond h omega_max = 2.
TEST(AutoIntegratorTest, ImplicitWhenTheStepIsBeyondTheExplicitLimit) {
  const Result chosen = RunJson(Rope(R"("step": 5e-3, "integrator": "AUTO_STEPPER")"));
  EXPECT_EQ(chosen.summary.integrator, "HHT");
  EXPECT_TRUE(absl::StrContains(chosen.summary.integrator_reason, "CENTRAL_DIFFERENCE does not fit"))
      << chosen.summary.integrator_reason;
  ExpectSameFrames(chosen, RunJson(Rope(R"("step": 5e-3, "integrator": "HHT")")));
}

TEST(AutoIntegratorTest, ImplicitForImplicitSettingsConstraintsAndContact) {
  EXPECT_TRUE(absl::StrContains(
      RunJson(Rope(R"("step": 1e-4, "integrator": "AUTO_STEPPER", "rho_infinity": 0.8)"))
          .summary.integrator_reason,
      "HHT: solver.rho_infinity is given"));
  EXPECT_TRUE(absl::StrContains(
      RunJson(Rope(R"("step": 1e-4, "integrator": "AUTO_STEPPER")",
               R"("seabed": {"depth": 1.5, "stiffness": 1e5},)"))
          .summary.integrator_reason,
      "HHT: the seabed's contact"));
  // A body on the rope's end: constraint rows.
  const std::string with_body = absl::StrReplaceAll(
      Rope(R"("step": 1e-4, "integrator": "AUTO_STEPPER")",
           R"("bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                          "position": {"x": 2, "y": 0}}],)"),
      {{R"("joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}}])",
        R"("joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}},
                      {"type": "PIN", "a": {"cable": "rope", "s": 2}, "b": {"body": "b"}}])"}});
  // Adaptive steps with rows keep HHT.
  const Result body = RunJson(absl::StrReplaceAll(
      with_body, {{R"("integrator": "AUTO_STEPPER")",
                   R"("integrator": "AUTO_STEPPER", "adaptive": true, "tolerance": 1e-4)"}}));
  EXPECT_EQ(body.summary.integrator, "HHT");
  EXPECT_TRUE(absl::StrContains(body.summary.integrator_reason, "constraint rows"))
      << body.summary.integrator_reason;
}

TEST(AutoIntegratorTest, CentralDifferenceWithConstraintRowsAtAFixedStableStep) {
  // The rope with a body pinned to its end: 9 rows. At a fixed step within
  // the stable step (omega_max about 1e4 rad/s, 1e-4 s) AUTO takes
  // CENTRAL_DIFFERENCE, the same run as named; beyond it (5e-3 s), HHT.
  const std::string more = R"("bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                          "position": {"x": 2, "y": 0}}],)";
  const auto with_body = [&](const std::string& solver) {
    return absl::StrReplaceAll(
        Rope(solver, more),
        {{R"("joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}}])",
          R"("joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}},
                        {"type": "PIN", "a": {"cable": "rope", "s": 2}, "b": {"body": "b"}}])"}});
  };
  const Result chosen = RunJson(with_body(R"("step": 1e-4, "integrator": "AUTO_STEPPER")"));
  EXPECT_EQ(chosen.summary.status, "ok");
  EXPECT_EQ(chosen.summary.integrator, "CENTRAL_DIFFERENCE");
  EXPECT_TRUE(absl::StrContains(chosen.summary.integrator_reason, "constraint rows held by RATTLE"))
      << chosen.summary.integrator_reason;
  ExpectSameFrames(chosen,
                   RunJson(with_body(R"("step": 1e-4, "integrator": "CENTRAL_DIFFERENCE")")));
  EXPECT_EQ(RunJson(with_body(R"("step": 5e-3, "integrator": "AUTO_STEPPER")")).summary.integrator,
            "HHT");
}

TEST(AutoIntegratorTest, CentralDifferenceWhenAdaptive) {
  const Result chosen =
      RunJson(Rope(R"("step": 1e-4, "integrator": "AUTO_STEPPER", "adaptive": true, "tolerance": 1e-4)"));
  EXPECT_EQ(chosen.summary.status, "ok");
  EXPECT_EQ(chosen.summary.integrator, "CENTRAL_DIFFERENCE");
}

TEST(AutoIntegratorTest, NamedSteppersAreKept) {
  const Result named = RunJson(Rope(R"("step": 1e-4)"));
  EXPECT_EQ(named.summary.integrator, "HHT");
  EXPECT_EQ(named.summary.integrator_requested, "HHT");
  EXPECT_TRUE(named.summary.integrator_reason.empty());
}

}  // namespace
}  // namespace cablesim
