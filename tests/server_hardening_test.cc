// Hardening against the independent review of issue 30, on a real
// cablesim-server: quiet, honest logs while the database is down, and
// the other reproducers of that review rebuilt as tests.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <sqlite3.h>

#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "both_stores_test_util.h"
#include "postgres_test_util.h"
#include "convert/scene_file.h"
#include "server/request_checks.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::ServerProcess;

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

int CountLines(const std::string& text, const std::string& needle) {
  int n = 0;
  for (absl::string_view line : absl::StrSplit(text, '\n')) n += absl::StrContains(line, needle);
  return n;
}

// The review: while PostgreSQL was down the servers logged "no result (out
// of memory?)" 64 times in 6 s. Here the server's database is dropped
// under it (as good as down: every reconnect fails) for 6 s with 4
// workers polling twice a second each (~48 failed claims): the log says
// the store is unreachable, once (a repeat at most every 10 s), never
// "out of memory".
TEST(ServerHardeningTest, DatabaseDownIsLoggedAsSuchAndRateLimited) {
  CABLESIM_POSTGRES_URL_OR_SKIP(url, "db_down");
  ASSERT_FALSE(url.empty());
  const std::string dir = testing::FreshDir("db_down");
  ServerProcess server(dir, {"--store=" + url, "--workers=4"});
  const std::string name = url.substr(url.rfind('/') + 1);
  const std::string admin = url.substr(0, url.rfind('/') + 1) + "postgres";
  PGconn* conn = PQconnectdb(admin.c_str());
  ASSERT_EQ(PQstatus(conn), CONNECTION_OK) << PQerrorMessage(conn);
  PGresult* r =
      PQexec(conn, absl::StrCat("DROP DATABASE \"", name, "\" WITH (FORCE)").c_str());
  EXPECT_EQ(PQresultStatus(r), PGRES_COMMAND_OK) << PQerrorMessage(conn);
  PQclear(r);
  PQfinish(conn);
  ASSERT_TRUE(server.WaitForLog("the job store is unreachable"));
  std::this_thread::sleep_for(std::chrono::seconds(6));
  const std::string log = ReadText(server.log_path());
  EXPECT_THAT(log, Not(HasSubstr("out of memory")));
  EXPECT_LE(CountLines(log, "the job store is unreachable"), 2) << log;
  EXPECT_EQ(CountLines(log, "claiming a job"), 0) << log;
}

// The limits `cablesim` applies in-process (DefaultServerLimits) are the
// server's flags' defaults: its --help lists the same numbers.
TEST(ServerHardeningTest, TheServersFlagDefaultsAreDefaultServerLimits) {
  const std::string dir = testing::FreshDir("help_defaults");
  ASSERT_EQ(std::system(absl::StrCat("'", CABLESIM_BIN_DIR, "/cablesim-server' --help >'", dir,
                                     "/help'")
                            .c_str()),
            0);
  const std::string help = ReadText(dir + "/help");
  const ServerLimits l = DefaultServerLimits();
  const std::vector<std::pair<std::string, int64_t>> flags = {
      {"max-elements", l.max_elements},
      {"max-steps", l.max_steps},
      {"max-frames", l.max_frames},
      {"max-trajectory-values", l.max_trajectory_values},
      {"max-sweep-items", l.max_sweep_items},
      {"max-streams", l.max_streams},
      {"max-streams-per-peer", l.max_streams_per_peer},
      {"max-queued-jobs-per-peer", l.max_queued_jobs_per_peer},
      {"max-modes", l.max_modes},
      {"max-modal-bytes", l.max_modal_bytes},
      {"max-name-bytes", l.max_name_bytes},
      {"max-coordinates", l.max_coordinates},
      {"max-message-bytes", l.max_message_bytes},
      {"stall-timeout-s", static_cast<int64_t>(absl::ToDoubleSeconds(l.stall_timeout))},
      {"max-unary-calls", l.max_unary_calls},
      {"max-unary-calls-per-peer", l.max_unary_calls_per_peer},
      {"max-inflight-bytes", l.max_inflight_bytes},
      {"max-work-units", l.max_work_units}};
  for (const auto& [name, value] : flags) {
    const size_t at = help.find("--" + name + "  ");
    ASSERT_NE(at, std::string::npos) << name;
    const std::string line = help.substr(at, help.find('\n', at) - at);
    EXPECT_THAT(line, HasSubstr(absl::StrCat("(default: ", value, ")"))) << line;
  }
}

