// Joint reactions (Scene.output.reactions): the force, and for FIXED the
// moment, that each joint exerts on its side a, from the multipliers of its
// constraint rows; checked against statics in closed form.

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/output/frame_columns.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kG = 9.81;

// A body of m = 2 kg pinned (or welded) to ground at the point `point`
// (body frame) of it, at rest where gravity leaves it: the support carries
// the weight, F = (0, m g, 0) on the body; welded with its centre of mass
// a horizontal distance d from the joint, the support also holds the
// weight's moment about the joint, M_z = m g d (the weight at r = (d, 0)
// from the joint pulls with (0, -m g): r x F = -m g d, which M balances).
std::string BodyOnSupport(const std::string& type, const std::string& point,
                          const std::string& model, const std::string& analysis) {
  return absl::StrFormat(R"({"model": "%s", "gravity": {"y": -9.81},
    "bodies": [{"name": "bob", "mass": 2, "inertia": {"x": 0.02, "y": 0.02, "z": 0.03}}],
    "joints": [{"name": "pivot", "type": "%s", "a": {"body": "bob", "point": %s}}],
    "output": {"reactions": true},
    "solver": {"analysis": "%s", "duration": 0.2, "step": 0.01, "output_interval": 0.1}})",
                         model, type, point, analysis);
}

struct SupportCase {
  const char* type;
  const char* point;
  const char* model;
  const char* analysis;
  double moment_z;  // expected M_z [N m]
};

class BodySupportTest : public ::testing::TestWithParam<SupportCase> {};

// Tolerance 1e-9 relative: the equilibrium is exact (a body hanging below
// its pin, or welded) and the multipliers solve a linear system with the
// weight on its right-hand side; only rounding (and Newton's tolerance,
// far below) remains.
TEST_P(BodySupportTest, CarriesTheWeightAndItsMoment) {
  const SupportCase& c = GetParam();
  CollectingSink sink;
  RunOk(SceneFromJson(BodyOnSupport(c.type, c.point, c.model, c.analysis)), &sink);
  ASSERT_EQ(sink.info().joint_names, std::vector<std::string>{"pivot"});
  const bool fixed = std::string(c.type) == "FIXED";
  ASSERT_EQ(sink.info().joint_reaction_values, std::vector<int>{fixed ? 6 : 3});
  ASSERT_FALSE(sink.frames().empty());
  for (const Frame& f : sink.frames()) {
    // STATIC frames are load increments: the weight times the load factor t.
    const double w = 2 * kG * (std::string(c.analysis) == "STATIC" ? f.t : 1.0);
    ASSERT_EQ(f.reactions.size(), 1u);
    EXPECT_NEAR(f.reactions[0].force.x(), 0, 1e-9 * w) << f.t;
    EXPECT_NEAR(f.reactions[0].force.y(), w, 1e-9 * w) << f.t;
    EXPECT_NEAR(f.reactions[0].force.z(), 0, 1e-9 * w) << f.t;
    if (!fixed) continue;
    EXPECT_NEAR(f.reactions[0].moment.x(), 0, 1e-9 * w) << f.t;
    EXPECT_NEAR(f.reactions[0].moment.y(), 0, 1e-9 * w) << f.t;
    EXPECT_NEAR(f.reactions[0].moment.z(), c.moment_z * w / (2 * kG), 1e-9 * w) << f.t;
  }
  // The columns, named by the joint's index.
  const std::vector<std::string> columns = FrameColumns(sink.info());
  EXPECT_THAT(columns, ::testing::Contains("joints[0].fy"));
  EXPECT_EQ(std::count(columns.begin(), columns.end(), "joints[0].mz"), fixed ? 1 : 0);
}

INSTANTIATE_TEST_SUITE_P(
    Supports, BodySupportTest,
    ::testing::Values(
        // A pendulum at rest below its pivot, the joint's rows on an offset point.
        SupportCase{"PIN", R"({"y": 1})", "PLANAR", "DYNAMIC", 0},
        SupportCase{"PIN", R"({"y": 1})", "SPATIAL", "DYNAMIC", 0},
        SupportCase{"PIN", R"({"y": 1})", "PLANAR", "STATIC", 0},
        // Pinned at its centre of mass (else removed coordinates).
        SupportCase{"PIN", R"({"x": 0})", "PLANAR", "STATIC", 0},
        // Welded 0.5 m to the left of its centre of mass: M_z = m g 0.5.
        SupportCase{"FIXED", R"({"x": -0.5})", "PLANAR", "STATIC", 2 * kG * 0.5},
        SupportCase{"FIXED", R"({"x": -0.5})", "SPATIAL", "STATIC", 2 * kG * 0.5}));

