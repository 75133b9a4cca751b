// The cable's shape through the command line and the service: `cablesim run
// --shape FILE` (in-process service) writes t,cable,node,s,x,y,z whose
// frames and probe nodes match the run CSV; the service's rows carry the
// nodes only when the scene asks.

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <tuple>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "client/cli.h"
#include "client/shape_csv_writer.h"

namespace cablesim {
namespace {

std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) rows.push_back(absl::StrSplit(line, ','));
  return rows;
}

int RunCommand(const std::vector<std::string>& args, std::string* out) {
  std::ostringstream o, e;
  const int code = RunCli(args, o, e);
  *out = o.str() + e.str();
  return code;
}

// The sample scene (output.shape true): 1 s every 0.02 s, 51 frames; the
// string's 9 nodes (its kink at s = 1 split, counted once) and the tail's 4.
TEST(ShapeCliTest, ShapeCsvMatchesTheRunCsv) {
  const std::string scene = absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/kinked-string-shape.json");
  const std::string dir = absl::StrCat(::testing::TempDir(), "/shape_cli_test_", ::getpid());
  const std::string csv = dir + "_run.csv", shape = dir + "_nodes.csv";
  std::string output;
  ASSERT_EQ(RunCommand({"run", scene, "--out", csv, "--shape", shape}, &output), 0) << output;
  const auto run = ReadCsv(csv);
  const auto nodes = ReadCsv(shape);
  ASSERT_EQ(run.size(), 1u + 51);
  ASSERT_EQ(nodes.size(), 1u + 51 * 13);
  EXPECT_EQ(absl::StrJoin(nodes[0], ","), ShapeCsvWriter::kHeader);
  // The run CSV has no node column (the shape is in its own file).
  for (const std::string& c : run[0]) EXPECT_EQ(c.find(".nodes["), std::string::npos) << c;
  std::map<std::string, size_t> column;
  for (size_t i = 0; i < run[0].size(); ++i) column[run[0][i]] = i;
  // Probe -> (cable, node) of the sample scene.
  const std::vector<std::tuple<std::string, int, int>> probes = {
      {"start", 0, 0}, {"kink", 0, 4}, {"quarter", 0, 2}, {"end", 1, 3}};
  for (size_t f = 0; f < 51; ++f) {
    const std::vector<std::string>& row = run[1 + f];
    for (size_t n = 0; n < 13; ++n) {
      const std::vector<std::string>& node = nodes[1 + 13 * f + n];
      ASSERT_EQ(node.size(), 7u);
      // The same frame times, written the same way.
      EXPECT_EQ(node[0], row[0]) << "frame " << f;
      EXPECT_EQ(std::stoi(node[1]), n < 9 ? 0 : 1);
      EXPECT_EQ(std::stoi(node[2]), n < 9 ? static_cast<int>(n) : static_cast<int>(n) - 9);
    }
    for (const auto& [name, cable, k] : probes) {
      const std::vector<std::string>& node = nodes[1 + 13 * f + (cable == 0 ? 0 : 9) + k];
      // The same doubles, printed with 17 digits: identical text.
      EXPECT_EQ(node[4], row[column[name + ".x"]]) << name << " frame " << f;
      EXPECT_EQ(node[5], row[column[name + ".y"]]) << name << " frame " << f;
      EXPECT_EQ(node[6], row[column[name + ".z"]]) << name << " frame " << f;
    }
  }
  // The kink's arc length, and the weight moves (it bounces on the
  // string: the test sees motion).
  EXPECT_EQ(std::stod(nodes[1 + 4][3]), 1.0);
  double lowest = 0;
  for (size_t f = 0; f < 51; ++f) lowest = std::min(lowest, std::stod(nodes[1 + 13 * f + 4][5]));
  EXPECT_LT(lowest, -1e-3);
  std::remove(csv.c_str());
  std::remove(shape.c_str());
}

// Beside --out when the scene asks and --shape is not given.
TEST(ShapeCliTest, SceneOutputShapeWritesBesideTheCsv) {
  const std::string scene = absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/kinked-string-shape.json");
  const std::string base = absl::StrCat(::testing::TempDir(), "/shape_cli_beside_", ::getpid());
  std::string output;
  ASSERT_EQ(RunCommand({"run", scene, "--out", base + ".csv"}, &output), 0) << output;
  EXPECT_EQ(ReadCsv(base + ".shape.csv").size(), 1u + 51 * 13);
  std::remove((base + ".csv").c_str());
  std::remove((base + ".shape.csv").c_str());
}

// --shape asks for the shape of a scene that does not (the falling
// pendulum: 12 elements, 13 nodes).
TEST(ShapeCliTest, ShapeFlagAsksForTheShape) {
  const std::string scene = absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/falling-pendulum.json");
  const std::string shape = absl::StrCat(::testing::TempDir(), "/shape_cli_flag_", ::getpid());
  std::string output;
  ASSERT_EQ(RunCommand({"run", scene, "--shape", shape}, &output), 0) << output;
  EXPECT_EQ(ReadCsv(shape).size(), 1u + 1001 * 13);
  std::remove(shape.c_str());
  EXPECT_EQ(RunCommand({"validate", scene, "--shape", shape}, &output), 2);
}

}  // namespace
}  // namespace cablesim
