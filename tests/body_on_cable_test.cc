// Bodies placed by a cable (Body.on): the centre on the cable's polyline
// and the axis along its tangent, and bodies threaded on a cable (a PIN at
// each face), against the same scenes laid out by hand.

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

absl::StatusOr<Scene> Convert(const std::string& json) {
  auto proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  return SceneFromProto(*proto);
}

// A 1 m rope pinned at both ends along +x, with a cylinder (height 0.1 m)
// at its middle; `body` and `joints` complete the scene.
std::string Rope(const std::string& body, const std::string& joints,
                 const std::string& points = R"([{"x": 0}, {"x": 1}])") {
  return absl::StrCat(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rope", "points": )",
                      points, R"(, "elements": 10, "density": 1000,
                "youngs_modulus": 1e7, "diameter": 0.01}],
    "bodies": [{"name": "bead", "cylinder": {"diameter": 0.04, "height": 0.1}, "density": 1000, )",
                      body, R"(}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}},
               {"type": "PIN", "a": {"cable": "rope", "s": 1}})",
                      joints, R"(],
    "probes": [{"name": "bead", "body": "bead"}, {"name": "mid", "cable": "rope", "s": 0.5}],
    "solver": {"duration": 0.2, "step": 0.002, "output_interval": 0.02}})");
}

// A body placed by the cable keeps its damping (it was dropped once: the
// placement returned before the damping was read), and bad damping is
// still named.
TEST(BodyOnCableTest, PlacedBodyKeepsItsDamping) {
  absl::StatusOr<Scene> scene = Convert(
      Rope(R"("on": {"cable": "rope", "s": 0.5}, "damping": {"linear": 3, "angular": 0.5})", ""));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->bodies[0].linear_damping_n_s_m, 3);
  EXPECT_EQ(scene->bodies[0].angular_damping_n_m_s, 0.5);
  absl::StatusOr<Scene> bad =
      Convert(Rope(R"("on": {"cable": "rope", "s": 0.5}, "damping": {"linear": -1})", ""));
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("bodies[0].damping.linear"));
}