// A body of M = 100 kg hanging from two nearly weightless, stiff cables
// of length 5 m from anchors at (-3, 0) and (3, 0), joined at its centre
// of mass: the cables hang straight, the body 4 m below the anchors, and
// each cable holds T = M g / (2 * 4/5) = 613.125 N. The anchor pulls its
// cable towards itself: (-3, 4) / 5 T on the left cable; the body's joint
// pulls the cable's end down and in, (3, -4) / 5 T. The cables' own weight
// (1e-3 kg/m, 0.05 N against T = 613 N) and stretch (T L / EA = 4e-6 m,
// turning the cables by 1e-6 rad) make the figures off by 1e-4 relative at
// most: the tolerance. (A cable 1000 times softer, stretched by 4 mm, is
// off by 1.2e-3 in the horizontal force: the test sees the geometry.)
TEST(JointReactionsTest, BodyHangingFromTwoCables) {
  const std::string json = R"({"gravity": {"y": -9.81},
    "cables": [
      {"name": "left", "length": 5, "elements": 4, "density": 0.12732395447351628,
       "youngs_modulus": 1e11, "diameter": 0.1, "bending": "NONE",
       "points": [{"x": -3, "y": 0}, {"x": 0, "y": -4}]},
      {"name": "right", "length": 5, "elements": 4, "density": 0.12732395447351628,
       "youngs_modulus": 1e11, "diameter": 0.1, "bending": "NONE",
       "points": [{"x": 3, "y": 0}, {"x": 0, "y": -4}]}],
    "bodies": [{"name": "load", "mass": 100, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"y": -4}}],
    "joints": [
      {"name": "anchor left", "type": "PIN", "a": {"cable": "left", "s": 0}},
      {"name": "anchor right", "type": "PIN", "a": {"cable": "right", "s": 0}},
      {"type": "PIN", "a": {"cable": "left", "s": 5}, "b": {"body": "load"}},
      {"type": "PIN", "a": {"cable": "right", "s": 5}, "b": {"body": "load"}}],
    "output": {"reactions": true},
    "solver": {"analysis": "STATIC"}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  EXPECT_EQ(sink.info().joint_names,
            (std::vector<std::string>{"anchor left", "anchor right", "", ""}));
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.reactions.size(), 4u);
  const double t = 100 * kG / (2 * 0.8);
  const double tol = 1e-4 * t;
  const Eigen::Vector3d left_anchor(-0.6 * t, 0.8 * t, 0), right_anchor(0.6 * t, 0.8 * t, 0);
  EXPECT_LT((f.reactions[0].force - left_anchor).norm(), tol) << f.reactions[0].force.transpose();
  EXPECT_LT((f.reactions[1].force - right_anchor).norm(), tol) << f.reactions[1].force.transpose();
  EXPECT_LT((f.reactions[2].force + left_anchor).norm(), tol) << f.reactions[2].force.transpose();
  EXPECT_LT((f.reactions[3].force + right_anchor).norm(), tol) << f.reactions[3].force.transpose();
  // The body's joints hold the body: the forces on it (minus those on the
  // cables' ends) sum to its weight, to rounding.
  EXPECT_NEAR(-(f.reactions[2].force + f.reactions[3].force).y(), 100 * kG, 1e-9 * t);
}

// Without output.reactions: no reaction columns, no names lost.
TEST(JointReactionsTest, NoneUnlessAskedFor) {
  std::string json = BodyOnSupport("PIN", R"({"y": 1})", "PLANAR", "STATIC");
  json.replace(json.find(R"("reactions": true)"), 17, R"("reactions": false)");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  EXPECT_TRUE(sink.info().joint_reaction_values.empty());
  EXPECT_EQ(sink.info().joint_names, std::vector<std::string>{"pivot"});
  EXPECT_TRUE(sink.frames().back().reactions.empty());
  for (const std::string& c : FrameColumns(sink.info()))
    EXPECT_EQ(c.find("joints["), std::string::npos) << c;
}

}  // namespace
}  // namespace cablesim
