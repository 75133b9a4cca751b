// `cablesim run` prints each run warning on standard error, keeps exit 0,
// and with --strict fails the run with exit 3 (docs/honest-runs.md).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <unistd.h>

#include "absl/strings/str_cat.h"
#include "client/cli.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct CliResult {
  int code = -1;
  std::string out, err;
};

CliResult Cli(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  CliResult r;
  r.code = RunCli(args, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

std::string WriteScene(const std::string& name, const std::string& json) {
  const std::string path =
      absl::StrCat(::testing::TempDir(), "/cli_strict_test_", ::getpid(), "_", name);
  std::ofstream(path) << json;
  return path;
}

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
  const std::string path = WriteScene("loose.json", FreeFall(1e-4));
  const CliResult r = Cli({"run", path});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("status":"ok")"));
  EXPECT_THAT(r.out, HasSubstr(R"("error_tolerance_m":1e-04)"));
  EXPECT_THAT(r.out, HasSubstr(R"("warnings":["the estimated local error of a step)"));
  EXPECT_THAT(r.err, HasSubstr("cablesim: warning: the estimated local error of a step"));
}

TEST(CliStrictTest, StrictFailsARunWithWarningsWithExitThree) {
  const std::string path = WriteScene("strict.json", FreeFall(1e-4));
  const CliResult r = Cli({"run", path, "--strict"});
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("status":"failed")"));
  EXPECT_THAT(r.out, HasSubstr(R"("error":"solver.strict: the estimated local error)"));
  EXPECT_THAT(r.err, HasSubstr("cablesim: numerical failure at t = 0.05: solver.strict:"));
}

TEST(CliStrictTest, StrictPassesARunWithoutWarnings) {
  const std::string path = WriteScene("quiet.json", FreeFall(1e-3));
  const CliResult r = Cli({"run", path, "--strict"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr(R"("warnings":[])"));
  EXPECT_THAT(r.err, Not(HasSubstr("warning")));
}

TEST(CliStrictTest, StrictIsForRunAndSubmitOnly) {
  const std::string path = WriteScene("validate.json", FreeFall(1e-3));
  const CliResult r = Cli({"validate", path, "--strict"});
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("validate: no option --strict"));
  EXPECT_EQ(Cli({"run", path, "--strict=yes"}).code, 2);
}

}  // namespace
}  // namespace cablesim
