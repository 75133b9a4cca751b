// The built `cablesim` binary, as a user runs it: the summary's statistics
// (output.statistics, output.rainflow), sweep thresholds on physical results
// (--max/--min COLUMN=VALUE) and the JUnit report (--junit), read back with
// Python's xml.etree (an XML parser independent of the writer).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "absl/strings/str_cat.h"
#include "tests/process_util.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

using ::cablesim::testing::Process;

// Runs `command`, its stderr after its stdout.
Process Sh(const std::string& command) { return testing::RunCommand(command + " 2>&1"); }

std::string Cablesim(const std::string& args) {
  return absl::StrCat(CABLESIM_BIN_DIR, "/cablesim ", args);
}

std::string TempFile(const std::string& name, const std::string& contents) {
  const std::string path = testing::Scratch(
      absl::StrCat(::testing::TempDir(), "/cli_statistics_", ::getpid(), "_", name));
  std::ofstream(path) << contents;
  return path;
}

// A pinned cable, 2 elements, 0.1 s: its free end "end" starts at y = 0
// and, with gravity, falls.
constexpr char kBase[] = R"({
  "name": "tiny",
  "gravity": {"y": -9.81},
  "cables": [{"name": "c", "length": 0.5, "elements": 2, "density": 1000,
              "youngs_modulus": 1e7, "diameter": 0.01}],
  "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
  "probes": [{"name": "end", "cable": "c", "s": 0.5}],
  "solver": {"duration": 0.1, "step": 0.005, "output_interval": 0.01}%s
})";

std::string Scene(const std::string& extra) {
  std::string s = kBase;
  s.replace(s.find("%s"), 2, extra);
  return s;
}

