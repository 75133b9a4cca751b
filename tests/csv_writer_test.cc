// The trajectory CSV: header, row format, write errors.

#include "client/csv_writer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

ModelInfo InfoWithProbes(std::vector<std::string> names) {
  ModelInfo info;
  info.model = "planar";
  info.probe_names = std::move(names);
  return info;
}

Frame FrameWithProbes(double t, int probes) {
  Frame frame;
  frame.t = t;
  for (int i = 0; i < probes; ++i) {
    ProbeSample sample;
    sample.position_m = Eigen::Vector3d(1 + i, 2, 3);
    sample.velocity_m_s = Eigen::Vector3d(4, 5, 6);
    sample.acceleration_m_s2 = Eigen::Vector3d(7, 8, 9);
    frame.probes.push_back(sample);
  }
  frame.energy = {0.1, -0.2, 0.3, 0.4, 0.6, 0.25};
  frame.constraint_violation = 1e-12;
  return frame;
}

TEST(CsvWriterTest, Header) {
  EXPECT_EQ(CsvWriter::Header(ModelInfo()),
            "t,energy.kinetic,energy.potential,energy.axial,energy.bending,energy.total,"
            "constraint.violation,energy.damped,loads.energy.potential");
  EXPECT_EQ(CsvWriter::Header(InfoWithProbes({"tip"})),
            "t,tip.x,tip.y,tip.z,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az,"
            "energy.kinetic,energy.potential,energy.axial,energy.bending,energy.total,"
            "constraint.violation,energy.damped,loads.energy.potential");
  // The parts after every existing column, named by index (names are free
  // text: the comma here would break a column named after it).
  ModelInfo parts = InfoWithProbes({"tip"});
  parts.cable_names = {"rope, main", "b"};
  parts.body_names = {"b"};
  EXPECT_EQ(CsvWriter::Header(parts),
            "t,tip.x,tip.y,tip.z,tip.vx,tip.vy,tip.vz,tip.ax,tip.ay,tip.az,"
            "energy.kinetic,energy.potential,energy.axial,energy.bending,energy.total,"
            "constraint.violation,energy.damped,"
            "cables[0].energy.kinetic,cables[0].energy.gravity,cables[0].energy.axial,"
            "cables[0].energy.bending,"
            "cables[1].energy.kinetic,cables[1].energy.gravity,cables[1].energy.axial,"
            "cables[1].energy.bending,"
            "bodies[0].energy.kinetic,bodies[0].energy.gravity,loads.energy.potential");
}

TEST(CsvWriterTest, PartsAreWrittenAfterTheTotals) {
  std::ostringstream out;
  ModelInfo info = InfoWithProbes({});
  info.cable_names = {"c"};
  info.body_names = {"b"};
  CsvWriter writer(&out, "memory");
  ASSERT_TRUE(writer.OnStart(info).ok());
  Frame frame = FrameWithProbes(0, 0);
  frame.energy_parts.cables = {{1, 2, 3, 4}};
  frame.energy_parts.bodies = {{5, 6, 0, 0}};
  frame.energy_parts.loads = 7;
  ASSERT_TRUE(writer.OnFrame(frame).ok());
  ASSERT_TRUE(writer.Finish().ok());
  const std::vector<std::string> lines = absl::StrSplit(out.str(), '\n');
  ASSERT_EQ(lines.size(), 3);
  EXPECT_EQ(lines[1], "0,0.1,-0.2,0.3,0.4,0.6,1e-12,0.25,1,2,3,4,5,6,7");
  // A frame without the parts of the header is refused.
  std::ostringstream other;
  CsvWriter refusing(&other, "memory");
  ASSERT_TRUE(refusing.OnStart(info).ok());
  EXPECT_FALSE(refusing.OnFrame(FrameWithProbes(0.1, 0)).ok());
}

TEST(CsvWriterTest, RowsRoundTrip) {
  std::ostringstream out;
  {
    CsvWriter writer(&out, "memory");
    ASSERT_TRUE(writer.OnStart(InfoWithProbes({"a", "b"})).ok());
    ASSERT_TRUE(writer.OnFrame(FrameWithProbes(0, 2)).ok());
    ASSERT_TRUE(writer.OnFrame(FrameWithProbes(0.1, 2)).ok());
    EXPECT_TRUE(writer.Finish().ok());
    EXPECT_EQ(writer.rows(), 2);
  }
  const std::vector<std::string> lines = absl::StrSplit(out.str(), '\n');
  ASSERT_EQ(lines.size(), 4);  // header, 2 rows, empty after the last newline
  EXPECT_EQ(lines[0], CsvWriter::Header(InfoWithProbes({"a", "b"})));
  // Each number in the shortest form that reads back to its double.
  EXPECT_EQ(lines[1], "0,1,2,3,4,5,6,7,8,9,2,2,3,4,5,6,7,8,9,0.1,-0.2,0.3,0.4,0.6,1e-12,0.25,0");
  const std::vector<std::string> cells = absl::StrSplit(lines[2], ',');
  ASSERT_EQ(cells.size(), 1 + 2 * 9 + 7 + 1);
  EXPECT_EQ(cells[0], "0.1");
  EXPECT_EQ(std::stod(cells[0]), 0.1);  // reads back exactly
  EXPECT_EQ(lines[3], "");
}