// Threaded at s = 0.5 is the hand-laid scene: centre (0.5, 0), axis +x,
// PIN joints from the cable at 0.45 and 0.55 to the faces (-+0.05, 0, 0).
// The two runs must be the same to rounding (1e-12 m): the same model.
TEST(BodyOnCableTest, ThreadedEqualsHandLaid) {
  absl::StatusOr<Scene> threaded =
      Convert(Rope(R"("on": {"cable": "rope", "s": 0.5, "threaded": true})", ""));
  ASSERT_TRUE(threaded.ok()) << threaded.status();
  ASSERT_EQ(threaded->joints.size(), 4u);  // the scene's two, then the faces'
  EXPECT_NEAR(threaded->bodies[0].position_m.x(), 0.5, 1e-15);
  absl::StatusOr<Scene> by_hand = Convert(Rope(R"("position": {"x": 0.5}, "axis": {"x": 1})", R"(,
      {"type": "PIN", "a": {"cable": "rope", "s": 0.45}, "b": {"body": "bead", "point": {"x": -0.05}}},
      {"type": "PIN", "a": {"cable": "rope", "s": 0.55}, "b": {"body": "bead", "point": {"x": 0.05}}})"));
  ASSERT_TRUE(by_hand.ok()) << by_hand.status();
  testing::CollectingSink a, b;
  testing::RunOk(*threaded, &a);
  testing::RunOk(*by_hand, &b);
  ASSERT_EQ(a.frames().size(), b.frames().size());
  ASSERT_GT(a.frames().size(), 5u);
  for (size_t i = 0; i < a.frames().size(); ++i) {
    for (int p = 0; p < 2; ++p) {
      EXPECT_LT((a.frames()[i].probes[p].position_m - b.frames()[i].probes[p].position_m).norm(),
                1e-12);
    }
  }
  // It moved: the bead sags under gravity.
  EXPECT_LT(a.frames().back().probes[0].position_m.y(), -1e-4);
}

// Where the cable bends inside the body, by hand the faces' joints would
// have to be placed on the chord to 1e-6 m (else the scene is rejected);
// threaded puts them there exactly, and the scene runs.
TEST(BodyOnCableTest, ThreadedAcrossACornerHoldsExactly) {
  const std::string bent = R"([{"x": 0}, {"x": 0.5}, {"x": 1, "y": -0.2}])";
  absl::StatusOr<Scene> scene =
      Convert(Rope(R"("on": {"cable": "rope", "s": 0.5, "threaded": true})", "", bent));
  ASSERT_TRUE(scene.ok()) << scene.status();
  testing::CollectingSink sink;
  const RunSummary s = testing::RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  EXPECT_LT(sink.frames()[0].constraint_violation, 1e-12);
  EXPECT_LT(s.max_constraint_violation, 1e-8);
}

// Not threaded: the centre at the cable point and the axis along the
// tangent, so a FIXED joint to the cable there holds at t = 0 on a slanted
// cable (laid by hand from rounded numbers it would not: 1e-5 m off).
TEST(BodyOnCableTest, PlacedOnCableAlongItsTangent) {
  const std::string slanted = R"([{"x": 0}, {"x": 0.96, "y": 0.28}])";
  absl::StatusOr<Scene> scene = Convert(Rope(R"("on": {"cable": "rope", "s": 0.37})",
      R"(, {"type": "FIXED", "a": {"cable": "rope", "s": 0.37}, "b": {"body": "bead"}})", slanted));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_NEAR(scene->bodies[0].position_m.x(), 0.37 * 0.96, 1e-15);
  EXPECT_NEAR(scene->bodies[0].position_m.y(), 0.37 * 0.28, 1e-15);
  EXPECT_NEAR(scene->bodies[0].axis.x(), 0.96, 1e-15);
  EXPECT_NEAR(scene->bodies[0].axis.y(), 0.28, 1e-15);
  testing::CollectingSink sink;
  testing::RunOk(*scene, &sink);
  // By hand, 1e-5 m off: rejected, naming the joint.
  absl::StatusOr<Scene> off = Convert(Rope(R"("position": {"x": 0.35521, "y": 0.1036}, "axis": {"x": 0.96, "y": 0.28})",
      R"(, {"type": "FIXED", "a": {"cable": "rope", "s": 0.37}, "b": {"body": "bead"}})", slanted));
  ASSERT_TRUE(off.ok());
  testing::CollectingSink unused;
  EXPECT_THAT(RunScene(*off, &unused).status().message(), HasSubstr("joints[2]: its two points"));
}

TEST(BodyOnCableTest, ValidationNamesTheField) {
  auto message = [](const std::string& body) {
    return std::string(Convert(Rope(body, "")).status().message());
  };
  EXPECT_THAT(message(R"("on": {"cable": "rope", "s": 0.97, "threaded": true})"),
              HasSubstr("bodies[0].on.s: must be in [0.05, 0.95]"));
  EXPECT_THAT(message(R"("on": {"cable": "chain", "s": 0.5})"),
              HasSubstr("bodies[0].on.cable: no cable named \"chain\""));
  EXPECT_THAT(message(R"("position": {"x": 0.5}, "on": {"cable": "rope", "s": 0.5})"),
              HasSubstr("bodies[0].position: not with on"));
  absl::Status s = Convert(R"({"cables": [{"name": "rope", "length": 1, "density": 1000,
      "youngs_modulus": 1e7, "diameter": 0.01}],
      "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                  "on": {"cable": "rope", "s": 0.5, "threaded": true}}],
      "solver": {"duration": 1}})").status();
  EXPECT_THAT(s.message(), HasSubstr("bodies[0].on.threaded: needs cylinder"));
}

}  // namespace
}  // namespace cablesim
