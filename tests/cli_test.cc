// The command line, run in-process through RunCli.

#include "client/cli.h"
#include "client/service_client.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "client/csv_writer.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

struct CliResult {
  int code = -1;
  std::string out;
  std::string err;
};

CliResult Cli(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  CliResult result;
  result.code = RunCli(args, out, err);
  result.out = out.str();
  result.err = err.str();
  return result;
}

std::string SampleScene(const char* name) {
  return absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/", name);
}

std::string WriteTempFile(const std::string& name, const std::string& contents) {
  const std::string path =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/cli_test_", ::getpid(), "_", name));
  std::ofstream(path) << contents;
  return path;
}

std::vector<std::string> ReadLines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// A tiny dynamic scene: 2 elements, 4 steps, 3 frames (t = 0, 0.01, 0.02).
constexpr char kTinyScene[] = R"({
  "name": "tiny",
  "gravity": {"y": -9.81},
  "cables": [{"name": "c", "length": 0.5, "elements": 2, "density": 1000,
              "youngs_modulus": 1e7, "diameter": 0.01}],
  "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
  "probes": [{"name": "end", "cable": "c", "s": 0.5}],
  "solver": {"duration": 0.02, "step": 0.005, "output_interval": 0.01}
})";

// The model of a scene with one cable, named "c", and these probes.
ModelInfo OneCable(std::vector<std::string> probes) {
  ModelInfo info;
  info.probe_names = std::move(probes);
  info.cable_names = {"c"};
  return info;
}

TEST(CliTest, NoArgumentsIsAUsageError) {
  const CliResult r = Cli({});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("Usage:"));
  EXPECT_EQ(r.out, "");
}

TEST(CliTest, UnknownCommandIsAUsageError) {
  const CliResult r = Cli({"frobnicate", "x.json"});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("cablesim: unknown command \"frobnicate\""));
  EXPECT_THAT(r.err, HasSubstr("Usage:"));
}

TEST(CliTest, UnknownOptionIsAUsageError) {
  const CliResult r = Cli({"run", SampleScene("falling-pendulum.json"), "--outt=x.csv"});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown option --outt=x.csv"));
}

// The spellings the parser (CLI11) takes, as the hand-written one did: a
// single dash before a long name, --name=value, -o, the last --out wins,
// and a value that is missing or empty is named.
TEST(CliTest, OptionSpellings) {
  const std::string scene = WriteTempFile("spellings_scene.json", kTinyScene);
  const std::string first = WriteTempFile("spellings_first.csv", ""),
                    last = WriteTempFile("spellings_last.csv", "");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", scene, "-out", last},
        {"run", scene, "--out=" + last},
        {"run", "--out", first, scene, "-o", last}}) {
    std::filesystem::remove(first);
    std::filesystem::remove(last);
    const CliResult r = Cli(args);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(last)) << absl::StrJoin(args, " ");
    EXPECT_FALSE(std::filesystem::exists(first)) << absl::StrJoin(args, " ");
  }
  EXPECT_EQ(Cli({"-version"}).code, 0);
  EXPECT_THAT(Cli({"run", scene, "--out="}).err, HasSubstr("--out needs a file"));
  EXPECT_THAT(Cli({"run", scene, "--server"}).err, HasSubstr("--server needs a value"));
  EXPECT_THAT(Cli({"run", scene, "--strict=1"}).err, HasSubstr("--strict takes no value"));
  EXPECT_THAT(Cli({"run", scene, "-strikt"}).err, HasSubstr("unknown option --strikt"));
}

TEST(CliTest, MissingSceneArgument) {
  EXPECT_EQ(Cli({"run"}).code, 2);
  EXPECT_EQ(Cli({"validate"}).code, 2);
  EXPECT_EQ(Cli({"run", "--out"}).code, 2);
  EXPECT_EQ(Cli({"validate", "a.json", "b.json"}).code, 2);
}

