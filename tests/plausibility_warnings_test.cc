// Plausibility warnings (convert/plausibility_warnings.h, issue 32 item 4):
// the new user's unit slips on a 20 m steel wire lifting 500 kg each get
// their warning, naming the field, the value and the units; the sound wire
// gets none; the warnings never block a run and reach its summary; and the
// sample scenes get only the warnings listed (each explained) below.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_join.h"
#include "convert/plausibility_warnings.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

// The wire of issue 32 (tests/run_warnings_test.cc), with `cable` fields and
// `solver` fields spliced in.
std::string Wire(const std::string& cable, const std::string& solver) {
  return R"({"name": "wire-lift", "gravity": {"y": -9.81},
    "cables": [{"name": "wire", "start": {"x": 0, "y": 0}, "direction": {"y": -1},
                "length": 20, "elements": 20, "density": 7850, "bending": "NONE", )" +
         cable + R"(}],
    "bodies": [{"name": "load", "mass": 500, "inertia": {"x": 20, "y": 20, "z": 20},
                "position": {"x": 0, "y": -20.4}}],
    "joints": [{"type": "PIN", "a": {"cable": "wire", "s": 0}},
               {"type": "PIN", "a": {"cable": "wire", "s": 20},
                "b": {"body": "load", "point": {"y": 0.4}}}],
    "probes": [{"name": "top", "cable": "wire", "s": 0}],
    "solver": {"analysis": "DYNAMIC", "duration": 4, )" +
         solver + "}}";
}

std::vector<std::string> WarningsOf(const std::string& json) {
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? scene->warnings : std::vector<std::string>{};
}

bool Has(const std::vector<std::string>& warnings, const std::vector<std::string>& parts) {
  for (const std::string& w : warnings) {
    bool all = true;
    for (const std::string& p : parts) all = all && absl::StrContains(w, p);
    if (all) return true;
  }
  return false;
}

const char kSteel[] = R"("youngs_modulus": 2e11, "diameter": 0.02)";

TEST(PlausibilityWarningsTest, TheSoundWireHasNone) {
  const std::vector<std::string> w = WarningsOf(Wire(kSteel, R"("step": 0.002)"));
  EXPECT_TRUE(w.empty()) << absl::StrJoin(w, "\n");
}

// `diameter: 20` (mm meant): a 20 m thick wire of 49,000 t; its 1 m elements
// are shorter than its diameter and it outweighs its payload 1e5 times.
TEST(PlausibilityWarningsTest, DiameterInMillimetres) {
  const std::vector<std::string> w =
      WarningsOf(Wire(R"("youngs_modulus": 2e11, "diameter": 20)", R"("step": 0.002)"));
  EXPECT_TRUE(Has(w, {"cables[0].elements", "cables[0].diameter 20 m", "shorter than"}))
      << absl::StrJoin(w, "\n");
  EXPECT_TRUE(Has(w, {"cables[0] 'wire'", "times its payload's 500 kg", "kg/m^3"}))
      << absl::StrJoin(w, "\n");
}

// `youngs_modulus: 200` (GPa meant): outside the range, and a static strain
// of (500 + 49) kg x 9.81 / (200 Pa x 3.14e-4 m^2) = 8.6e7.
TEST(PlausibilityWarningsTest, YoungsModulusInGigapascals) {
  const std::vector<std::string> w =
      WarningsOf(Wire(R"("youngs_modulus": 200, "diameter": 0.02)", R"("step": 0.002)"));
  EXPECT_TRUE(Has(w, {"cables[0].youngs_modulus: 200 Pa is outside", "expects Pa"}))
      << absl::StrJoin(w, "\n");
  EXPECT_TRUE(Has(w, {"static strain", "8.58e+06 %"})) << absl::StrJoin(w, "\n");
}

// `step: 2` (ms meant): the load bounces on the wire's axial spring at
// 2 pi sqrt((500 + 49.3 / 3) kg x 20 m / (2e11 Pa x 3.1416e-4 m^2)) = 0.0806 s.
TEST(PlausibilityWarningsTest, StepInMilliseconds) {
  const std::vector<std::string> w = WarningsOf(Wire(kSteel, R"("step": 2)"));
  ASSERT_EQ(w.size(), 1u) << absl::StrJoin(w, "\n");
  EXPECT_TRUE(Has(w, {"solver.step: 2 s is above", "0.0806 s", "expects seconds"})) << w[0];
  // Adaptive steps hold their own error: no warning.
  EXPECT_TRUE(WarningsOf(Wire(kSteel, R"("step": 2, "adaptive": true)")).empty());
}

TEST(PlausibilityWarningsTest, DensityAndCoarseElements) {
  const std::vector<std::string> w = WarningsOf(
      R"({"name": "rope", "gravity": {"y": -9.81},
          "cables": [{"name": "rope", "start": {"x": 0, "y": 0}, "direction": {"x": 1},
                      "length": 10, "elements": 4, "density": 7.85, "youngs_modulus": 2e11,
                      "diameter": 0.01}],
          "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}}],
          "solver": {"analysis": "DYNAMIC", "duration": 0.01, "step": 0.001}})");
  EXPECT_TRUE(Has(w, {"cables[0].density: 7.85 kg/m^3 is outside", "expects kg/m^3"}))
      << absl::StrJoin(w, "\n");
  EXPECT_TRUE(Has(w, {"cables[0].elements: 4 elements of 2.5 m", "1/10 of the cable"}))
      << absl::StrJoin(w, "\n");
}