using FairQueueTest = testing::BothStoresTest;

v1::Job GetJob(v1::CablesimService::Stub* stub, const std::string& token, const std::string& id) {
  grpc::ClientContext context;
  context.AddMetadata("authorization", "Bearer " + token);
  v1::GetJobRequest request;
  request.set_id(id);
  v1::Job job;
  EXPECT_TRUE(stub->GetJob(&context, request, &job).ok());
  return job;
}

// The review: after one tenant queued 60 one-second jobs, another's 2 ms
// job waited 27 s (first in, first out across tenants). Here, one worker:
// alice's first job holds it (at the test gate) while she queues 60 more
// and bob queues one; when the worker is free, bob's job is the next to
// start, not alice's second (round-robin across tenants).
TEST_P(FairQueueTest, AnotherTenantsJobStartsNextNotAfterTheQueue) {
  std::vector<std::string> flags = StoreFlags("fair_queue");
  if (skipped_) GTEST_SKIP() << "PostgreSQL is not installed";
  const std::string dir = testing::FreshDir("fair_queue_" + GetParam());
  testing::JobGate gate(dir);
  const std::string alice = "tok-alice-0123456789", bob = "tok-bob-0123456789ab";
  testing::WritePrivateFile(dir + "/tokens", absl::StrCat(alice, " alice\n", bob, " bob\n"));
  flags.push_back("--workers=1");
  flags.push_back("--token-file=" + dir + "/tokens");
  ServerProcess server(dir, flags, {gate.env()});
  auto stub = server.Stub();
  auto submit = [&](const std::string& token, const std::string& name) {
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer " + token);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = testing::Pendulum(0.02, 1e-3, 1e-2);
    request.mutable_scene()->set_name(name);
    v1::Job job;
    EXPECT_TRUE(stub->SubmitJob(&context, request, &job).ok());
    return job.id();
  };
  std::vector<std::string> alices = {submit(alice, "gated alice 0")};
  ASSERT_TRUE(server.WaitForLog("waits at the gate"));
  for (int i = 1; i <= 60; ++i) alices.push_back(submit(alice, absl::StrCat("gated alice ", i)));
  const std::string bobs = submit(bob, "gated bob");
  gate.Open(alices[0]);
  // The next job to start: bob's, while alice's second still waits.
  v1::JobState bob_state = v1::QUEUED;
  for (int i = 0; i < 3000 && bob_state == v1::QUEUED; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    bob_state = GetJob(stub.get(), bob, bobs).state();
  }
  EXPECT_EQ(bob_state, v1::RUNNING);
  EXPECT_EQ(GetJob(stub.get(), alice, alices[1]).state(), v1::QUEUED);
  gate.Open(bobs);
  for (const std::string& id : alices) gate.Open(id);
}

INSTANTIATE_TEST_SUITE_P(BothStores, FairQueueTest, ::testing::Values("sqlite", "postgresql"),
                         [](const auto& info) { return info.param; });

