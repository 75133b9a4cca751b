// solver.initial_state: STATIC starts a DYNAMIC run from the static
// equilibrium under the scene's gravity and loads (issue 9). The scene: a
// 2 kg body clamped (FIXED) between two steel wires of 5 mm hung from two
// supports 2 m apart, laid out as polylines whose corners are far from
// equilibrium (started as given, the body whips by 0.13 m in 1 s).

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

std::string HungBody(const std::string& solver) {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "left", "elements": 20, "density": 7850, "youngs_modulus": 2e11,
                "diameter": 0.005,
                "points": [{"x": 0, "y": 0}, {"x": 0.9, "y": -0.5}, {"x": 0.95, "y": -0.5}]},
               {"name": "right", "elements": 20, "density": 7850, "youngs_modulus": 2e11,
                "diameter": 0.005,
                "points": [{"x": 1.05, "y": -0.5}, {"x": 1.1, "y": -0.5}, {"x": 2, "y": 0}]}],
    "bodies": [{"name": "box", "mass": 2, "inertia": {"x": 0.001, "y": 0.002, "z": 0.002},
                "position": {"x": 1, "y": -0.5}}],
    "joints": [{"type": "PIN", "a": {"cable": "left", "s": 0}},
               {"type": "PIN", "a": {"cable": "right", "s": 1.0795630140986999}},
               {"type": "FIXED", "a": {"cable": "left", "s": 1.0795630140986999},
                "b": {"body": "box", "point": {"x": -0.05}}},
               {"type": "FIXED", "a": {"cable": "right", "s": 0},
                "b": {"body": "box", "point": {"x": 0.05}}}],
    "probes": [{"name": "box", "body": "box"}, {"name": "wire", "cable": "left", "s": 0.5}],
    "solver": %s})",
                         solver);
}

// Every frame of 1 s within 1e-9 m of the equilibrium, with each
// second-order stepper; and that equilibrium is STATIC analysis's own (the
// same scene run as STATIC, to the same 1e-9 m).
TEST(InitialStateTest, BodyHungBetweenSupportsStaysAtTheStaticEquilibrium) {
  CollectingSink statics;
  RunOk(SceneFromJson(HungBody(R"({"analysis": "STATIC", "newton_tolerance": 1e-12})")),
        &statics);
  ASSERT_FALSE(statics.frames().empty());
  const Frame& eq = statics.frames().back();
  // The layout is far from it: the box sits 3 cm higher at equilibrium.
  ASSERT_GT(eq.probes[0].position_m.y() + 0.5, 0.01);
  for (const char* integrator : {"HHT", "GENERALIZED_ALPHA"}) {
    CollectingSink sink;
    const RunSummary s = RunOk(
        SceneFromJson(HungBody(absl::StrFormat(
            R"({"duration": 1, "step": 1e-3, "output_interval": 0.01, "integrator": "%s",
                "initial_state": "STATIC"})",
            integrator))),
        &sink);
    ASSERT_EQ(sink.frames().size(), 101u) << integrator;
    double worst = 0;
    for (const Frame& f : sink.frames())
      for (int p = 0; p < 2; ++p)
        worst = std::max(worst, (f.probes[p].position_m - eq.probes[p].position_m).norm());
    EXPECT_LE(worst, 1e-9) << integrator;
    EXPECT_EQ(s.rejected_steps, 0) << integrator;
  }
}

TEST(InitialStateTest, AsGivenIsTheDefaultAndWhips) {
  CollectingSink sink;
  RunOk(SceneFromJson(HungBody(R"({"duration": 0.2, "step": 1e-3, "output_interval": 0.01})")),
        &sink);
  double moved = 0;
  for (const Frame& f : sink.frames())
    moved = std::max(moved, (f.probes[0].position_m - sink.frames()[0].probes[0].position_m).norm());
  EXPECT_GT(moved, 0.01);
}

TEST(InitialStateTest, StaticStartIsForDynamicAnalysisOnly) {
  auto proto = ParseSceneJson(HungBody(R"({"analysis": "STATIC", "initial_state": "STATIC"})"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.status().message().find("solver.initial_state"), std::string::npos)
      << scene.status();
}

TEST(InitialStateTest, AStartWithoutEquilibriumFailsAtTimeZeroSayingWhy) {
  // A free cable has no equilibrium to start from.
  CollectingSink sink;
  auto summary = RunScene(SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "elements": 4, "density": 1000,
                "youngs_modulus": 1e9, "diameter": 0.01}],
    "solver": {"duration": 0.1, "initial_state": "STATIC", "load_steps": 1,
               "max_step_halvings": 1}})"),
                          &sink);
  ASSERT_TRUE(summary.ok()) << summary.status();
  EXPECT_EQ(summary->status, "failed");
  EXPECT_EQ(summary->failure_time_s, 0);
  EXPECT_NE(summary->error.find("solver.initial_state STATIC: "), std::string::npos)
      << summary->error;
  EXPECT_NE(summary->error.find("no static equilibrium"), std::string::npos) << summary->error;
}

}  // namespace
}  // namespace cablesim
