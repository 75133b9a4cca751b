// The command line against a cablesim-server on a loopback port, and its
// sweep command in-process: the same output as the in-process run, the job
// commands, a sweep that fails on a threshold, and one item of a sweep
// run alone (--item).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "client/cli.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

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

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string WithoutWallTime(const std::string& json) {
  const size_t at = json.find("\"wall_seconds\":");
  const size_t end = json.find(',', at);
  return json.substr(0, at) + json.substr(end + 1);
}

class CliServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(testing::FreshDir("cli_server"));
    gate_ = new testing::JobGate(*dir_);
    server_ = new testing::ServerProcess(*dir_, {"--workers=1"}, {gate_->env()});
  }
  static void TearDownTestSuite() {
    delete server_;
    delete gate_;
    delete dir_;
  }
  // The falling pendulum with another duration; `scene_name` "gated..."
  // makes a job of it wait at the server's test-only gate after its first
  // frame.
  static std::string Scene(const std::string& name, double duration,
                           const std::string& scene_name = "falling-pendulum") {
    const std::string path = absl::StrCat(*dir_, "/", name, ".json");
    std::string json = Read(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/falling-pendulum.json"));
    const size_t at = json.find("\"duration\": 1.0");
    json.replace(at, 15, absl::StrCat("\"duration\": ", duration));
    const std::string name_field = "\"name\": \"falling-pendulum\"";
    json.replace(json.find(name_field), name_field.size(),
                 absl::StrCat("\"name\": \"", scene_name, "\""));
    std::ofstream(path) << json;
    return path;
  }
  static std::string* dir_;
  static testing::JobGate* gate_;
  static testing::ServerProcess* server_;
};
std::string* CliServerTest::dir_ = nullptr;
testing::JobGate* CliServerTest::gate_ = nullptr;
testing::ServerProcess* CliServerTest::server_ = nullptr;

TEST_F(CliServerTest, RunOnTheServerPrintsWhatTheInProcessRunPrints) {
  const std::string scene = Scene("short", 0.05);
  const std::string local_csv = *dir_ + "/local.csv", remote_csv = *dir_ + "/remote.csv";
  const CliResult local = Cli({"run", scene, "--out", local_csv});
  const CliResult remote = Cli({"run", scene, "--out", remote_csv, "--server", server_->address()});
  ASSERT_EQ(local.code, 0) << local.err;
  ASSERT_EQ(remote.code, 0) << remote.err;
  EXPECT_EQ(WithoutWallTime(remote.out), WithoutWallTime(local.out));
  EXPECT_EQ(Read(remote_csv), Read(local_csv));
  EXPECT_EQ(std::count(local.out.begin(), local.out.end(), '\n'), 1);
}

TEST_F(CliServerTest, InvalidSceneOnTheServerIsExitCode2WithTheField) {
  const std::string path = *dir_ + "/bad.json";
  std::ofstream(path) << R"({"cables": [{"name": "c", "length": -1, "density": 1,
                             "youngs_modulus": 1, "diameter": 0.01}],
                             "solver": {"duration": 1}})";
  const CliResult r = Cli({"run", path, "--server", server_->address()});
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, absl::StrCat("cablesim: ", path, ": cables[0].length: must be > 0 (got -1)\n"));
}

TEST_F(CliServerTest, UnreachableServerIsExitCode1) {
  const CliResult r = Cli({"run", Scene("short", 0.01), "--server", "127.0.0.1:1"});
  EXPECT_EQ(r.code, 1);
  EXPECT_THAT(r.err, StartsWith("cablesim: UNAVAILABLE"));
}