TEST(CliTest, Help) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"}, {"help"}, {"run", "--help"}}) {
    const CliResult r = Cli(args);
    EXPECT_EQ(r.code, 0);
    EXPECT_THAT(r.out, HasSubstr("cablesim run SCENE [--out FILE.csv]"));
    EXPECT_EQ(r.err, "");
  }
}

TEST(CliTest, SweepRefusesABaseFileOutsideItsDirectoryUnlessAllowed) {
  // The sample sweep's base scene is in ../scenes.
  const std::string sweep = absl::StrCat(CABLESIM_SOURCE_DIR, "/sweeps/pendulum-resolution.json");
  const CliResult refused = Cli({"sweep", sweep});
  EXPECT_EQ(refused.code, 2);
  EXPECT_THAT(refused.err, HasSubstr("base_file: must be under the sweep file's directory"));
  const CliResult bad_flag = Cli({"sweep", sweep, "--allow-outside=yes"});
  EXPECT_EQ(bad_flag.code, 2);
  EXPECT_THAT(bad_flag.err, HasSubstr("--allow-outside takes no value"));
  EXPECT_EQ(Cli({"run", SampleScene("falling-pendulum.json"), "--allow-outside"}).code, 2);
}

// `energy --out` names its columns as the run CSV does.
TEST(CliTest, EnergyCsvUsesTheRunCsvColumnNames) {
  const std::string scene = WriteTempFile("energy_scene.json", kTinyScene);
  const std::string csv =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/cli_test_", ::getpid(), "_energy.csv"));
  const CliResult r = Cli({"energy", scene, "--out", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_EQ(lines.size(), 4u);  // header and 3 frames
  EXPECT_EQ(lines[0],
            "t,energy.kinetic,energy.potential,energy.axial,energy.bending,energy.total,"
            "constraint.violation,energy.damped,cables[0].energy.kinetic,cables[0].energy.gravity,"
            "cables[0].energy.axial,cables[0].energy.bending,loads.energy.potential");
}

TEST(CliTest, MissingFileIsBadInput) {
  for (const char* command : {"run", "validate"}) {
    const CliResult r = Cli({command, "/nonexistent/scene.json"});
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_THAT(r.err, StartsWith("cablesim: /nonexistent/scene.json: ")) << command;
  }
}

TEST(CliTest, InvalidSceneIsBadInputWithTheFieldPath) {
  const std::string path = WriteTempFile("invalid.json", R"({
    "cables": [{"name": "c", "length": -1, "density": 1000, "youngs_modulus": 1e7,
                "diameter": 0.01}],
    "solver": {"duration": 1}})");
  for (const char* command : {"run", "validate"}) {
    const CliResult r = Cli({command, path});
    EXPECT_EQ(r.code, 2) << command;
    EXPECT_EQ(r.err, absl::StrCat("cablesim: ", path, ": cables[0].length: must be > 0 (got -1)\n"))
        << command;
  }
  // validate also answers in JSON.
  const CliResult r = Cli({"validate", path});
  EXPECT_THAT(r.out, StartsWith(R"({"status":"invalid",)"));
  EXPECT_THAT(r.out, HasSubstr(R"j("error":"cables[0].length: must be > 0 (got -1)")j"));
  std::remove(path.c_str());
}

TEST(CliTest, UnparsableSceneIsBadInputWithTheFieldName) {
  const std::string path =
      WriteTempFile("unknown_field.json", R"({"cables": [{"name": "c", "lenght": 1}]})");
  const CliResult r = Cli({"run", path});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith(absl::StrCat("cablesim: ", path, ": ")));
  EXPECT_THAT(r.err, HasSubstr("lenght"));
  std::remove(path.c_str());
}

TEST(CliTest, TextFormatScene) {
  const std::string path = WriteTempFile("scene.txtpb", R"pb(
    name: "text"
    cables { name: "c" length: 1 density: 1000 youngs_modulus: 1e7 diameter: 0.01 }
    solver { duration: 1 }
  )pb");
  const CliResult r = Cli({"validate", path});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("name":"text")"));
  std::remove(path.c_str());
}

