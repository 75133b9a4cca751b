// What the engine builds for a scene: nodes where joints, loads and probes
// sit, ground joints removing coordinates, and the engine's own rejections
// (which name the joint).

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::SceneFromJson;

constexpr char kCable[] = R"("cables": [{"name": "c", "length": 1.0, "elements": 4,
    "direction": {"x": 1}, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}])";

TEST(ModelBuildTest, InsertsANodeWhereverAJointLoadOrProbeSits) {
  // 4 uniform elements (nodes at 0, .25, .5, .75, 1) plus nodes at 0.1
  // (probe) and 0.6 (load); 0.5 (joint side) is already a node.
  const Scene scene = SceneFromJson(std::string("{") + kCable + R"(,
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0.5}}],
    "loads": [{"at": {"cable": "c", "s": 0.6}, "force": {"y": -1}}],
    "probes": [{"name": "p", "cable": "c", "s": 0.1}],
    "solver": {"duration": 0.01}})");
  const auto info = DescribeModel(scene);
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_EQ(info->nodes, 7);
  EXPECT_EQ(info->elements, 6);
  EXPECT_EQ(info->coordinates, 28);
  EXPECT_EQ(info->dofs, 26);  // the pinned node loses its position
  EXPECT_EQ(info->multipliers, 0);
}

TEST(ModelBuildTest, ClampKeepsOneSlopeUnknownAlongTheInitialDirection) {
  const Scene scene = SceneFromJson(std::string("{") + kCable + R"(,
    "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0}}],
    "solver": {"duration": 0.01}})");
  const auto info = DescribeModel(scene);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->dofs, 20 - 3);  // position (2) fixed, slope 2 -> 1
}

TEST(ModelBuildTest, RejectsJointSidesThatDoNotMeetAtTheStart) {
  const Scene scene = SceneFromJson(std::string("{") + kCable + R"(,
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 1.2}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1.0}, "b": {"body": "b"}}],
    "solver": {"duration": 0.01}})");
  const auto info = DescribeModel(scene);
  ASSERT_FALSE(info.ok());
  EXPECT_EQ(info.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(info.status().message().find("joints[0]: its two points are 0.2 m apart"),
            absl::string_view::npos)
      << info.status();
}

TEST(ModelBuildTest, RejectsAFixedJointWhoseTangentsAreNotParallel) {
  const Scene scene = SceneFromJson(std::string("{") + kCable + R"(,
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 1.0, "y": 0.1}, "axis": {"y": 1}}],
    "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 1.0},
                "b": {"body": "b", "point": {"x": -0.1}}}],
    "solver": {"duration": 0.01}})");
  const auto info = DescribeModel(scene);
  ASSERT_FALSE(info.ok());
  EXPECT_NE(info.status().message().find("joints[0]: FIXED needs the cable tangent parallel"),
            absl::string_view::npos)
      << info.status();
}

TEST(ModelBuildTest, DropsAJointBetweenTwoGroundedPointsAndStillRuns) {
  // The cable's first node is pinned to ground and so is the body's centre
  // of mass: a PIN between the two has no unknowns left, within 1e-7 m it is
  // satisfied, and it must not make the Newton system singular.
  const Scene scene = SceneFromJson(std::string("{") + kCable + R"(,
    "gravity": {"y": -9.81},
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 1e-7}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
               {"type": "PIN", "a": {"body": "b"}},
               {"type": "PIN", "a": {"cable": "c", "s": 0}, "b": {"body": "b"}}],
    "solver": {"duration": 0.01, "step": 1e-3}})");
  const auto info = DescribeModel(scene);
  ASSERT_TRUE(info.ok()) << info.status();
  // Only the body's own unit-axis row is left (its axis can still turn).
  EXPECT_EQ(info->multipliers, 1);
  testing::CollectingSink sink;
  const auto summary = RunScene(scene, &sink);
  ASSERT_TRUE(summary.ok());
  EXPECT_EQ(summary->status, "ok") << summary->error;
}

}  // namespace
}  // namespace cablesim