// A damaged job row through the service: GetJob answers DATA_LOSS for
// that job alone, ListJobs serves the others and counts it, and
// `cablesim-server --check DIR` lists it (exit 1; 0 on a sound store).
TEST(ServerHardeningTest, ADamagedJobRowIsDataLossAndSkippedByListJobs) {
  const std::string dir = testing::FreshDir("damaged_row");
  std::vector<std::string> ids;
  {
    ServerProcess server(dir, {"--workers=1"});
    auto stub = server.Stub();
    for (int i = 0; i < 3; ++i) ids.push_back(testing::Submit(stub.get(), testing::Pendulum(0.01, 1e-3, 1e-2)).id());
    for (const std::string& id : ids) EXPECT_EQ(testing::WaitForJob(stub.get(), id), v1::SUCCEEDED);
    server.Kill(SIGTERM);
  }
  const std::string check = absl::StrCat("'", CABLESIM_BIN_DIR, "/cablesim-server' --check '", dir,
                                         "' >'", dir, "/check.txt' 2>&1");
  int status = std::system(check.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << ReadText(dir + "/check.txt");
  EXPECT_THAT(ReadText(dir + "/check.txt"), HasSubstr(": 0 damaged rows"));
  // The summary of the middle job altered behind the store's back (as a
  // flipped bit would): its checksum no longer matches.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir + "/cablesim.db").c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db,
                         absl::StrCat("UPDATE jobs SET row_sum = row_sum + 1 WHERE pid = '",
                                      ids[1], "'")
                             .c_str(),
                         nullptr, nullptr, &error),
            SQLITE_OK)
      << error;
  sqlite3_close(db);
  status = std::system(check.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_THAT(ReadText(dir + "/check.txt"), HasSubstr("damaged: job " + ids[1]));
  EXPECT_THAT(ReadText(dir + "/check.txt"), HasSubstr(": 1 damaged rows"));

  ServerProcess server(dir, {"--workers=1"});
  auto stub = server.Stub();
  {
    grpc::ClientContext context;
    v1::GetJobRequest request;
    request.set_id(ids[1]);
    v1::Job job;
    const grpc::Status s = stub->GetJob(&context, request, &job);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::DATA_LOSS);
    EXPECT_THAT(s.error_message(), HasSubstr("fails its checksum"));
  }
  {
    grpc::ClientContext context;
    v1::GetJobRequest request;
    request.set_id(ids[0]);
    v1::Job job;
    EXPECT_TRUE(stub->GetJob(&context, request, &job).ok());
  }
  grpc::ClientContext context;
  v1::ListJobsRequest request;
  v1::ListJobsResponse response;
  ASSERT_TRUE(stub->ListJobs(&context, request, &response).ok());
  EXPECT_EQ(response.jobs_size(), 2);
  EXPECT_EQ(response.damaged_skipped(), 1);
}

// The server's peak resident memory (VmHWM) [bytes].
int64_t PeakRss(pid_t pid) {
  std::ifstream in(absl::StrCat("/proc/", pid, "/status"));
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::atoll(line.c_str() + 6) * 1024;
  }
  return -1;
}

// A valid scene of `points` polyline points (about 31 bytes each in a
// request).
v1::Scene BigScene(int points) {
  v1::Scene scene = testing::Pendulum(0.01, 1e-3, 1e-2);
  v1::Cable* cable = scene.mutable_cables(0);
  cable->clear_length();
  cable->clear_start();
  cable->clear_direction();
  for (int i = 0; i < points; ++i) {
    v1::Vec3* p = cable->add_points();
    p->set_x(1.2 * i / (points - 1));
    p->set_y(1e-7 * (i % 2));
  }
  return scene;
}

