// Smoke test of the work-precision harness (bench/work_precision.cc): a tiny
// configuration through the real binary. Checks the CSV contract the plot
// script reads, that a rejected variant is skipped with its reason, and that
// the measured error behaves as backward Euler's must (first order).

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using Row = std::map<std::string, std::string>;

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::vector<Row> ReadCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<Row> rows;
  if (!std::getline(in, line)) return rows;
  const std::vector<std::string> header = SplitCsvLine(line);
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = SplitCsvLine(line);
    EXPECT_EQ(fields.size(), header.size()) << line;
    Row row;
    for (size_t k = 0; k < header.size() && k < fields.size(); ++k) row[header[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

constexpr char kConfig[] = R"({"repeats": 1,
 "integrators": [{"label": "IMPLICIT_EULER", "patch": {"solver": {"integrator": "IMPLICIT_EULER"}}},
                 {"label": "bogus", "patch": {"solver": {"integrator": "NOT_AN_INTEGRATOR"}}}],
 "linear_solvers": ["MINRES"],
 "scenes": [{"name": "falling-pendulum", "file": "scenes/falling-pendulum.json",
             "patch": {"solver": {"duration": 0.1, "output_interval": 0.01}},
             "steps": [1e-3, 5e-4], "tolerances": [],
             "reference": [{"solver": {"integrator": "IMPLICIT_EULER", "step": 1e-5}}]},
            {"name": "missing", "file": "scenes/no-such-scene.json", "steps": [1e-3], "reference": [{}]}],
 "scaling": {"scene": {"cables": [{"name": "rope", "length": 1, "elements": 10, "direction": {"y": -1},
                                   "density": 1000, "youngs_modulus": 1e8, "diameter": 0.01}],
                       "gravity": {"y": -9.81}, "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}}],
                       "probes": [{"name": "tip", "cable": "rope", "s": 1}], "solver": {"duration": 0.001}},
             "elements": [10, 20], "linear_solvers": ["MINRES"], "repeats": 1}})";

TEST(WorkPrecisionSmokeTest, TinyReport) {
  // A directory of this process's own: another checkout's tests may run
  // the same test at the same time.
  const std::filesystem::path dir = testing::Scratch(
      (std::filesystem::path(::testing::TempDir()) /
       ("work_precision_" + std::to_string(::getpid()))).string());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path config = dir / "config.json";
  std::ofstream(config) << kConfig;
  const std::string command =
      absl::StrCat(CABLESIM_BIN_DIR, "/work_precision --config ", config.string(), " --out ",
                   dir.string(), " --source-dir ", CABLESIM_SOURCE_DIR, " 2> ",
                   (dir / "log.txt").string());
  ASSERT_EQ(std::system(command.c_str()), 0) << command;

  const std::vector<Row> rows = ReadCsv(dir / "work_precision.csv");
  std::vector<Row> ok;
  bool bogus_skipped = false, missing_skipped = false;
  for (const Row& r : rows) {
    if (r.at("status") == "ok") ok.push_back(r);
    if (r.at("integrator") == "bogus") {
      EXPECT_EQ(r.at("status"), "skipped");
      EXPECT_THAT(r.at("note"), HasSubstr("NOT_AN_INTEGRATOR"));
      bogus_skipped = true;
    }
    if (r.at("scene") == "missing") {
      EXPECT_EQ(r.at("status"), "skipped");
      EXPECT_THAT(r.at("note"), HasSubstr("missing"));
      missing_skipped = true;
    }
  }
  EXPECT_TRUE(bogus_skipped);
  EXPECT_TRUE(missing_skipped);
  ASSERT_EQ(ok.size(), 2u);
  const double e1 = std::stod(ok[0].at("max_probe_error_m"));
  const double e2 = std::stod(ok[1].at("max_probe_error_m"));
  EXPECT_EQ(std::stod(ok[0].at("step_s")), 1e-3);
  EXPECT_GT(std::stod(ok[0].at("wall_s_median")), 0);
  EXPECT_EQ(ok[0].at("steps"), "100");
  // Backward Euler is first order: halving the step halves the error. The
  // reference (h = 1e-5) is 1 % of the coarse errors, and the O(h^2) terms
  // at h = 1e-3 over 0.1 s a few percent: 2 within 15 %.
  EXPECT_NEAR(e1 / e2, 2.0, 0.3);
  EXPECT_FALSE(ok[0].at("reference_self_error_m").empty());

  const std::vector<Row> scaling = ReadCsv(dir / "scaling.csv");
  ASSERT_EQ(scaling.size(), 2u);
  for (const Row& r : scaling) {
    EXPECT_EQ(r.at("status"), "ok") << r.at("note");
    // The time per step is the difference of two measured wall times over
    // the difference of their steps. Its sign is a measurement (a run of a
    // few hundred microseconds preempted on a busy machine makes it
    // negative; 13 of 200 repeats beside two CPU hogs), so the test checks
    // the arithmetic, not the clock: long minus short, over the steps.
    const double wall_short = std::stod(r.at("wall_short_s"));
    const double wall_long = std::stod(r.at("wall_long_s"));
    EXPECT_GT(wall_short, 0);
    EXPECT_GT(wall_long, 0);
    const double steps = std::stod(r.at("steps_long")) - std::stod(r.at("steps_short"));
    ASSERT_EQ(steps, 20);
    EXPECT_NEAR(std::stod(r.at("s_per_step")), (wall_long - wall_short) / steps,
                1e-12 * (wall_long + wall_short));
    // Counts, not times: positive whatever the load.
    EXPECT_GT(std::stod(r.at("newton_per_step")), 0);
  }
  EXPECT_EQ(scaling[1].at("elements"), "20");
}

}  // namespace
}  // namespace cablesim
