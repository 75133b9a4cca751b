// Durability and isolation of cablesim-server (slow: seconds of real runs):
// kill -9 during a sweep and a restart, a job accepted just before kill -9,
// SIGTERM leaving unfinished jobs queued, and a client that stops reading.
//
// The contract (README "Service"): every accepted job reaches a final state
// exactly once, with its result kept. A job finished before a kill -9 is
// kept and not run again; a job running at the kill is put back to QUEUED
// at the restart and runs again from its start (`attempts` counts both
// runs), and what it keeps is bit-identical to one uninterrupted run; a
// queued job runs once.
//
// Where a verdict depends on when a signal lands, the jobs wait at the
// server's test-only gate (testing::JobGate) until the test opens it, so
// which jobs have finished and which are running at the kill is chosen by
// the test, never by timing.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <map>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "convert/run_proto.h"
#include "convert/scene_from_proto.h"
#include "server_test_util.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::JobGate;
using testing::Pendulum;
using testing::ServerProcess;

std::vector<v1::Job> ListAll(v1::CablesimService::Stub* stub, const std::string& sweep = "") {
  grpc::ClientContext context;
  v1::ListJobsRequest request;
  request.set_sweep_id(sweep);
  request.set_limit(10000);
  v1::ListJobsResponse response;
  EXPECT_TRUE(stub->ListJobs(&context, request, &response).ok());
  return {response.jobs().begin(), response.jobs().end()};
}

// A finished job's kept trajectory: its rows, one after the other.
std::vector<double> ResultValues(v1::CablesimService::Stub* stub, const std::string& id,
                                 int64_t* rows) {
  grpc::ClientContext context;
  v1::GetJobResultRequest request;
  request.set_id(id);
  auto reader = stub->GetJobResult(&context, request);
  v1::RunEvent event;
  std::vector<double> values;
  *rows = 0;
  while (reader->Read(&event)) {
    if (!event.has_frames()) continue;
    *rows += event.frames().rows();
    values.insert(values.end(), event.frames().values().begin(), event.frames().values().end());
  }
  EXPECT_TRUE(reader->Finish().ok()) << id;
  return values;
}

// The rows the engine produces for `scene` in this process, in the service's
// column order (what a job that ran once, uninterrupted, keeps).
std::vector<double> ReferenceValues(const v1::Scene& scene) {
  testing::CollectingSink sink;
  testing::RunOk(*SceneFromProto(scene), &sink);
  google::protobuf::RepeatedField<double> values;
  for (const Frame& frame : sink.frames()) AppendFrameRow(frame, &values);
  return {values.begin(), values.end()};
}