// The review: 32 concurrent Validate calls, each holding a 7.8 MB valid
// scene, took the server to 4.56 GB. Scaled: 24 concurrent calls of a
// 3.1 MB scene under a memory budget of 128 MB: the calls beyond it are
// refused at once naming the budget, those within it succeed, and the
// server's peak RSS stays under 450 MB (measured: 262 MB; without the
// budget all 24 are held at once and the peak is 757 MB).
TEST(ServerHardeningTest, ConcurrentValidateCallsStayWithinTheMemoryBudget) {
  const std::string dir = testing::FreshDir("memory_budget");
  ServerProcess server(dir, {"--max-inflight-bytes=134217728", "--max-unary-calls-per-peer=64"});
  const v1::Scene scene = BigScene(200000);
  v1::ValidateRequest request;
  *request.mutable_scene() = scene;
  std::cerr << "[ budget ] request of " << request.ByteSizeLong() << " bytes\n";
  const int64_t before = PeakRss(server.pid());
  std::vector<std::thread> threads;
  std::vector<grpc::Status> statuses(24);
  std::vector<bool> valid(24, false);
  for (int i = 0; i < 24; ++i) {
    threads.emplace_back([&, i] {
      auto stub = v1::CablesimService::NewStub(server.Channel());
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
      v1::ValidateResponse response;
      statuses[i] = stub->Validate(&context, request, &response);
      valid[i] = response.valid();
    });
  }
  for (std::thread& t : threads) t.join();
  const int64_t peak = PeakRss(server.pid());
  int ok = 0, refused = 0;
  for (int i = 0; i < 24; ++i) {
    if (statuses[i].ok()) {
      ++ok;
      EXPECT_TRUE(valid[i]);
    } else {
      ++refused;
      EXPECT_EQ(statuses[i].error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
      EXPECT_THAT(statuses[i].error_message(), HasSubstr("max_inflight_bytes"));
    }
  }
  std::cerr << "[ budget ] " << ok << " validated, " << refused << " refused; peak RSS "
            << before / (1 << 20) << " MB before, " << peak / (1 << 20) << " MB after\n";
  EXPECT_GT(ok, 0);
  EXPECT_GT(refused, 0);
#if defined(__SANITIZE_ADDRESS__)
  // Under AddressSanitizer the server's RSS is not the program's: freed
  // memory waits in ASan's quarantine (256 MB by default) and every block
  // carries redzones (2 validated scenes peaked at 909 MB there). The
  // refusals above are still checked; the bound is the Release build's.
  (void)peak;
#else
  EXPECT_LT(peak, int64_t{450} << 20);
#endif
}

// Concurrent scene checks per client are bounded too: beyond
// max_unary_calls_per_peer a call is refused naming that limit.
TEST(ServerHardeningTest, ConcurrentUnaryCallsPerClientAreBounded) {
  const std::string dir = testing::FreshDir("unary_per_peer");
  ServerProcess server(dir, {"--max-unary-calls-per-peer=2"});
  v1::ValidateRequest request;
  *request.mutable_scene() = BigScene(40000);
  std::vector<std::thread> threads;
  std::vector<grpc::Status> statuses(12);
  for (int i = 0; i < 12; ++i) {
    threads.emplace_back([&, i] {
      auto stub = v1::CablesimService::NewStub(server.Channel());
      grpc::ClientContext context;
      v1::ValidateResponse response;
      statuses[i] = stub->Validate(&context, request, &response);
    });
  }
  for (std::thread& t : threads) t.join();
  int refused = 0;
  for (const grpc::Status& s : statuses) {
    if (s.ok()) continue;
    ++refused;
    EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_THAT(s.error_message(), HasSubstr("max_unary_calls_per_peer"));
  }
  EXPECT_GT(refused, 0);
}

// The review's scene, scaled: a mooring line in `seas` JONSWAP sea states
// of 1,000 components each, within every limit, whose one step sums
// seas x 1,000 components at every Gauss point of every element in every
// Newton iteration (seconds per step).
v1::Scene WaveScene(int seas, double duration_s, double step_s) {
  absl::StatusOr<v1::Scene> scene = ParseSceneJson(absl::StrCat(R"({
    "name": "heavy-seas",
    "gravity": {"y": -9.81},
    "fluid": {"density": 1025, "still_water_level": 50, "water_depth": 100},
    "cables": [{"name": "line", "length": 40, "elements": 40,
                "start": {"x": 0, "y": 0}, "direction": {"x": 1},
                "density": 7800, "youngs_modulus": 2e11, "diameter": 0.05,
                "hydrodynamics": {"normal_drag": 1.2, "added_mass": 1}}],
    "joints": [{"type": "PIN", "a": {"cable": "line", "s": 0}}],
    "probes": [{"name": "end", "cable": "line", "s": 40}],
    "solver": {"duration": )", duration_s, R"(, "step": )", step_s, R"(}})"));
  EXPECT_TRUE(scene.ok()) << scene.status();
  for (int i = 0; i < seas; ++i) {
    v1::Waves::Jonswap* sea = scene->mutable_fluid()->mutable_waves()->add_jonswap();
    sea->set_significant_height(1 + 0.01 * i);
    sea->set_peak_period(8);
    sea->set_components(1000);
    sea->set_seed(i + 1);
  }
  return *scene;
}

// CPU seconds the process has used (user + system).
double CpuSeconds(pid_t pid) {
  std::ifstream in(absl::StrCat("/proc/", pid, "/stat"));
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::vector<std::string> fields =
      absl::StrSplit(stat.substr(stat.rfind(')') + 2), ' ');
  return (std::stod(fields[11]) + std::stod(fields[12])) / sysconf(_SC_CLK_TCK);
}

// The review: after a client's deadline the server computed on for 67 s
// (100 sea states), since cancellation was asked only between steps.
// Here a Run of 100 sea states with a 2 s deadline: within 1 s after the
// deadline the server's CPU is idle (less than 0.15 s of CPU over the
// following second), though one step takes far longer.
TEST(ServerHardeningTest, ADeadlineStopsAStepOfManyWaveComponentsWithinASecond) {
  const std::string dir = testing::FreshDir("cancel_in_step");
  ServerProcess server(dir, {"--workers=1"});
  auto stub = server.Stub();
  v1::RunRequest request;
  *request.mutable_scene() = WaveScene(100, 0.1, 0.01);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(2));
  auto reader = stub->Run(&context, request);
  v1::RunEvent event;
  while (reader->Read(&event)) {
  }
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double cpu0 = CpuSeconds(server.pid());
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double cpu1 = CpuSeconds(server.pid());
  std::cerr << "[ cancel ] CPU from 1 s to 2 s after the deadline: " << cpu1 - cpu0 << " s\n";
  EXPECT_LT(cpu1 - cpu0, 0.15);
}

