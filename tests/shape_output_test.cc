// The cable's shape (Scene.output.shape): every node's position per frame,
// in the frames, the service's rows and the CLI's shape CSV.

#include <cmath>

#include <gtest/gtest.h>

#include "engine/output/frame_columns.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// A string (no bending stiffness) hung from two pins with a weight pinned
// at its middle: the node under the weight is split (a kink, twin_of in
// the model) and must count once. Probes at nodes: the ends, the kink and
// a quarter point; a second, stiff cable hangs from the weight.
constexpr char kKinkedString[] = R"({
  "gravity": {"y": -9.81},
  "cables": [{"name": "string", "length": 2.0, "elements": 8, "direction": {"x": 1},
              "density": 1000, "youngs_modulus": 1e8, "diameter": 0.005, "bending": "NONE"},
             {"name": "tail", "length": 0.5, "elements": 3, "start": {"x": 1},
              "direction": {"y": -1}, "density": 2000, "youngs_modulus": 1e8,
              "diameter": 0.005}],
  "bodies": [{"name": "weight", "mass": 0.5, "inertia": {"z": 1e-4}, "position": {"x": 1}}],
  "joints": [{"type": "PIN", "a": {"cable": "string", "s": 0}},
             {"type": "PIN", "a": {"cable": "string", "s": 2.0}},
             {"type": "PIN", "a": {"cable": "string", "s": 1.0}, "b": {"body": "weight"}},
             {"type": "PIN", "a": {"cable": "tail", "s": 0}, "b": {"body": "weight"}}],
  "probes": [{"name": "start", "cable": "string", "s": 0},
             {"name": "kink", "cable": "string", "s": 1.0},
             {"name": "quarter", "cable": "string", "s": 0.5},
             {"name": "end", "cable": "tail", "s": 0.5}],
  "output": {"shape": true},
  "solver": {"duration": 0.1, "step": 1e-3, "output_interval": 0.02}})";

TEST(ShapeOutputTest, NodesAtTheProbesAreTheProbePositions) {
  CollectingSink sink;
  RunOk(SceneFromJson(kKinkedString), &sink);
  const ModelInfo& info = sink.info();
  ASSERT_TRUE(info.shape);
  // 8 + 1 nodes on the string (the kink at s = 1 is a node of the uniform
  // mesh, split in two halves that count once), 3 + 1 on the tail.
  ASSERT_EQ(info.cable_nodes, (std::vector<int>{9, 4}));
  EXPECT_EQ(info.nodes, 13);
  ASSERT_EQ(info.node_s.size(), 13u);
  EXPECT_EQ(info.node_s[0], 0);
  EXPECT_EQ(info.node_s[4], 1.0);
  EXPECT_EQ(info.node_s[8], 2.0);
  EXPECT_EQ(info.node_s[12], 0.5);
  ASSERT_EQ(sink.frames().size(), 6u);
  double largest_motion = 0;
  for (const Frame& f : sink.frames()) {
    ASSERT_EQ(f.nodes.size(), 13u) << "t = " << f.t;
    // A probe at a node is that node's position coordinates: the same
    // doubles (both read q; no arithmetic on a coefficient of 1).
    EXPECT_EQ(f.nodes[0], f.probes[0].position_m) << "t = " << f.t;
    EXPECT_EQ(f.nodes[4], f.probes[1].position_m) << "t = " << f.t;
    EXPECT_EQ(f.nodes[2], f.probes[2].position_m) << "t = " << f.t;
    EXPECT_EQ(f.nodes[12], f.probes[3].position_m) << "t = " << f.t;
    largest_motion = std::max(largest_motion, (f.nodes[4] - Eigen::Vector3d(1, 0, 0)).norm());
  }
  EXPECT_GT(largest_motion, 1e-3);  // the weight falls: the test sees motion
}

TEST(ShapeOutputTest, CostsNothingWhenNotAsked) {
  std::string json = kKinkedString;
  json.replace(json.find(R"("output": {"shape": true},)"), 26, "");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  EXPECT_FALSE(sink.info().shape);
  EXPECT_EQ(sink.info().cable_nodes, (std::vector<int>{9, 4}));
  for (const Frame& f : sink.frames()) EXPECT_TRUE(f.nodes.empty());
  // And the row has no node column.
  for (const std::string& c : FrameColumns(sink.info()))
    EXPECT_EQ(c.find(".nodes["), std::string::npos) << c;
}

TEST(ShapeOutputTest, NodeColumnsRoundTrip) {
  CollectingSink sink;
  RunOk(SceneFromJson(kKinkedString), &sink);
  const std::vector<std::string> columns = FrameColumns(sink.info());
  ASSERT_EQ(static_cast<int64_t>(columns.size()),
            FrameRowSize(4, 2, 1) + 3 * 13);
  EXPECT_EQ(columns[FrameRowSize(4, 2, 1)], "cables[0].nodes[0].x");
  EXPECT_EQ(columns.back(), "cables[1].nodes[3].z");
  const Frame& last = sink.frames().back();
  std::vector<double> row;
  ForEachFrameValue(last, [&row](double v) { row.push_back(v); });
  ForEachNodeValue(last, [&row](double v) { row.push_back(v); });
  ASSERT_EQ(row.size(), columns.size());
  Frame back;
  FrameReader(sink.info(), columns).Read(row, &back);
  EXPECT_EQ(back.nodes, last.nodes);
}

}  // namespace
}  // namespace cablesim