// AppendCsvNumber's shortest form reads back to the same double across
// the range: 100,000 random bit patterns (finite ones), the extremes, and
// numbers whose shortest form needs all 17 digits; never longer than 17
// significant digits' form, which it replaced.
TEST(CsvWriterTest, ShortestNumbersReadBackExactly) {
  std::mt19937_64 bits(29112026);
  std::vector<double> values = {0.0, -0.0, 1e-320, -4.9406564584124654e-324,
                                2.2250738585072014e-308, 1.7976931348623157e308,
                                0.1 + 0.2, 1.0 / 3, 20.433999999999997, -35.392999999999972};
  while (values.size() < 100010) {
    const uint64_t b = bits();
    double v;
    std::memcpy(&v, &b, sizeof v);
    if (std::isfinite(v)) values.push_back(v);
  }
  for (double v : values) {
    std::string text;
    AppendCsvNumber(&text, v);
    const double back = std::strtod(text.c_str(), nullptr);
    ASSERT_EQ(std::memcmp(&back, &v, sizeof v), 0) << text;
    ASSERT_LE(text.size(), absl::StrFormat("%.17g", v).size()) << text;
  }
}

TEST(CsvWriterTest, NonFiniteValuesAreWritten) {
  std::ostringstream out;
  CsvWriter writer(&out, "memory");
  ASSERT_TRUE(writer.OnStart(InfoWithProbes({})).ok());
  Frame frame = FrameWithProbes(1, 0);
  frame.energy.total = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(writer.OnFrame(frame).ok());
  ASSERT_TRUE(writer.Finish().ok());
  EXPECT_THAT(out.str(), HasSubstr(",inf,"));
}

// Rows are written together, kRowsPerFlush at a time (one system call per
// batch, not per row), so a reader following the file sees them in
// batches, and Finish writes the rest.
TEST(CsvWriterTest, RowsAreWrittenInBatches) {
  std::ostringstream out;
  CsvWriter writer(&out, "memory");
  ASSERT_TRUE(writer.OnStart(InfoWithProbes({"a"})).ok());
  auto lines = [&out] {
    const std::string text = out.str();
    return std::count(text.begin(), text.end(), '\n');
  };
  const std::string header_only = out.str();
  EXPECT_EQ(lines(), 1);
  for (int i = 1; i < CsvWriter::kRowsPerFlush; ++i)
    ASSERT_TRUE(writer.OnFrame(FrameWithProbes(i, 1)).ok());
  EXPECT_EQ(out.str(), header_only);
  ASSERT_TRUE(writer.OnFrame(FrameWithProbes(0, 1)).ok());
  EXPECT_EQ(lines(), 1 + CsvWriter::kRowsPerFlush);
  ASSERT_TRUE(writer.OnFrame(FrameWithProbes(0, 1)).ok());
  EXPECT_EQ(lines(), 1 + CsvWriter::kRowsPerFlush);
  ASSERT_TRUE(writer.Finish().ok());
  EXPECT_EQ(lines(), 2 + CsvWriter::kRowsPerFlush);
  EXPECT_EQ(writer.rows(), CsvWriter::kRowsPerFlush + 1);
}

TEST(CsvWriterTest, WrongProbeCountIsAnError) {
  std::ostringstream out;
  CsvWriter writer(&out, "memory");
  ASSERT_TRUE(writer.OnStart(InfoWithProbes({"a"})).ok());
  const absl::Status status = writer.OnFrame(FrameWithProbes(0, 2));
  EXPECT_FALSE(status.ok());
  EXPECT_FALSE(writer.status().ok());
  EXPECT_FALSE(writer.Finish().ok());
}

TEST(CsvWriterTest, FileIsCompleteAfterFinish) {
  const std::string path = ::testing::TempDir() + "/csv_writer_test_" + std::to_string(::getpid()) + ".csv";
  auto writer = CsvWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status();
  ASSERT_TRUE((*writer)->OnStart(InfoWithProbes({"p"})).ok());
  for (int i = 0; i < 250; ++i) ASSERT_TRUE((*writer)->OnFrame(FrameWithProbes(i, 1)).ok());
  ASSERT_TRUE((*writer)->Finish().ok());
  std::ifstream in(path);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 251);
  std::remove(path.c_str());
}

TEST(CsvWriterTest, FileIsFlushedOnDestruction) {
  const std::string path = ::testing::TempDir() + "/csv_writer_test_destroyed_" + std::to_string(::getpid()) + ".csv";
  {
    auto writer = CsvWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status();
    ASSERT_TRUE((*writer)->OnStart(InfoWithProbes({})).ok());
    ASSERT_TRUE((*writer)->OnFrame(FrameWithProbes(0, 0)).ok());
  }
  std::ifstream in(path);
  std::string header, row;
  ASSERT_TRUE(std::getline(in, header));
  ASSERT_TRUE(std::getline(in, row));
  EXPECT_EQ(row.substr(0, 2), "0,");
  std::remove(path.c_str());
}

TEST(CsvWriterTest, UnopenableFile) {
  auto writer = CsvWriter::Create("/nonexistent-dir/out.csv");
  ASSERT_FALSE(writer.ok());
  EXPECT_THAT(std::string(writer.status().message()), HasSubstr("/nonexistent-dir/out.csv"));
}

TEST(CsvWriterTest, WriteFailureIsReported) {
  std::ifstream probe("/dev/full");
  if (!probe) GTEST_SKIP() << "no /dev/full";
  auto writer = CsvWriter::Create("/dev/full");
  ASSERT_TRUE(writer.ok()) << writer.status();
  // The header is flushed at once, so /dev/full refuses it.
  EXPECT_FALSE((*writer)->OnStart(InfoWithProbes({"p"})).ok());
  EXPECT_FALSE((*writer)->Finish().ok());
}

}  // namespace
}  // namespace cablesim