TEST(CliTest, ValidateSampleScenes) {
  const CliResult pendulum = Cli({"validate", SampleScene("falling-pendulum.json")});
  EXPECT_EQ(pendulum.code, 0) << pendulum.err;
  // The paper's soft beam (E = 0.7 MPa) would stretch 9 % hanging: its one
  // plausibility warning, listed in the JSON line and on standard error.
  EXPECT_THAT(pendulum.err,
              StartsWith("cablesim: warning: cables[0] 'beam': the static strain under its "
                         "weight, payload and loads is about 9.32 %"));
  EXPECT_EQ(pendulum.err.find('\n'), pendulum.err.size() - 1) << pendulum.err;
  EXPECT_THAT(pendulum.out, HasSubstr(R"("warnings":["cables[0] 'beam': the static strain)"));
  EXPECT_THAT(pendulum.out, StartsWith(R"({"status":"ok",)"));
  EXPECT_THAT(pendulum.out,
              HasSubstr(R"("name":"falling-pendulum","cables":1,"bodies":0,"joints":1,)"
                        R"("loads":0,"probes":1,"analysis":"DYNAMIC")"));
  EXPECT_EQ(pendulum.out.back(), '\n');
  EXPECT_EQ(pendulum.out.find('\n'), pendulum.out.size() - 1);  // one line

  const CliResult cylinder = Cli({"validate", SampleScene("cable-with-end-cylinder.json")});
  EXPECT_EQ(cylinder.code, 0) << cylinder.err;
  EXPECT_EQ(cylinder.err, "");  // no plausibility warning
  EXPECT_THAT(cylinder.out, HasSubstr(R"("warnings":[])"));
  EXPECT_THAT(cylinder.out, HasSubstr(R"("bodies":1,"joints":2,)"));

  const CliResult cantilever = Cli({"validate", SampleScene("cantilever-large-deflection.json")});
  EXPECT_EQ(cantilever.code, 0) << cantilever.err;
  EXPECT_THAT(cantilever.out, HasSubstr(R"("analysis":"STATIC")"));
  EXPECT_THAT(cantilever.out, HasSubstr(R"("load_steps":20)"));
}

TEST(CliTest, ValidateTakesNoOut) {
  const CliResult r = Cli({"validate", SampleScene("falling-pendulum.json"), "--out", "x.csv"});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("--out is only for run"));
}

TEST(CliTest, RunWritesSummaryAndCsv) {
  const std::string scene = WriteTempFile("tiny.json", kTinyScene);
  const std::string csv =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/cli_test_", ::getpid(), "_tiny.csv"));
  // Twice, with both spellings of --out: RunCli keeps no state.
  for (const std::string& out_flag : {std::string("--out=") + csv, std::string("--out")}) {
    std::vector<std::string> args = {"run", scene, out_flag};
    if (out_flag == "--out") args.push_back(csv);
    const CliResult r = Cli(args);
    ASSERT_EQ(r.code, 0) << r.err;
    // The one plausibility warning of this tiny scene, and nothing else.
    EXPECT_THAT(r.err, StartsWith("cablesim: warning: cables[0].elements: 2 elements of 0.25 m "
                                  "are longer than 1/10 of the cable"));
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    EXPECT_THAT(r.out, StartsWith(R"({"status":"ok",)"));
    EXPECT_THAT(r.out, HasSubstr(R"("model":"planar")"));
    const std::vector<std::string> lines = ReadLines(csv);
    ASSERT_EQ(lines.size(), 4);  // header and t = 0, 0.01, 0.02
    EXPECT_EQ(lines[0], CsvWriter::Header(OneCable({"end"})));
    EXPECT_THAT(lines[1], StartsWith("0,"));
    const std::vector<std::string> last = absl::StrSplit(lines[3], ',');
    EXPECT_NEAR(std::stod(last[0]), 0.02, 1e-12);
  }
  std::remove(csv.c_str());
  std::remove(scene.c_str());
}

