// The steps of MultibodyModel::Build one at a time (ModelBuilder): the mesh,
// the initial coordinates, the elimination of ground-fixed coordinates, the
// order of the unknowns, and the joints refused at the start. Each test runs
// the steps up to the one it is about and reads that step's result.

#include "engine/model/model_builder.h"

#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::SceneFromJson;

// A planar cable "c" 1 m long along x from the origin, 4 elements (nodes
// at 0, .25, .5, .75, 1), bending as given ("" for the default), with the
// scene's other fields `rest` (JSON members, each followed by a comma).
Scene OnCable(const std::string& bending, const std::string& rest) {
  const std::string bending_field =
      bending.empty() ? "" : absl::StrCat(R"(, "bending": ")", bending, "\"");
  return SceneFromJson(absl::StrCat(
      R"({"cables": [{"name": "c", "length": 1.0, "elements": 4, "direction": {"x": 1},
          "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01)",
      bending_field, "}], ", rest, R"("solver": {"duration": 0.01}})"));
}

// A refusal with exactly this message.
void ExpectRefused(const absl::Status& status, const std::string& message) {
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(status.message(), message);
}

// Runs the steps up to and including MeshCables.
void Mesh(ModelBuilder* builder) {
  ASSERT_TRUE(builder->ChooseDimension().ok());
  builder->MeshCables();
}

// Runs the steps up to and including Joints (which must succeed).
void UpToJoints(ModelBuilder* builder) {
  Mesh(builder);
  ASSERT_TRUE(builder->InitialCoordinates().ok());
  const absl::Status joints = builder->Joints();
  ASSERT_TRUE(joints.ok()) << joints;
}

TEST(ModelBuilderTest, MeshPutsANodeAtEveryJointLoadAndProbe) {
  const Scene scene = OnCable("", R"(
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0.3}}],
    "loads": [{"at": {"cable": "c", "s": 0.6}, "force": {"y": -1}}],
    "probes": [{"name": "p", "cable": "c", "s": 0.1}],
    )");
  ModelBuilder builder(scene);
  Mesh(&builder);
  const ModelBuilder::Mesh& mesh = builder.mesh();
  ASSERT_EQ(mesh.node_s.size(), 1u);
  EXPECT_EQ(mesh.node_s[0], (std::vector<double>{0, 0.1, 0.25, 0.3, 0.5, 0.6, 0.75, 1.0}));
  EXPECT_EQ(mesh.first_node, (std::vector<int>{0, 8}));
  EXPECT_EQ(mesh.nodes(), 8);
  EXPECT_EQ(mesh.Node(scene.joints[0].a), 3);
  EXPECT_EQ(mesh.Node(scene.loads[0].at), 5);
  EXPECT_EQ(mesh.Node(scene.probes[0].at), 1);
}

TEST(ModelBuilderTest, MeshSnapsArcLengthsWithinOneBillionthOfTheLength) {
  // 0.5 + 5e-10 is the node at 0.5; 1 - 5e-10 is the end, which stays at
  // exactly 1; 0.3 and 0.3 + 2e-9 are two nodes.
  const Scene scene = OnCable("", R"(
    "probes": [{"name": "mid", "cable": "c", "s": 0.5000000005},
               {"name": "end", "cable": "c", "s": 0.9999999995},
               {"name": "p", "cable": "c", "s": 0.3},
               {"name": "q", "cable": "c", "s": 0.300000002}],
    )");
  ModelBuilder builder(scene);
  Mesh(&builder);
  const ModelBuilder::Mesh& mesh = builder.mesh();
  EXPECT_EQ(mesh.nodes(), 7);
  EXPECT_EQ(mesh.node_s[0].back(), 1.0);
  EXPECT_EQ(mesh.Node(scene.probes[0].at), 4);
  EXPECT_EQ(mesh.Node(scene.probes[1].at), 6);
  EXPECT_EQ(mesh.Node(scene.probes[2].at), 2);
  EXPECT_EQ(mesh.Node(scene.probes[3].at), 3);
}

