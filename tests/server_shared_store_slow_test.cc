// Three cablesim-servers on one PostgreSQL database (a real PostgreSQL the
// test starts on loopback, tests/postgres_test_util.h): one queue.
//
// A 60-item sweep submitted to one server is run by all three (each
// server's share is printed); any server answers for any job. Then the
// same sweep again, and one server is killed with SIGKILL mid-sweep while
// it holds an item (the test-only job gate decides the moment): once
// its lease expires, the others take its item again, every item finishes
// exactly once (one "SUCCEEDED" line in all the servers' logs together),
// and every item's summary, last frame and energy report are identical to
// the uninterrupted sweep's (the engine is deterministic; only the wall
// time and the job ids differ).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <set>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "postgres_test_util.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using testing::Pendulum;
using testing::ServerProcess;

constexpr int kItems = 60;
constexpr int kServers = 3;

v1::SubmitSweepRequest SixtyItems() {
  v1::SubmitSweepRequest request;
  request.set_name("shared-store");
  // ~0.2 s of computing per item; "gated": each item waits after its
  // first frame until the test opens its gate (RunGated).
  *request.mutable_base() = Pendulum(0.2, 1e-4, 0.01);
  request.mutable_base()->set_name("gated-shared-store");
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("gravity.y");
  for (int i = 0; i < kItems; ++i) axis->add_values(-9.0 - 0.01 * i);
  return request;
}