TEST(ServerDurabilityTest, KillNineDuringASweepThenRestart) {
  const std::string dir = testing::FreshDir("kill9");
  const JobGate gate(dir);
  ServerProcess server(dir, {"--workers=2"}, {gate.env()});
  auto stub = server.Stub();
  // 8 items of the falling pendulum (0.3 s, 3000 steps), each stopping
  // after its first frame until the test opens its gate.
  v1::SubmitSweepRequest request;
  request.set_name("kill9");
  *request.mutable_base() = Pendulum(0.3, 1e-4, 1e-2);
  request.mutable_base()->set_name("gated-kill9");
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("cables[0].elements");
  for (int e : {4, 5, 6, 7, 8, 9, 10, 11}) axis->add_values(e);
  v1::Sweep sweep;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->SubmitSweep(&context, request, &sweep).ok());
  }
  ASSERT_EQ(sweep.items(), 8);
  const std::vector<std::string> ids(sweep.job_ids().begin(), sweep.job_ids().end());
  // Items 0 and 1 may finish; the two workers then take items 2 and 3
  // (oldest first), which stop mid-run at their gates; 4 to 7 stay queued.
  gate.Open(ids[0]);
  gate.Open(ids[1]);
  ASSERT_EQ(testing::WaitForJob(stub.get(), ids[0]), v1::SUCCEEDED);
  ASSERT_EQ(testing::WaitForJob(stub.get(), ids[1]), v1::SUCCEEDED);
  for (int i : {2, 3}) {
    ASSERT_TRUE(server.WaitForLog(absl::StrCat("job ", ids[i], " waits at the gate")));
  }
  std::map<std::string, v1::Job> before;
  for (const v1::Job& j : ListAll(stub.get(), sweep.id())) before[j.id()] = j;
  ASSERT_EQ(before.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    const v1::JobState expected = i < 2 ? v1::SUCCEEDED : i < 4 ? v1::RUNNING : v1::QUEUED;
    ASSERT_EQ(before[ids[i]].state(), expected) << "item " << i;
  }
  const int status = server.Kill(SIGKILL);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

  for (int i = 2; i < 8; ++i) gate.Open(ids[i]);
  server.Restart();
  stub = server.Stub();
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  v1::WatchSweepRequest watch;
  watch.set_id(sweep.id());
  auto reader = stub->WatchSweep(&context, watch);
  v1::SweepEvent event;
  while (reader->Read(&event)) {
  }
  ASSERT_TRUE(reader->Finish().ok());

  const std::vector<v1::Job> after = ListAll(stub.get(), sweep.id());
  ASSERT_EQ(after.size(), 8u);  // no job lost, none duplicated
  EXPECT_EQ(ListAll(stub.get()).size(), 8u);
  for (const v1::Job& j : after) {
    SCOPED_TRACE(j.id());
    EXPECT_EQ(j.state(), v1::SUCCEEDED);
    EXPECT_EQ(j.summary().status(), "ok");
    EXPECT_EQ(j.summary().frames(), 31);
    // The kept trajectory, bit-identical to one uninterrupted run of the
    // item, whether it ran once or was interrupted by the kill and run
    // again from its start.
    int64_t rows = 0;
    const std::vector<double> kept = ResultValues(stub.get(), j.id(), &rows);
    EXPECT_EQ(rows, 31);
    v1::Scene item = request.base();
    item.mutable_cables(0)->set_elements(4 + j.sweep_index());
    const std::vector<double> reference = ReferenceValues(item);
    ASSERT_EQ(kept.size(), reference.size());
    EXPECT_EQ(std::memcmp(kept.data(), reference.data(), kept.size() * sizeof(double)), 0)
        << "item " << j.sweep_index() << " differs from its uninterrupted run";
    const v1::Job& old = before.at(j.id());
    if (old.state() == v1::SUCCEEDED) {
      // Finished before the kill: kept, not run again.
      EXPECT_EQ(j.attempts(), 1);
      EXPECT_EQ(j.finished_unix_ms(), old.finished_unix_ms());
    } else if (old.state() == v1::RUNNING) {
      EXPECT_EQ(j.attempts(), 2);  // interrupted once, then run to the end once
    } else {
      EXPECT_EQ(j.attempts(), 1);
    }
  }
}

TEST(ServerDurabilityTest, AcceptedJobSurvivesKillNine) {
  const std::string dir = testing::FreshDir("accepted");
  const JobGate gate(dir);
  ServerProcess server(dir, {"--workers=1"}, {gate.env()});
  auto stub = server.Stub();
  // Both jobs wait at their gates: neither can finish before the kill.
  std::vector<std::string> ids;
  for (double duration : {0.2, 0.05}) {
    grpc::ClientContext context;
    v1::SubmitJobRequest submit;
    *submit.mutable_scene() = Pendulum(duration, 1e-4, 1e-2);
    submit.mutable_scene()->set_name("gated-accepted");
    v1::Job job;
    ASSERT_TRUE(stub->SubmitJob(&context, submit, &job).ok());
    ids.push_back(job.id());
  }
  server.Kill(SIGKILL);  // right after the ids came back
  for (const std::string& id : ids) gate.Open(id);
  server.Restart();
  stub = server.Stub();
  for (const std::string& id : ids) {
    v1::Job done;
    EXPECT_EQ(testing::WaitForJob(stub.get(), id, &done), v1::SUCCEEDED) << id;
    EXPECT_EQ(done.summary().status(), "ok");
  }
}