TEST(ModelBuilderTest, PinInsideACableWithoutBendingSplitsItsNode) {
  const Scene scene = OnCable("NONE", R"(
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0.5}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  const ModelBuilder::Mesh& mesh = builder.mesh();
  // Nodes 0, .25, .5, .5 (the twin), .75, 1.
  ASSERT_EQ(mesh.nodes(), 6);
  EXPECT_EQ(mesh.twin_of, (std::vector<int>{-1, -1, -1, 2, -1, -1}));
  EXPECT_EQ(mesh.Node(scene.joints[0].a), 2);
  EXPECT_EQ(builder.model().nodes(), 5);  // a split node counts once
  // The halves share the position, not the slope: each takes its side's
  // tangent (here both along x) times the stretch (1).
  const Eigen::VectorXd& q0 = builder.q0();
  EXPECT_EQ(q0.segment<2>(8), q0.segment<2>(12));
  EXPECT_EQ(q0.segment<2>(10), Eigen::Vector2d(1, 0));
  EXPECT_EQ(q0.segment<2>(14), Eigen::Vector2d(1, 0));
  builder.OrderUnknowns();
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(builder.UnknownOf(12 + k), builder.UnknownOf(8 + k));  // positions: grounded
    EXPECT_NE(builder.UnknownOf(14 + k), builder.UnknownOf(10 + k));
  }
}

TEST(ModelBuilderTest, PointLoadInsideACableWithoutBendingSplitsItsNode) {
  const Scene scene = OnCable("NONE", R"(
    "loads": [{"at": {"cable": "c", "s": 0.6}, "force": {"y": -1}}],
    )");
  ModelBuilder builder(scene);
  Mesh(&builder);
  EXPECT_EQ(builder.mesh().twin_of, (std::vector<int>{-1, -1, -1, -1, 3, -1, -1}));
}

TEST(ModelBuilderTest, FixedJointInsideACableWithoutBendingDoesNotSplitItsNode) {
  // A FIXED joint is about the slope: no kink there, alone or with a PIN at
  // the same point.
  const std::string pin_there = R"(, {"type": "PIN", "a": {"cable": "c", "s": 0.5}})";
  for (const std::string& pin : {std::string(""), pin_there}) {
    const Scene scene = OnCable(
        "NONE", absl::StrCat(R"("joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0.5}})", pin,
                             "], "));
    ModelBuilder builder(scene);
    Mesh(&builder);
    EXPECT_EQ(builder.mesh().nodes(), 5) << pin;
    EXPECT_EQ(builder.mesh().twin_of, (std::vector<int>(5, -1))) << pin;
  }
}

TEST(ModelBuilderTest, PinAtTheEndOrInABendingCableDoesNotSplit) {
  for (const std::string& bending : {std::string(""), std::string("NONE")}) {
    const std::string s = bending.empty() ? "0.5" : "1.0";
    const Scene scene = OnCable(
        bending, absl::StrCat(R"("joints": [{"type": "PIN", "a": {"cable": "c", "s": )", s,
                              "}}], "));
    ModelBuilder builder(scene);
    Mesh(&builder);
    EXPECT_EQ(builder.mesh().twin_of, (std::vector<int>(5, -1))) << bending;
  }
}