// A warning never blocks a run: the run finishes ok and lists it first.
TEST(PlausibilityWarningsTest, ARunListsThemAndFinishes) {
  absl::StatusOr<v1::Scene> proto =
      ParseSceneJson(Wire(R"("youngs_modulus": 2e11, "diameter": 20)", R"("step": 0.4)"));
  ASSERT_TRUE(proto.ok());
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok());
  ASSERT_FALSE(scene->warnings.empty());
  class NullSink : public FrameSink {
   public:
    absl::Status OnFrame(const Frame&) override { return absl::OkStatus(); }
  } sink;
  absl::StatusOr<RunSummary> summary = RunScene(*scene, &sink);
  ASSERT_TRUE(summary.ok()) << summary.status();
  EXPECT_EQ(summary->status, "ok");
  ASSERT_GE(summary->warnings.size(), scene->warnings.size());
  for (size_t i = 0; i < scene->warnings.size(); ++i)
    EXPECT_EQ(summary->warnings[i], scene->warnings[i]);
}

// Every sample scene: the warnings it gets are exactly those expected here
// (each a real property of the scene, docs/honest-runs.md says why).
TEST(PlausibilityWarningsTest, SampleScenesGetOnlyTheExpectedWarnings) {
  // scene file -> a part of each warning it is expected to get.
  // The falling pendulum of the paper (and its variants) is a deliberately
  // soft beam (E = 0.7 MPa): hanging from its pin it would stretch by 9 %
  // at the top (47 % at g = 50), and swinging more: true, and worth saying.
  // Its 40-element mesh has elements (0.03 m) shorter than the 0.048 m
  // diameter of its 0.0018 m^2 section: true too.
  const std::string strain = "static strain under its weight";
  const std::map<std::string, std::vector<std::string>> expected = {
      {"scenes/falling-pendulum.json", {strain}},
      {"scenes/paper/falling-12-g9.81.json", {strain}},
      {"scenes/paper/falling-12-g50.json", {strain}},
      {"scenes/paper/falling-40-g9.81.json", {strain, "shorter than the cable's diameter"}},
  };
  int scenes = 0;
  for (const char* dir : {"scenes", "scenes/paper"}) {
    for (const auto& entry :
         std::filesystem::directory_iterator(std::string(CABLESIM_SOURCE_DIR) + "/" + dir)) {
      if (entry.path().extension() != ".json") continue;
      const std::string name = std::string(dir) + "/" + entry.path().filename().string();
      absl::StatusOr<v1::Scene> proto = ReadSceneFile(entry.path().string());
      ASSERT_TRUE(proto.ok()) << name << ": " << proto.status();
      absl::StatusOr<Scene> scene = SceneFromProto(*proto);
      ASSERT_TRUE(scene.ok()) << name << ": " << scene.status();
      ++scenes;
      const auto it = expected.find(name);
      const std::vector<std::string> want =
          it == expected.end() ? std::vector<std::string>{} : it->second;
      EXPECT_EQ(scene->warnings.size(), want.size())
          << name << ":\n" << absl::StrJoin(scene->warnings, "\n");
      for (const std::string& part : want)
        EXPECT_TRUE(Has(scene->warnings, {part})) << name << ": no warning with " << part;
    }
  }
  EXPECT_GE(scenes, 32);
}

}  // namespace
}  // namespace cablesim