TEST_F(CliServerTest, SubmitWatchJobsEnergyCancel) {
  const std::string address = server_->address();
  const CliResult submitted = Cli({"submit", Scene("job", 0.1), "--server", address});
  ASSERT_EQ(submitted.code, 0) << submitted.err;
  EXPECT_THAT(submitted.out, StartsWith(R"({"id":"j-)"));
  const std::string id = submitted.out.substr(7, submitted.out.find('"', 7) - 7);
  const std::string csv = *dir_ + "/job.csv";
  const CliResult watched = Cli({"watch", id, "--server", address, "--out", csv});
  ASSERT_EQ(watched.code, 0) << watched.err;
  EXPECT_THAT(watched.out, StartsWith(R"({"status":"ok",)"));
  EXPECT_THAT(watched.out, HasSubstr(R"("frames":101,)"));
  const std::vector<std::string> lines = absl::StrSplit(Read(csv), '\n', absl::SkipEmpty());
  EXPECT_EQ(lines.size(), 102u);  // header + 101 frames

  const CliResult jobs = Cli({"jobs", "--server", address, "--state", "succeeded"});
  ASSERT_EQ(jobs.code, 0) << jobs.err;
  EXPECT_THAT(jobs.out, HasSubstr(absl::StrCat(R"({"id":")", id, R"(","state":"SUCCEEDED")")));

  const CliResult energy = Cli({"energy", id, "--server", address});
  ASSERT_EQ(energy.code, 0) << energy.err;
  EXPECT_THAT(energy.out, HasSubstr(R"("frames":101,)"));
  EXPECT_THAT(energy.out, HasSubstr(R"("relative_drift":-)"));  // dissipation

  // Cancel, both ways, each chosen by the test, not by when the worker
  // takes the job: `long` never finishes by itself (its gate stays shut)
  // and is cancelled once it is running at its gate; `queued`, submitted
  // while `long` holds the only worker, is cancelled before it ever runs.
  const CliResult long_job = Cli({"submit", Scene("long", 19, "gated-long"), "--server", address});
  ASSERT_EQ(long_job.code, 0);
  const std::string long_id = long_job.out.substr(7, long_job.out.find('"', 7) - 7);
  ASSERT_TRUE(server_->WaitForLog(absl::StrCat("job ", long_id, " waits at the gate")));
  const CliResult queued_job =
      Cli({"submit", Scene("queued", 19, "gated-queued"), "--server", address});
  ASSERT_EQ(queued_job.code, 0);
  const std::string queued_id = queued_job.out.substr(7, queued_job.out.find('"', 7) - 7);
  for (const std::string& job : {queued_id, long_id}) {
    const CliResult cancelled = Cli({"cancel", job, "--server", address});
    ASSERT_EQ(cancelled.code, 0) << cancelled.err;
  }
  const CliResult after_queued = Cli({"watch", queued_id, "--server", address});
  EXPECT_EQ(after_queued.code, 1);  // cancelled is not success
  EXPECT_THAT(after_queued.out, HasSubstr(R"("state":"CANCELLED")"));
  EXPECT_THAT(after_queued.out, HasSubstr(R"("attempts":0,)"));  // never ran
  const CliResult after_running = Cli({"watch", long_id, "--server", address});
  EXPECT_EQ(after_running.code, 1);
  EXPECT_THAT(after_running.out, HasSubstr(R"("status":"cancelled")"));  // stopped mid-run

  EXPECT_EQ(Cli({"submit", Scene("x", 0.1)}).code, 2);  // needs --server
}

TEST_F(CliServerTest, SweepWritesOneRowPerItemAndFailsOnAThreshold) {
  const std::string sweep = *dir_ + "/sweep.json";
  std::ofstream(sweep) << R"({"name": "steps", "base_file": "short.json",
    "axes": [{"path": "solver.step", "values": [1e-3, 5e-4]},
             {"path": "cables[0].elements", "values": [4, 6, 8]}]})";
  Scene("short", 0.05);
  const std::string csv = *dir_ + "/sweep.csv";
  // In-process (no --server), 2 workers.
  const CliResult ok = Cli({"sweep", sweep, "--out", csv, "--workers", "2"});
  ASSERT_EQ(ok.code, 0) << ok.err;
  const std::vector<std::string> rows = absl::StrSplit(Read(csv), '\n', absl::SkipEmpty());
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_THAT(rows[0], StartsWith("index,job_id,state,solver.step,cables[0].elements,status,"));
  EXPECT_THAT(rows[0], HasSubstr(",final.tip.x,"));
  EXPECT_THAT(rows[1], ::testing::MatchesRegex("0,j-[A-Za-z0-9_-]{22},SUCCEEDED,0.001,4,ok,.*"));
  EXPECT_THAT(rows[6], ::testing::MatchesRegex("5,j-[A-Za-z0-9_-]{22},SUCCEEDED,5e-04,8,ok,.*"));

  // Backward Euler dissipates a few percent here: a drift limit of 1e-9
  // is exceeded by every item; exit code 3, the table still written.
  const CliResult strict = Cli(
      {"sweep", sweep, "--out", csv, "--server", server_->address(), "--max-energy-drift", "1e-9"});
  EXPECT_EQ(strict.code, 3);
  EXPECT_THAT(strict.err, HasSubstr("energy drift"));
  EXPECT_EQ(std::vector<std::string>(absl::StrSplit(Read(csv), '\n', absl::SkipEmpty())).size(),
            7u);
  // An invalid axis is bad input.
  std::ofstream(sweep) << R"({"base_file": "short.json",
    "axes": [{"path": "cables[3].elements", "values": [4]}]})";
  const CliResult bad = Cli({"sweep", sweep, "--out", csv});
  EXPECT_EQ(bad.code, 2);
  EXPECT_THAT(bad.err, HasSubstr("axes[0].path: "));
}