TEST(CliStatisticsTest, RunSummaryCarriesStatisticsOnlyWhenAsked) {
  const Process plain = Sh(Cablesim(absl::StrCat("run ", TempFile("plain.json", Scene("")))));
  ASSERT_EQ(plain.exit_code, 0) << plain.out;
  EXPECT_THAT(plain.out, Not(HasSubstr("\"statistics\"")));
  const Process stats = Sh(Cablesim(absl::StrCat(
      "run ", TempFile("stats.json",
                       Scene(R"(, "output": {"statistics": true, "rainflow": {"columns": ["end.y"],
                             "sn_slope": 3, "equivalent_cycles": 1e7}})")))));
  ASSERT_EQ(stats.exit_code, 0) << stats.out;
  EXPECT_THAT(stats.out, HasSubstr("\"statistics\":{\"columns\":[{\"column\":\"end.x\",\"count\":11,"));
  EXPECT_THAT(stats.out, HasSubstr("\"rainflow\":[{\"column\":\"end.y\",\"cycles\":"));
  // Every rainflow field is checked, naming it (exit 2).
  for (const auto& [rainflow, message] : std::vector<std::pair<std::string, std::string>>{
           {R"({"columns": ["end.q"], "sn_slope": 3, "equivalent_cycles": 1e7})",
            "output.rainflow.columns[0]: no frame column \"end.q\""},
           {R"({"columns": ["end.y"], "sn_slope": -3, "equivalent_cycles": 1e7})",
            "output.rainflow.sn_slope: must be a number > 0"},
           {R"({"columns": ["end.y"], "sn_slope": 3})",
            "output.rainflow.equivalent_cycles: must be a number > 0"}}) {
    const Process bad = Sh(Cablesim(absl::StrCat(
        "run ", TempFile("bad.json", Scene(absl::StrCat(R"(, "output": {"rainflow": )", rainflow,
                                                        "}"))))));
    EXPECT_EQ(bad.exit_code, 2) << bad.out;
    EXPECT_THAT(bad.out, HasSubstr(message));
  }
}

// Two items, gravity.y = 0 (the end stays at y = 0) and -9.81 (it falls):
// --min end.y=-1e-6 passes the first and fails the second.
std::string SweepFile() {
  return TempFile("sweep.json",
                  absl::StrCat(R"({"name": "fall", "base": )", Scene(""),
                               R"(, "axes": [{"path": "gravity.y", "values": [0, -9.81]}]})"));
}

// Python's xml.etree reads the report back: per testcase, its name and
// failure message (or "pass"), one line each.
Process ReadJUnit(const std::string& path) {
  return Sh(absl::StrCat(
      "python3 -c 'import sys, xml.etree.ElementTree as ET\n"
      "root = ET.parse(sys.argv[1]).getroot()\n"
      "suite = root.find(\"testsuite\")\n"
      "print(\"tests\", suite.get(\"tests\"), \"failures\", suite.get(\"failures\"))\n"
      "for case in suite.findall(\"testcase\"):\n"
      "    f = case.find(\"failure\")\n"
      "    print(case.get(\"name\"), \"|\", \"pass\" if f is None else f.get(\"message\"))\n' ",
      path));
}

TEST(CliStatisticsTest, SweepThresholdFailsTheItemNamingItsAxisValues) {
  const std::string junit = testing::Scratch(
      absl::StrCat(::testing::TempDir(), "/cli_statistics_", ::getpid(), "_junit.xml"));
  const Process r = Sh(Cablesim(absl::StrCat("sweep ", SweepFile(), " --workers 1",
                                             " --min end.y=-1e-6 --max end.y=1 --junit ", junit)));
  EXPECT_EQ(r.exit_code, 3) << r.out;
  // The table ends with the judged values: min.end.y, max.end.y.
  EXPECT_THAT(r.out, HasSubstr(",final.end.x,"));
  EXPECT_THAT(r.out, HasSubstr(",final.loads.energy.potential,min.end.y,max.end.y\n"));
  EXPECT_THAT(r.out, HasSubstr("sweep item 1 (gravity.y=-9.81; j-"));
  EXPECT_THAT(r.out, HasSubstr("): end.y min -"));
  EXPECT_THAT(r.out, HasSubstr(" is below -1e-06"));
  EXPECT_THAT(r.out, Not(HasSubstr("sweep item 0 (")));
  EXPECT_THAT(r.out, HasSubstr("2 of 2 items succeeded, 1 threshold violations"));
  const Process xml = ReadJUnit(junit);
  ASSERT_EQ(xml.exit_code, 0) << xml.out;
  EXPECT_THAT(xml.out, HasSubstr("tests 2 failures 1\n"));
  EXPECT_THAT(xml.out, HasSubstr("item 0: gravity.y=0 | pass\n"));
  EXPECT_THAT(xml.out, HasSubstr("item 1: gravity.y=-9.81 | end.y min -"));

  // Thresholds that hold: exit 0, no failure in the report.
  const Process ok = Sh(Cablesim(absl::StrCat("sweep ", SweepFile(), " --workers 1 --out /dev/null",
                                              " --max end.y=1e-6 --junit ", junit)));
  EXPECT_EQ(ok.exit_code, 0) << ok.out;
  const Process passed = ReadJUnit(junit);
  EXPECT_THAT(passed.out, HasSubstr("tests 2 failures 0\n"));
}

TEST(CliStatisticsTest, SweepThresholdOnAnUnknownColumnIsRefused) {
  const Process r = Sh(Cablesim(absl::StrCat("sweep ", SweepFile(), " --max nope.y=1")));
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_THAT(r.out, HasSubstr("--max nope.y=1"));
  EXPECT_THAT(r.out, HasSubstr("no frame column \"nope.y\""));
  for (const char* bad : {"--max end.y", "--min end.y=abc", "--max =3"}) {
    const Process usage = Sh(Cablesim(absl::StrCat("sweep ", SweepFile(), " ", bad)));
    EXPECT_EQ(usage.exit_code, 2) << bad << ": " << usage.out;
  }
}

}  // namespace
}  // namespace cablesim