// Line failure in the CSV: the tiny scene's support lets go at t = 0.01 s;
// its column joints[0].released ends the frame columns, 0 at t = 0 and at
// the release (that frame still shows it holding), 1 after; the scene
// without the release has no such column (the CSV above).
TEST(CliTest, RunCsvMarksAReleasedJoint) {
  std::string json = kTinyScene;
  const std::string pin = R"("a": {"cable": "c", "s": 0})";
  json.insert(json.find(pin) + pin.size(), R"(, "release": {"time": 0.01})");
  const std::string scene = WriteTempFile("tiny_release.json", json);
  const std::string csv = testing::Scratch(
      absl::StrCat(::testing::TempDir(), "/cli_test_", ::getpid(), "_tiny_release.csv"));
  const CliResult r = Cli({"run", scene, "--out", csv});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("releases":[{"joint":0,)"));
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_EQ(lines.size(), 4);  // header and t = 0, 0.01, 0.02
  EXPECT_EQ(lines[0], CsvWriter::Header(OneCable({"end"})) + ",joints[0].released");
  const std::vector<std::string> expected = {"0", "0", "1"};
  for (int k = 1; k <= 3; ++k) {
    const std::vector<std::string> cells = absl::StrSplit(lines[k], ',');
    EXPECT_EQ(cells.back(), expected[k - 1]) << lines[k];
  }
  std::remove(csv.c_str());
  std::remove(scene.c_str());
}

TEST(CliTest, RunWithoutOut) {
  const std::string scene = WriteTempFile("tiny_no_out.json", kTinyScene);
  const CliResult r = Cli({"run", scene});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, StartsWith(R"({"status":"ok",)"));
  EXPECT_THAT(r.out, HasSubstr(R"("frames":3,)"));
  std::remove(scene.c_str());
}

TEST(CliTest, UnwritableOutIsAnIoError) {
  const std::string scene = WriteTempFile("tiny_bad_out.json", kTinyScene);
  const CliResult r = Cli({"run", scene, "--out", "/nonexistent-dir/out.csv"});
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, StartsWith("cablesim: /nonexistent-dir/out.csv: "));
  std::remove(scene.c_str());
}

TEST(CliTest, FullDiskIsAnIoError) {
  if (!std::ifstream("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string scene = WriteTempFile("tiny_full.json", kTinyScene);
  const CliResult r = Cli({"run", scene, "--out", "/dev/full"});
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, StartsWith("cablesim: /dev/full: "));
  std::remove(scene.c_str());
}

TEST(CliTest, NumericalFailureExitsWith3AndKeepsTheCsv) {
  // One Newton iteration and no step halving cannot carry a stiff cable
  // through a 0.5 s step.
  const std::string scene = WriteTempFile("failing.json", R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "elements": 4, "density": 1000,
                "youngs_modulus": 1e9, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": {"duration": 1, "step": 0.5, "max_newton_iterations": 1,
               "max_step_halvings": 0}})");
  const std::string csv =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/cli_test_", ::getpid(), "_failing.csv"));
  const CliResult r = Cli({"run", scene, "--out", csv});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_THAT(r.out, StartsWith(R"({"status":"failed","error":")"));
  EXPECT_THAT(r.out, HasSubstr(R"("failure_time_s":)"));
  // The scene's two plausibility warnings (4 coarse elements; a 0.5 s
  // step over the cable's 3.6 ms axial bounce), then the failure.
  EXPECT_THAT(r.err, StartsWith("cablesim: warning: cables[0].elements: 4 elements"));
  EXPECT_THAT(r.err, HasSubstr("\ncablesim: warning: solver.step: 0.5 s is above the shortest "
                               "period"));
  EXPECT_THAT(r.err, HasSubstr("\ncablesim: numerical failure at t = "));
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_GE(lines.size(), 2);  // the header and the frame at t = 0
  EXPECT_EQ(lines[0], CsvWriter::Header(OneCable({})));
  EXPECT_THAT(lines[1], StartsWith("0,"));
  std::remove(csv.c_str());
  std::remove(scene.c_str());
}