// SIGTERM while a job is inside such a step: the server stops within its
// 2 s grace (the review: it hung past 30 s), and the job stays queued.
TEST(ServerHardeningTest, SigtermEndsAStepOfManyWaveComponentsWithinTheGrace) {
  const std::string dir = testing::FreshDir("sigterm_in_step");
  ServerProcess server(dir, {"--workers=1", "--shutdown-grace-s=2"});
  auto stub = server.Stub();
  const v1::Job job = testing::Submit(stub.get(), WaveScene(100, 0.1, 0.01));
  EXPECT_EQ(testing::WaitForState(stub.get(), job.id(), v1::RUNNING).state(), v1::RUNNING);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto start = std::chrono::steady_clock::now();
  const int status = server.Kill(SIGTERM);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "[ sigterm ] exited " << seconds << " s after SIGTERM\n";
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_LT(seconds, 3.0);
  server.Restart();
  auto again = server.Stub();
  grpc::ClientContext context;
  v1::GetJobRequest get;
  get.set_id(job.id());
  v1::Job after;
  ASSERT_TRUE(again->GetJob(&context, get, &after).ok());
  EXPECT_NE(after.state(), v1::FAILED);
  {
    grpc::ClientContext cancel_context;
    v1::CancelJobRequest cancel;
    cancel.set_id(job.id());
    v1::Job cancelled;
    (void)again->CancelJob(&cancel_context, cancel, &cancelled);
  }
}

// The costing counts wave components: the same scene over 10,000 steps
// (3.2e11 units: 40 elements x 8 Gauss points x 100,001) is refused at
// once, naming max_work_units; with one sea state (3.2e9) it is not.
TEST(ServerHardeningTest, TheCostingCountsWaveComponents) {
  const std::string dir = testing::FreshDir("work_units");
  ServerProcess server(dir);
  auto stub = server.Stub();
  for (const auto& [seas, refused] : {std::pair{100, true}, std::pair{1, false}}) {
    grpc::ClientContext context;
    v1::ValidateRequest request;
    *request.mutable_scene() = WaveScene(seas, 100, 0.01);
    v1::ValidateResponse response;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(stub->Validate(&context, request, &response).ok());
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    EXPECT_EQ(response.valid(), !refused) << seas;
    if (refused) {
      ASSERT_EQ(response.errors_size(), 1);
      EXPECT_THAT(response.errors(0).message(), HasSubstr("max_work_units"));
    }
  }
}

