// Runs the sample scenes under scenes/ through the built `cablesim` binary,
// as a user would, and checks the exit code, the summary line and the CSV.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "cablesim/version.h"
#include "tests/process_util.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr char kEnergyColumns[] =
    "energy.kinetic,energy.potential,energy.axial,energy.bending,energy.total,"
    "constraint.violation,energy.damped";
// The energy per part of the sample scenes' one cable (README, "Energy per
// part"), after the totals.
constexpr char kCableEnergyColumns[] =
    "cables[0].energy.kinetic,cables[0].energy.gravity,cables[0].energy.axial,"
    "cables[0].energy.bending";
constexpr char kLoadsColumn[] = "loads.energy.potential";

using ::cablesim::testing::Process;
using ::cablesim::testing::RunCommand;

std::string ProbeColumns(const std::string& name) {
  std::vector<std::string> columns;
  for (const char* c : {"x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"}) {
    columns.push_back(absl::StrCat(name, ".", c));
  }
  return absl::StrJoin(columns, ",");
}

struct Csv {
  std::string header;
  std::vector<std::vector<double>> rows;
};

Csv ReadCsv(const std::string& path) {
  Csv csv;
  std::ifstream in(path);
  std::getline(in, csv.header);
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    for (const absl::string_view cell : absl::StrSplit(line, ',')) {
      row.push_back(std::stod(std::string(cell)));
    }
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

// Runs scenes/`scene` with --out and returns the CSV; checks the exit code
// and the summary line.
Csv RunSample(const std::string& scene) {
  const std::string binary = absl::StrCat(CABLESIM_BIN_DIR, "/cablesim");
  EXPECT_TRUE(std::ifstream(binary).good()) << "build the cablesim target first: " << binary;
  const std::string csv = testing::Scratch(
      absl::StrCat(::testing::TempDir(), "/cli_end_to_end_", ::getpid(), "_", scene, ".csv"));
  std::remove(csv.c_str());
  const Process p = RunCommand(absl::StrCat("'", binary, "' run '", CABLESIM_SOURCE_DIR, "/scenes/",
                                            scene, "' --out '", csv, "'"));
  EXPECT_EQ(p.exit_code, 0) << p.out;
  EXPECT_THAT(p.out, StartsWith(R"({"status":"ok",)"));
  EXPECT_EQ(p.out.find('\n'), p.out.size() - 1) << "one line: " << p.out;
  Csv result = ReadCsv(csv);
  EXPECT_THAT(p.out, HasSubstr(absl::StrCat("\"frames\":", result.rows.size(), ",")));
  int non_finite = 0;
  for (const std::vector<double>& row : result.rows) {
    for (const double value : row) non_finite += std::isfinite(value) ? 0 : 1;
  }
  EXPECT_EQ(non_finite, 0) << "non-finite numbers in the CSV";
  std::remove(csv.c_str());
  return result;
}

void ExpectTimes(const Csv& csv, size_t rows, double first, double last) {
  ASSERT_EQ(csv.rows.size(), rows);
  EXPECT_EQ(csv.rows.front()[0], first);
  EXPECT_NEAR(csv.rows.back()[0], last, 1e-9 * std::max(1.0, last));
  for (size_t i = 1; i < csv.rows.size(); ++i) {
    EXPECT_GT(csv.rows[i][0], csv.rows[i - 1][0]) << "row " << i;
  }
}

TEST(CliEndToEndTest, FallingPendulum) {
  const Csv csv = RunSample("falling-pendulum.json");
  EXPECT_EQ(csv.header, absl::StrCat("t,", ProbeColumns("tip"), ",", kEnergyColumns, ",",
                                     kCableEnergyColumns, ",", kLoadsColumn));
  ExpectTimes(csv, 1 + 1000, 0.0, 1.0);  // 1 s every 0.001 s
  // Starts horizontal at rest: the tip at (1.2, 0).
  EXPECT_NEAR(csv.rows.front()[1], 1.2, 1e-12);
  EXPECT_NEAR(csv.rows.front()[2], 0.0, 1e-12);
}

TEST(CliEndToEndTest, CableWithEndCylinder) {
  const Csv csv = RunSample("cable-with-end-cylinder.json");
  EXPECT_EQ(csv.header,
            absl::StrCat("t,", ProbeColumns("cylinder"), ",", kEnergyColumns, ",",
                         kCableEnergyColumns,
                         ",bodies[0].energy.kinetic,bodies[0].energy.gravity,", kLoadsColumn));
  ExpectTimes(csv, 1 + 2000, 0.0, 20.0);  // 20 s every 0.01 s
  EXPECT_NEAR(csv.rows.front()[1], 0.55, 1e-12);
}

TEST(CliEndToEndTest, CantileverLargeDeflection) {
  const Csv csv = RunSample("cantilever-large-deflection.json");
  EXPECT_EQ(csv.header, absl::StrCat("t,", ProbeColumns("tip"), ",", kEnergyColumns, ",",
                                     kCableEnergyColumns, ",", kLoadsColumn));
  // STATIC: one row per load increment, t the load factor in (0, 1].
  ExpectTimes(csv, 20, 1.0 / 20, 1.0);
  // The tip load bends the rod down.
  EXPECT_LT(csv.rows.back()[2], 0.0);
}

TEST(CliEndToEndTest, SpatialPendulum) {
  const Csv csv = RunSample("spatial-pendulum.json");
  EXPECT_EQ(csv.header,
            absl::StrCat("t,", ProbeColumns("tip"), ",", ProbeColumns("middle"), ",", kEnergyColumns,
                         ",", kCableEnergyColumns, ",", kLoadsColumn));
  ExpectTimes(csv, 1 + 2000, 0.0, 2.0);  // 2 s every 0.001 s
  // Spun at 4 rad/s about +y from along +x: the tip starts at (1, 0, 0)
  // moving at w x r = (0, 0, -4) m/s, and the z columns carry the motion.
  EXPECT_NEAR(csv.rows.front()[1], 1.0, 1e-12);
  EXPECT_NEAR(csv.rows.front()[6], -4.0, 1e-12);
  double zmax = 0;
  for (const auto& row : csv.rows) zmax = std::max(zmax, std::abs(row[3]));
  EXPECT_GT(zmax, 0.5);
}

// Both binaries say their version and build type (from CMake) and print
// their usage with exit code 0; a usage error exits with 2.
TEST(CliEndToEndTest, VersionAndHelpOfBothBinaries) {
  const std::string bin = CABLESIM_BIN_DIR;
  for (const std::string program : {"cablesim", "cablesim-server"}) {
    const Process version = RunCommand(absl::StrCat(bin, "/", program, " --version"));
    EXPECT_EQ(version.exit_code, 0) << program;
    EXPECT_EQ(version.out, VersionLine(program) + "\n");
    EXPECT_THAT(version.out, HasSubstr(absl::StrCat("(", CABLESIM_BUILD_TYPE, " build")));
    const Process help = RunCommand(absl::StrCat(bin, "/", program, " --help"));
    EXPECT_EQ(help.exit_code, 0) << program;
    EXPECT_THAT(help.out, HasSubstr("Exit status: 0"));
    const Process bad = RunCommand(absl::StrCat(bin, "/", program, " --no-such-flag 2>/dev/null"));
    EXPECT_EQ(bad.exit_code, 2) << program;
  }
  const Process help = RunCommand(bin + "/cablesim-server --help");
  EXPECT_THAT(help.out, HasSubstr("--data-dir  directory of the job database"));
  EXPECT_THAT(help.out, HasSubstr("--max-message-bytes"));
}

}  // namespace
}  // namespace cablesim