TEST(ModelBuilderTest, PinnedToGroundNodeLosesItsPositionCoordinates) {
  const Scene scene = OnCable("", R"(
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0.25}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  const ModelBuilder::Elimination& elim = builder.elimination();
  ASSERT_EQ(elim.grounded.size(), 20u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(elim.grounded[i], i == 4 || i == 5) << i;
  EXPECT_EQ(elim.clamped, std::vector<bool>(5, false));
  EXPECT_TRUE(builder.pending_rows().empty());  // a joint to ground is no row
  builder.OrderUnknowns();
  EXPECT_EQ(builder.model().dofs(), 18);
  EXPECT_EQ(builder.UnknownOf(4), -1);
  EXPECT_EQ(builder.UnknownOf(5), -1);
  // The unknowns run on along the cable past the pinned node's slope.
  EXPECT_EQ(builder.UnknownOf(3), 3);
  EXPECT_EQ(builder.UnknownOf(6), 4);
  Eigen::VectorXd q(20);
  builder.model().ToFull(builder.model().initial_z(), &q);
  EXPECT_EQ(q.segment<2>(4), Eigen::Vector2d(0.25, 0));
}

TEST(ModelBuilderTest, ClampedNodeKeepsOneSlopeUnknownAlongItsInitialTangent) {
  const Scene scene = OnCable("", R"(
    "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  EXPECT_TRUE(builder.elimination().clamped[0]);
  EXPECT_EQ(builder.elimination().clamp_dir[0], Eigen::Vector3d(1, 0, 0));
  builder.OrderUnknowns();
  EXPECT_EQ(builder.UnknownOf(0), -1);
  EXPECT_EQ(builder.UnknownOf(2), 0);
  EXPECT_EQ(builder.UnknownOf(3), 0);
  EXPECT_EQ(builder.model().dofs(), 17);
}

TEST(ModelBuilderTest, BodyUnknownsComeRightAfterItsFirstJoinedNode) {
  // The body hangs at s = 0.5 (node 2) and also at the end (node 4): its 4
  // unknowns follow node 2's, before node 3's; node 2's position is grounded.
  const Scene scene = OnCable("", R"(
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 0.75}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1.0},
                "b": {"body": "b", "point": {"x": 0.25}}},
               {"type": "PIN", "a": {"body": "b", "point": {"x": -0.25}},
                "b": {"cable": "c", "s": 0.5}},
               {"type": "PIN", "a": {"cable": "c", "s": 0.5}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  ASSERT_TRUE(builder.CheckJointsAtStart().ok());
  builder.OrderUnknowns();
  // Nodes 0, 1: unknowns 0-7; node 2: slope only, 8-9; body (coordinates
  // 20-23): 10-13; node 3: 14-17.
  EXPECT_EQ(builder.UnknownOf(8), -1);
  EXPECT_EQ(builder.UnknownOf(11), 9);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(builder.UnknownOf(20 + k), 10 + k);
  EXPECT_EQ(builder.UnknownOf(12), 14);
  EXPECT_EQ(builder.model().dofs(), 22);
}

TEST(ModelBuilderTest, RowsNoUnknownCanChangeAreDropped) {
  // Node 0 pinned to ground and the body pinned to ground at its centre of
  // mass: the PIN between them keeps its 2 rows as pending but no unknown
  // moves them; the body's unit-axis row stays.
  const Scene scene = OnCable("", R"(
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
               {"type": "PIN", "a": {"body": "b"}},
               {"type": "PIN", "a": {"cable": "c", "s": 0}, "b": {"body": "b"}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  EXPECT_EQ(builder.pending_rows().size(), 3u);
  builder.OrderUnknowns();
  builder.KeepMovableRows();
  EXPECT_EQ(builder.model().multipliers(), 1);
  EXPECT_EQ(builder.model().RowJoint(0), -1);
}

TEST(ModelBuilderTest, FixedBetweenTwoCablesWithCrossedTangentsIsRefused) {
  const Scene scene = SceneFromJson(R"({"cables": [
      {"name": "a", "length": 1.0, "elements": 2, "direction": {"x": 1},
       "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01},
      {"name": "b", "length": 1.0, "elements": 2, "start": {"x": 1}, "direction": {"y": 1},
       "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
    "joints": [{"type": "FIXED", "a": {"cable": "a", "s": 1.0}, "b": {"cable": "b", "s": 0}}],
    "solver": {"duration": 0.01}})");
  ModelBuilder builder(scene);
  Mesh(&builder);
  ASSERT_TRUE(builder.InitialCoordinates().ok());
  ExpectRefused(builder.Joints(),
                "joints[0]: FIXED between two cables needs their tangents parallel and in the "
                "same sense at t = 0 (sine of the angle between them: 1)");
}

TEST(ModelBuilderTest, FixedCableToBodyOffItsAxisIsRefusedAtTheStart) {
  // The cable runs along x; the body's x axis is y.
  const Scene scene = OnCable("", R"(
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 1.0, "y": 0.1}, "axis": {"y": 1}}],
    "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 1.0},
                "b": {"body": "b", "point": {"x": -0.1}}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  ExpectRefused(builder.CheckJointsAtStart(),
                "joints[0]: FIXED needs the cable tangent parallel to the other side's axis at "
                "t = 0 (sine of the angle between them: -1)");
}

TEST(ModelBuilderTest, JointPointsApartAtTheStartAreRefused) {
  const Scene scene = OnCable("", R"(
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"x": 1.2}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1.0}, "b": {"body": "b"}}],
    )");
  ModelBuilder builder(scene);
  UpToJoints(&builder);
  ExpectRefused(builder.CheckJointsAtStart(),
                "joints[0]: its two points are 0.2 m apart at t = 0 (they must coincide)");
}

}  // namespace
}  // namespace cablesim