// The review: 64 streams that stop reading locked every client out of Run
// for the 30 s stall timeout (with tokens 4 tenants sufficed). Here, with
// --max-streams=4: two tenants hold 2 streams each and read nothing past
// the header; a third tenant's Run is served at once (not refused, not
// kept waiting) while they stall, and each stalling tenant is still held
// to its own max_streams_per_peer.
TEST(ServerHardeningTest, StreamsThatStopReadingDoNotLockOthersOutOfRun) {
  const std::string dir = testing::FreshDir("stalled_streams");
  const std::vector<std::string> tokens = {"tok-tenant-a-0123456", "tok-tenant-b-0123456",
                                           "tok-tenant-c-0123456"};
  testing::WritePrivateFile(dir + "/tokens", absl::StrCat(tokens[0], " a\n", tokens[1], " b\n",
                                                          tokens[2], " c\n"));
  ServerProcess server(dir, {"--token-file=" + dir + "/tokens", "--max-streams=4",
                             "--max-streams-per-peer=2", "--stall-timeout-s=60"});
  grpc::ChannelArguments small_window;
  small_window.SetInt("grpc.http2.bdp_probe", 0);
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientReader<v1::RunEvent>>> readers;
  std::vector<std::unique_ptr<v1::CablesimService::Stub>> stubs;
  v1::RunRequest request;
  *request.mutable_scene() = testing::Pendulum(15, 1e-3, 1e-3);
  for (int t = 0; t < 2; ++t) {
    for (int k = 0; k < 2; ++k) {
      stubs.push_back(v1::CablesimService::NewStub(server.Channel(small_window)));
      contexts.push_back(std::make_unique<grpc::ClientContext>());
      contexts.back()->AddMetadata("authorization", "Bearer " + tokens[t]);
      readers.push_back(stubs.back()->Run(contexts.back().get(), request));
      v1::RunEvent event;
      ASSERT_TRUE(readers.back()->Read(&event));
      ASSERT_TRUE(event.has_header());
    }
  }
  auto run = [&](const std::string& token) {
    auto stub = server.Stub();
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer " + token);
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(20));
    v1::RunRequest small;
    *small.mutable_scene() = testing::Pendulum(0.01, 1e-3, 1e-3);
    auto reader = stub->Run(&context, small);
    v1::RunEvent event;
    bool summary = false;
    while (reader->Read(&event)) summary |= event.has_summary();
    const grpc::Status status = reader->Finish();
    return std::pair{status, summary};
  };
  // The four stall once their writes have waited 1 s on their clients;
  // how soon they fill the flow-control window depends on the machine
  // (a sanitizer build on a busy CI machine took more than 2.5 s), so the
  // third tenant tries every 200 ms. Without the stall rule it would be
  // refused until the 60 s stall timeout cut the four: 20 s bounds it.
  const auto first_try = std::chrono::steady_clock::now();
  grpc::Status status;
  bool summary = false;
  std::chrono::steady_clock::duration served_in{};
  while (true) {
    const auto start = std::chrono::steady_clock::now();
    std::tie(status, summary) = run(tokens[2]);
    served_in = std::chrono::steady_clock::now() - start;
    if (status.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED ||
        std::chrono::steady_clock::now() - first_try > std::chrono::seconds(20)) {
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(summary);
  // Once admitted it is not kept waiting behind the stalled four.
  EXPECT_LT(served_in, std::chrono::seconds(5));
  // A stalling tenant is held to its own share.
  const auto [mine, unused] = run(tokens[0]);
  EXPECT_EQ(mine.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(mine.error_message(), HasSubstr("max_streams_per_peer"));
  for (auto& context : contexts) context->TryCancel();
  for (auto& reader : readers) {
    v1::RunEvent event;
    while (reader->Read(&event)) {
    }
    reader->Finish();
  }
}

}  // namespace
}  // namespace cablesim