TEST(ServerDurabilityTest, SigtermLeavesUnfinishedJobsQueued) {
  const std::string dir = testing::FreshDir("sigterm");
  const JobGate gate(dir);
  ServerProcess server(dir, {"--workers=1"}, {gate.env()});
  auto stub = server.Stub();
  v1::Job job;
  {
    grpc::ClientContext context;
    v1::SubmitJobRequest submit;
    *submit.mutable_scene() = Pendulum(0.2, 1e-4, 1e-2);
    submit.mutable_scene()->set_name("gated-sigterm");
    ASSERT_TRUE(stub->SubmitJob(&context, submit, &job).ok());
  }
  // Running, stopped at its gate: it cannot finish before the signal.
  ASSERT_TRUE(server.WaitForLog(absl::StrCat("job ", job.id(), " waits at the gate")));
  // (An open client connection holds the server's shutdown up to its grace
  // period; this client goes away first.)
  stub.reset();
  const auto start = std::chrono::steady_clock::now();
  const int status = server.Kill(SIGTERM);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  // No hang: a guard far above the 2 s grace period, not a measure of speed.
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60));
  gate.Open(job.id());
  server.Restart();
  stub = server.Stub();
  v1::Job done;
  EXPECT_EQ(testing::WaitForJob(stub.get(), job.id(), &done), v1::SUCCEEDED);
  EXPECT_EQ(done.attempts(), 2);  // put back to QUEUED, then run again
}

long RssKiB(pid_t pid) {
  std::ifstream in(absl::StrCat("/proc/", pid, "/status"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmRSS:", 0) == 0) {
      long kib = 0;
      std::vector<std::string> parts = absl::StrSplit(line, ' ', absl::SkipEmpty());
      if (parts.size() >= 2 && absl::SimpleAtoi(parts[1], &kib)) return kib;
    }
  }
  return -1;
}

TEST(ServerDurabilityTest, AClientThatStopsReadingHurtsNoOne) {
  const std::string dir = testing::FreshDir("stall");
  ServerProcess server(dir, {"--stall-timeout-s=1"});
  // The stalled client keeps HTTP/2's default 64 KiB stream window (no BDP
  // probing, which would let it accept megabytes it never reads), so the
  // server feels the stall at once.
  grpc::ChannelArguments small_window;
  small_window.SetInt("grpc.http2.bdp_probe", 0);
  auto stub = v1::CablesimService::NewStub(server.Channel(small_window));
  // 150001 frames of 16 doubles (19 MB) if it were read to the end.
  grpc::ClientContext context;
  v1::RunRequest request;
  *request.mutable_scene() = Pendulum(15, 1e-4, 1e-4);
  auto stalled = stub->Run(&context, request);
  v1::RunEvent event;
  ASSERT_TRUE(stalled->Read(&event));
  ASSERT_TRUE(event.has_header());
  const long rss_start = RssKiB(server.pid());
  // While it reads nothing, another client is served in full.
  {
    auto other = server.Stub();  // its own connection
    grpc::ClientContext c;
    v1::RunRequest r;
    *r.mutable_scene() = Pendulum(0.05, 1e-3, 1e-3);
    auto reader = other->Run(&c, r);
    int64_t rows = 0;
    bool summary = false;
    while (reader->Read(&event)) {
      rows += event.has_frames() ? event.frames().rows() : 0;
      summary |= event.has_summary();
    }
    EXPECT_TRUE(reader->Finish().ok());
    EXPECT_EQ(rows, 51);
    EXPECT_TRUE(summary);
  }
  // Until the watchdog has cancelled the stalled stream (an event the
  // server reports, not a time the test guesses).
  ASSERT_TRUE(server.WaitForLog("cancelling a stream whose client has read nothing"));
  // The server did not buffer the stalled stream (flow control): its memory
  // grew by far less than the 19 MB of the whole trajectory.
  const long rss_end = RssKiB(server.pid());
  EXPECT_LT(rss_end - rss_start, 8 * 1024) << rss_start << " -> " << rss_end << " KiB";
  // Reading again: what was in flight, then CANCELLED by the watchdog.
  int64_t rows = 0;
  bool summary = false;
  while (stalled->Read(&event)) {
    rows += event.has_frames() ? event.frames().rows() : 0;
    summary |= event.has_summary();
  }
  EXPECT_EQ(stalled->Finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_FALSE(summary);
  EXPECT_LT(rows, 150001);
}

}  // namespace
}  // namespace cablesim