// The review: the in-process CLI applied no limits at all (a 1e9-step
// scene ground silently). Now it applies the server's default limits,
// refusing such a scene at once naming the limit, unless --no-limits.
TEST(CliTest, InProcessRunsApplyTheServerDefaultLimitsUnlessNoLimits) {
  std::string scene = kTinyScene;
  scene.replace(scene.find(R"("duration": 0.02, "step": 0.005)"),
                std::string(R"("duration": 0.02, "step": 0.005)").size(),
                R"("duration": 1000, "step": 1e-6)");  // 1e9 steps
  const std::string path = WriteTempFile("billion_steps.json", scene);
  const auto start = std::chrono::steady_clock::now();
  const CliResult run = Cli({"run", path});
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_THAT(run.err, HasSubstr("max_steps"));
  const CliResult validate = Cli({"validate", path});
  EXPECT_EQ(validate.code, 2);
  EXPECT_THAT(validate.out, HasSubstr("max_steps"));
  const CliResult lifted = Cli({"validate", path, "--no-limits"});
  EXPECT_EQ(lifted.code, 0) << lifted.err;
  EXPECT_EQ(Cli({"validate", path, "--no-limits", "--server", "127.0.0.1:1"}).code, 2);
  // The limits are the server's: its --help shows the same defaults.
  const ServerLimits limits = DefaultServerLimits();
  EXPECT_EQ(limits.max_steps, 5'000'000);
  EXPECT_EQ(Cli({"validate", path}).code, 2);  // each command sets its own
  EXPECT_EQ(InProcessLimits().max_elements, limits.max_elements);
}

// Run warnings go to standard error and the summary, exit 0; --strict
// fails a run with warnings with exit 3 (docs/honest-runs.md).
// A body falling freely under backward Euler: local error g h^2 / 2 =
// 4.9e-4 m per step, against the given tolerance.
std::string FreeFall(double tolerance) {
  return absl::StrCat(R"({"name": "free-fall", "gravity": {"y": -9.81},
      "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 1, "y": 1, "z": 1}}],
      "probes": [{"name": "b", "body": "b"}],
      "solver": {"duration": 0.05, "step": 0.01, "integrator": "IMPLICIT_EULER",
                 "tolerance": )",
                      tolerance, "}}");
}

TEST(CliStrictTest, WarningsGoToStandardErrorAndTheSummary) {
  const std::string path = WriteTempFile("strict_loose.json", FreeFall(1e-4));
  const CliResult r = Cli({"run", path});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("status":"ok")"));
  EXPECT_THAT(r.out, HasSubstr(R"("error_tolerance_m":1e-04)"));
  EXPECT_THAT(r.out, HasSubstr(R"("warnings":["the estimated local error of a step)"));
  EXPECT_THAT(r.err, HasSubstr("cablesim: warning: the estimated local error of a step"));
}

TEST(CliStrictTest, StrictFailsARunWithWarningsWithExitThree) {
  const std::string path = WriteTempFile("strict_strict.json", FreeFall(1e-4));
  const CliResult r = Cli({"run", path, "--strict"});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("status":"failed")"));
  EXPECT_THAT(r.out, HasSubstr(R"("error":"solver.strict: the estimated local error)"));
  EXPECT_THAT(r.err, HasSubstr("cablesim: numerical failure at t = 0.05: solver.strict:"));
}

TEST(CliStrictTest, StrictPassesARunWithoutWarnings) {
  const std::string path = WriteTempFile("strict_quiet.json", FreeFall(1e-3));
  const CliResult r = Cli({"run", path, "--strict"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("warnings":[])"));
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
}

TEST(CliStrictTest, StrictIsForRunAndSubmitOnly) {
  const std::string path = WriteTempFile("strict_validate.json", FreeFall(1e-3));
  const CliResult r = Cli({"validate", path, "--strict"});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("validate: no option --strict"));
  EXPECT_EQ(Cli({"run", path, "--strict=yes"}).code, 2);
}

}  // namespace
}  // namespace cablesim