std::string ReadLog(const ServerProcess& server) {
  std::ifstream in(server.log_path());
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// How many times `line` appears in `text`.
int Count(const std::string& text, const std::string& line) {
  int n = 0;
  for (size_t at = text.find(line); at != std::string::npos; at = text.find(line, at + 1)) ++n;
  return n;
}

// Polls `stub` until every item of `sweep` has finished (or 180 s).
std::vector<v1::Job> WaitForSweep(v1::CablesimService::Stub* stub, const std::string& sweep) {
  const absl::Time give_up = absl::Now() + absl::Seconds(180);
  while (absl::Now() < give_up) {
    grpc::ClientContext context;
    v1::ListJobsRequest request;
    request.set_sweep_id(sweep);
    request.set_page_size(kItems);
    v1::ListJobsResponse response;
    const grpc::Status s = stub->ListJobs(&context, request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    int finished = 0;
    for (const v1::Job& job : response.jobs()) {
      finished += job.state() == v1::SUCCEEDED || job.state() == v1::FAILED ||
                  job.state() == v1::CANCELLED;
    }
    if (finished == kItems) return {response.jobs().begin(), response.jobs().end()};
    absl::SleepFor(absl::Milliseconds(100));
  }
  ADD_FAILURE() << "sweep " << sweep << " did not finish";
  return {};
}

int FinishedCount(v1::CablesimService::Stub* stub, const std::string& sweep) {
  grpc::ClientContext context;
  v1::ListJobsRequest request;
  request.set_sweep_id(sweep);
  request.set_page_size(kItems);
  v1::ListJobsResponse response;
  if (!stub->ListJobs(&context, request, &response).ok()) return -1;
  int n = 0;
  for (const v1::Job& job : response.jobs()) n += job.state() == v1::SUCCEEDED;
  return n;
}

v1::SweepResults Results(v1::CablesimService::Stub* stub, const std::string& sweep) {
  grpc::ClientContext context;
  v1::GetSweepResultsRequest request;
  request.set_id(sweep);
  v1::SweepResults results;
  const grpc::Status s = stub->GetSweepResults(&context, request, &results);
  EXPECT_TRUE(s.ok()) << s.error_message();
  return results;
}

// An item as the run made it: without its job id and wall time.
std::string Comparable(v1::SweepItem item) {
  item.clear_job_id();
  item.mutable_summary()->clear_wall_seconds();
  return item.SerializeAsString();
}

// Each server's share of `jobs`: the "job ID SUCCEEDED" lines of its log.
std::vector<int> Shares(const std::vector<std::unique_ptr<ServerProcess>>& servers,
                        const std::vector<v1::Job>& jobs, std::map<std::string, int>* per_job) {
  std::vector<int> shares;
  for (const auto& server : servers) {
    const std::string log = ReadLog(*server);
    int share = 0;
    for (const v1::Job& job : jobs) {
      const int n = Count(log, absl::StrCat("job ", job.id(), " SUCCEEDED"));
      share += n;
      (*per_job)[job.id()] += n;
    }
    shares.push_back(share);
  }
  return shares;
}

// Runs sweep `sweep` to its end, opening the gate of every item as soon as
// a server waits at it. With `victim` >= 0: the first item server
// `victim` waits on once a third of the items have finished stays closed,
// server `victim` is killed with SIGKILL while it holds that item (its
// one worker blocked there, so it can have finished nothing else
// unlogged), then the gate opens for the server that takes the item
// again; returns that item's id.
std::string RunGated(const std::vector<std::unique_ptr<ServerProcess>>& servers,
                     const testing::JobGate& gate, v1::CablesimService::Stub* stub,
                     const std::string& sweep, int victim) {
  std::set<std::string> opened;
  std::string caught;
  const std::string prefix = "TEST ONLY: job ", suffix = " waits at the gate";
  const absl::Time give_up = absl::Now() + absl::Seconds(180);
  while (absl::Now() < give_up) {
    for (int i = 0; i < static_cast<int>(servers.size()); ++i) {
      const std::string log = ReadLog(*servers[i]);
      for (size_t at = log.find(prefix); at != std::string::npos; at = log.find(prefix, at + 1)) {
        const size_t start = at + prefix.size(), end = log.find(suffix, start);
        if (end == std::string::npos) break;
        const std::string id = log.substr(start, end - start);
        if (!opened.insert(id).second) continue;
        if (caught.empty() && i == victim && FinishedCount(stub, sweep) >= kItems / 3) {
          caught = id;
          servers[i]->Kill(SIGKILL);
        }
        gate.Open(id);
      }
    }
    if (FinishedCount(stub, sweep) == kItems) break;
    absl::SleepFor(absl::Milliseconds(10));
  }
  return caught;
}

TEST(ServerSharedStoreTest, ThreeServersShareOneQueueAndSurviveKillNine) {
  CABLESIM_POSTGRES_URL_OR_SKIP(url, "shared");
  const testing::JobGate gate(testing::FreshDir("shared_gate"));
  std::vector<std::unique_ptr<ServerProcess>> servers;
  for (int i = 0; i < kServers; ++i) {
    servers.push_back(std::make_unique<ServerProcess>(
        testing::FreshDir(absl::StrCat("shared_", i)),
        std::vector<std::string>{"--store=" + url, "--workers=1", "--lease-s=2"},
        std::vector<std::string>{gate.env()}));
    ASSERT_GT(servers.back()->port(), 0);
  }
  std::vector<std::unique_ptr<v1::CablesimService::Stub>> stubs;
  for (const auto& s : servers) stubs.push_back(s->Stub());

  // 1. Uninterrupted: submitted to server 0, run by all three.
  v1::Sweep first;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stubs[0]->SubmitSweep(&context, SixtyItems(), &first).ok());
  }
  EXPECT_TRUE(RunGated(servers, gate, stubs[1].get(), first.id(), -1).empty());
  // Answered by server 2, which did not take the submission.
  const std::vector<v1::Job> first_jobs = WaitForSweep(stubs[2].get(), first.id());
  ASSERT_EQ(first_jobs.size(), static_cast<size_t>(kItems));
  std::map<std::string, int> runs;
  const std::vector<int> shares = Shares(servers, first_jobs, &runs);
  std::cout << "uninterrupted 60-item sweep, items per server:";
  for (int i = 0; i < kServers; ++i) std::cout << " server " << i << ": " << shares[i];
  std::cout << std::endl;
  for (int i = 0; i < kServers; ++i) EXPECT_GT(shares[i], 0) << "server " << i << " ran nothing";
  for (const v1::Job& job : first_jobs) {
    EXPECT_EQ(job.state(), v1::SUCCEEDED);
    EXPECT_EQ(runs[job.id()], 1) << job.id();
    EXPECT_EQ(job.attempts(), 1);
  }
  // Any server answers for any job: its state and result.
  for (int i = 0; i < kServers; ++i) {
    const testing::JobResultRead read = testing::ReadJobResult(stubs[i].get(), first_jobs[i].id());
    EXPECT_TRUE(read.status.ok()) << read.status.error_message();
    EXPECT_EQ(read.rows, 21);  // 0.2 s every 0.01 s
  }
  const v1::SweepResults expected = Results(stubs[1].get(), first.id());
  ASSERT_EQ(expected.items_size(), kItems);

  // 2. The same sweep; server 1 is killed with SIGKILL a third of the way.
  v1::Sweep second;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stubs[2]->SubmitSweep(&context, SixtyItems(), &second).ok());
  }
  const std::string victim = RunGated(servers, gate, stubs[0].get(), second.id(), 1);
  ASSERT_FALSE(victim.empty()) << "server 1 was never caught holding an item";
  const std::vector<v1::Job> second_jobs = WaitForSweep(stubs[0].get(), second.id());
  ASSERT_EQ(second_jobs.size(), static_cast<size_t>(kItems));
  std::map<std::string, int> second_runs;
  const std::vector<int> second_shares = Shares(servers, second_jobs, &second_runs);
  int retaken = 0;
  for (const v1::Job& job : second_jobs) {
    EXPECT_EQ(job.state(), v1::SUCCEEDED);
    EXPECT_EQ(second_runs[job.id()], 1) << job.id() << " finished other than once";
    retaken += job.attempts() > 1;
    // The item server 1 held when it died ran again, as attempt 2.
    if (job.id() == victim) {
      EXPECT_EQ(job.attempts(), 2);
    }
  }
  std::cout << "60-item sweep with server 1 killed (SIGKILL) holding an item after at least "
            << kItems / 3
            << " items, items per server:";
  for (int i = 0; i < kServers; ++i) std::cout << " server " << i << ": " << second_shares[i];
  std::cout << "; items taken again after the lease expired: " << retaken << std::endl;
  EXPECT_EQ(retaken, 1);
  EXPECT_GT(second_shares[0], 0);
  EXPECT_GT(second_shares[2], 0);

  // 3. The same results as the uninterrupted sweep, item by item.
  const v1::SweepResults got = Results(stubs[2].get(), second.id());
  ASSERT_EQ(got.items_size(), kItems);
  EXPECT_EQ(got.final_columns_size(), expected.final_columns_size());
  for (int i = 0; i < kItems; ++i) {
    EXPECT_EQ(Comparable(got.items(i)), Comparable(expected.items(i))) << "item " << i;
  }
  EXPECT_EQ(got.sweep().finished(), kItems);
  EXPECT_EQ(got.sweep().failed(), 0);
}