std::vector<std::string> Lines(const std::string& text) {
  return absl::StrSplit(text, '\n', absl::SkipEmpty());
}

// A CSV row without the columns that differ between two runs of the same
// item: job_id (random) and wall_seconds.
std::string Comparable(const std::string& row, const std::vector<std::string>& header) {
  std::vector<std::string> cells = absl::StrSplit(row, ',');
  std::vector<std::string> kept;
  for (size_t k = 0; k < cells.size(); ++k) {
    if (header[k] != "job_id" && header[k] != "wall_seconds") kept.push_back(cells[k]);
  }
  return absl::StrJoin(kept, ",");
}

// `cablesim sweep SWEEP.json --item I`: one item of a sweep run alone (as
// one pod of deploy/kubernetes/sweep-indexed-job.yaml does) writes the same
// row as item I of the whole sweep.
TEST_F(CliServerTest, SweepItemAloneWritesTheRowOfTheWholeSweep) {
  const std::string& dir = *dir_;
  Scene("item_base", 0.05);
  const std::string sweep = dir + "/item_sweep.json";
  std::ofstream(sweep) << R"({"name": "items", "base_file": "item_base.json",
    "axes": [{"path": "solver.step", "values": [1e-3, 5e-4]},
             {"path": "cables[0].elements", "values": [4, 6, 8]}]})";

  const CliResult all = Cli({"sweep", sweep, "--workers", "2"});
  ASSERT_EQ(all.code, 0) << all.err;
  const std::vector<std::string> rows = Lines(all.out);
  ASSERT_EQ(rows.size(), 7u);
  const std::vector<std::string> header = absl::StrSplit(rows[0], ',');
  for (int i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    const std::string out = absl::StrCat(dir, "/item-", i, ".csv");
    const CliResult one =
        Cli({"sweep", sweep, "--item", std::to_string(i), "--out", out, "--workers", "1"});
    ASSERT_EQ(one.code, 0) << one.err;
    const std::vector<std::string> written = Lines(Read(out));
    ASSERT_EQ(written.size(), 2u);  // the header and item i's row
    EXPECT_EQ(written[0], rows[0]);
    EXPECT_EQ(Comparable(written[1], header), Comparable(rows[1 + i], header));
    EXPECT_THAT(written[1], StartsWith(absl::StrCat(i, ",j-")));
  }

  const CliResult outside = Cli({"sweep", sweep, "--item", "6"});
  EXPECT_EQ(outside.code, 2);
  EXPECT_THAT(outside.err, HasSubstr("--item: 6 is not an item of"));
  EXPECT_THAT(outside.err, HasSubstr("(6 items, 0 to 5)"));
  const CliResult negative = Cli({"sweep", sweep, "--item", "-1"});
  EXPECT_EQ(negative.code, 2);
  EXPECT_THAT(negative.err, HasSubstr("--item: a number >= 0"));
  EXPECT_EQ(Cli({"sweep", sweep, "--item", "x"}).code, 2);
  EXPECT_EQ(Cli({"run", sweep, "--item", "0"}).code, 2);  // only for sweep
}

}  // namespace
}  // namespace cablesim