// A job running on one server, cancelled through another: the cancel is
// recorded in the database and reaches the job at its server's next
// heartbeat; the watcher on the other server sees it CANCELLED.
TEST(ServerSharedStoreTest, ACancelThroughAnotherServerStopsTheJob) {
  CABLESIM_POSTGRES_URL_OR_SKIP(url, "cancel");
  const std::string gate_root = testing::FreshDir("shared_cancel_gate");
  const testing::JobGate gate(gate_root);  // never opened: the job waits
  std::vector<std::unique_ptr<ServerProcess>> servers;
  for (int i = 0; i < 2; ++i) {
    servers.push_back(std::make_unique<ServerProcess>(
        testing::FreshDir(absl::StrCat("shared_cancel_", i)),
        std::vector<std::string>{"--store=" + url, "--workers=1", "--lease-s=2"},
        std::vector<std::string>{gate.env()}));
    ASSERT_GT(servers.back()->port(), 0);
  }
  v1::SubmitJobRequest request;
  *request.mutable_scene() = Pendulum(5, 1e-4, 0.01);
  request.mutable_scene()->set_name("gated-cancel");
  v1::Job job;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(servers[0]->Stub()->SubmitJob(&context, request, &job).ok());
  }
  // Which server runs it: the one whose log says it waits at the gate.
  const std::string waits = absl::StrCat("job ", job.id(), " waits at the gate");
  int runner = -1;
  for (int tries = 0; tries < 2000 && runner < 0; ++tries) {
    for (int i = 0; i < 2; ++i) {
      if (ReadLog(*servers[i]).find(waits) != std::string::npos) runner = i;
    }
    absl::SleepFor(absl::Milliseconds(10));
  }
  ASSERT_GE(runner, 0) << "no server took the job";
  const int other = 1 - runner;
  auto stub = servers[other]->Stub();
  const absl::Time asked = absl::Now();
  {
    grpc::ClientContext context;
    v1::CancelJobRequest cancel;
    cancel.set_id(job.id());
    v1::Job answer;
    ASSERT_TRUE(stub->CancelJob(&context, cancel, &answer).ok());
  }
  v1::Job last;
  EXPECT_EQ(testing::WaitForJob(stub.get(), job.id(), &last), v1::CANCELLED);
  const double seconds = absl::ToDoubleSeconds(absl::Now() - asked);
  std::cout << "job running on server " << runner << ", cancelled through server " << other
            << ": CANCELLED after " << seconds << " s" << std::endl;
  // The heartbeat comes every min(lease / 4, 1 s) = 0.5 s; 10 s is far
  // from both it and the job's own 5 s of simulated time.
  EXPECT_LT(seconds, 10.0);
  EXPECT_EQ(last.attempts(), 1);
}

}  // namespace
}  // namespace cablesim
