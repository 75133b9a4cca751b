// Sweep throughput across servers sharing one PostgreSQL job store, and
// the store's own cost per job against SQLite.
//
//   SharedSweep/servers:N:   a 200-item sweep (the falling pendulum of
//                            scenes/ for 0.2 s at h = 1e-4, a frame every
//                            10 ms: ~35 ms of computing each) submitted to
//                            server 0 of N servers with one worker each,
//                            all on one PostgreSQL database, until server 0
//                            sees the last item finish. items_per_s;
//                            parallel efficiency = rate(N) / (N rate(1)).
//   SqliteSweep:             the same sweep on one server with one worker
//                            and its embedded SQLite store.
//   StoreOverhead/sqlite, /postgresql: 200 items of one time step each
//                            (~0.1 ms of computing) on one worker: the time
//                            per item is the store's per-job cost (submit,
//                            claim, result, final state, watch) plus the
//                            service's.
//   WatchLatency/notify:1|0: how soon a watcher on one server sees a job
//                            another ran finish, with LISTEN/NOTIFY and
//                            with polling alone.
//
// The servers run in this process (CablesimServer, in-process channels),
// each with its own store connection, exactly as separate processes would
// share the database. PostgreSQL is started by the benchmark itself on
// loopback (tests/postgres_test_util.h: initdb + pg_ctl in a temporary
// directory); without it the PostgreSQL benchmarks are skipped with the
// reason. It flushes every commit to disk (fsync on, its default), as
// SQLite's store does (synchronous=FULL).
//
// Run: build/bin/server_shared_store_bench --benchmark_repetitions=3
// and read the medians. On a machine with C cores, N servers of one
// worker cannot go faster than min(N, C) times one.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <limits>
#include <memory>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bench/sweep_bench_util.h"
#include "convert/scene_file.h"
#include "server/cablesim_server.h"
#include "tests/postgres_test_util.h"

namespace cablesim {
namespace {

constexpr int kItems = 200;

v1::SubmitSweepRequest Sweep(double duration_s) {
  v1::SubmitSweepRequest request;
  request.set_name("bench");
  v1::Scene scene =
      *ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/falling-pendulum.json");
  scene.mutable_solver()->set_duration(duration_s);
  scene.mutable_solver()->set_step(1e-4);
  scene.mutable_solver()->set_output_interval(std::max(1e-4, std::min(1e-2, duration_s)));
  *request.mutable_base() = scene;
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("gravity.y");
  for (int i = 0; i < kItems; ++i) axis->add_values(-9.81 + 0.001 * i);
  return request;
}

// Runs the sweep (items of `duration_s`) on `servers` servers of one
// worker each, on a fresh PostgreSQL database or SQLite directory each
// time; adds items_per_s and ms_per_item.
void RunSweeps(benchmark::State& state, int servers, bool postgres, double duration_s) {
  testing::TestPostgres* pg = nullptr;
  if (postgres) {
    std::string why;
    testing::TestPostgres::durable() = true;  // fsync as SQLite's synchronous=FULL
    pg = testing::TestPostgres::Get(&why);
    if (pg == nullptr) {
      state.SkipWithError(absl::StrCat("PostgreSQL: ", why).c_str());
      return;
    }
  }
  const v1::SubmitSweepRequest request = Sweep(duration_s);
  int64_t items = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const std::string dir = (std::filesystem::temp_directory_path() /
                             absl::StrCat("cablesim_shared_bench_", ::getpid()))
                                .string();
    std::filesystem::remove_all(dir);
    const std::string store = postgres ? pg->NewDatabase("bench") : "sqlite:" + dir;
    std::vector<std::unique_ptr<CablesimServer>> running;
    for (int i = 0; i < servers; ++i) {
      ServerOptions options;
      options.data_dir = store;
      options.workers = 1;
      options.log = false;
      options.limits = NoLimits();
      absl::StatusOr<std::unique_ptr<CablesimServer>> server = CablesimServer::Start(options);
      if (!server.ok()) {
        state.SkipWithError(std::string(server.status().message()).c_str());
        return;
      }
      running.push_back(std::move(*server));
    }
    auto stub = v1::CablesimService::NewStub(running[0]->InProcessChannel());
    state.ResumeTiming();
    absl::StatusOr<int> finished = RunSweepToTheEnd(stub.get(), request);
    if (!finished.ok() || *finished != kItems) {
      state.SkipWithError("sweep failed");
      return;
    }
    items += kItems;
    state.PauseTiming();
    stub.reset();
    for (auto& s : running) s->Shutdown(absl::ZeroDuration());
    running.clear();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
  }
  state.counters["items_per_s"] = benchmark::Counter(items, benchmark::Counter::kIsRate);
  // Seconds per (item / 1000): milliseconds per item.
  state.counters["ms_per_item"] = benchmark::Counter(
      items / 1000.0, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_SharedSweep(benchmark::State& state) {
  RunSweeps(state, static_cast<int>(state.range(0)), true, 0.2);
}
void BM_SqliteSweep(benchmark::State& state) { RunSweeps(state, 1, false, 0.2); }
void BM_StoreOverheadSqlite(benchmark::State& state) { RunSweeps(state, 1, false, 1e-4); }
void BM_StoreOverheadPostgresql(benchmark::State& state) { RunSweeps(state, 1, true, 1e-4); }

// How soon a watcher on one server sees a job finish that may have run on
// another: 40 one-step jobs submitted to server 0 of two (one worker
// each), each watched (WatchJob) on server 1 from its submission; the
// mean time from the job's finish (finished_unix_ms) to the end of the
// watch. notify:1, the servers LISTEN for each other's NOTIFY; notify:0,
// they poll alone (a watcher every 1 s).
void BM_WatchLatency(benchmark::State& state) {
  std::string why;
  testing::TestPostgres::durable() = true;
  testing::TestPostgres* pg = testing::TestPostgres::Get(&why);
  if (pg == nullptr) {
    state.SkipWithError(absl::StrCat("PostgreSQL: ", why).c_str());
    return;
  }
  constexpr int kJobs = 40;
  v1::SubmitJobRequest submit;
  *submit.mutable_scene() = Sweep(1e-4).base();
  double total_ms = 0;
  int64_t jobs = 0;
  for (auto _ : state) {
    const std::string store = pg->NewDatabase("watch");
    std::vector<std::unique_ptr<CablesimServer>> servers;
    for (int i = 0; i < 2; ++i) {
      ServerOptions options;
      options.data_dir = store;
      options.workers = 1;
      options.log = false;
      options.limits = NoLimits();
      options.store_notifications = state.range(0) != 0;
      servers.push_back(*CablesimServer::Start(options));
    }
    auto submitter = v1::CablesimService::NewStub(servers[0]->InProcessChannel());
    auto watcher = v1::CablesimService::NewStub(servers[1]->InProcessChannel());
    for (int i = 0; i < kJobs; ++i) {
      v1::Job job;
      grpc::ClientContext context;
      if (!submitter->SubmitJob(&context, submit, &job).ok()) {
        state.SkipWithError("SubmitJob failed");
        return;
      }
      grpc::ClientContext watch_context;
      v1::WatchJobRequest watch;
      watch.set_id(job.id());
      auto reader = watcher->WatchJob(&watch_context, watch);
      while (reader->Read(&job)) {
      }
      total_ms += static_cast<double>(NowUnixMs() - job.finished_unix_ms());
      ++jobs;
    }
    for (auto& s : servers) s->Shutdown(absl::ZeroDuration());
  }
  state.counters["mean_ms_after_finish"] = total_ms / static_cast<double>(jobs);
}

BENCHMARK(BM_WatchLatency)
    ->ArgName("notify")
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK(BM_SharedSweep)
    ->ArgName("servers")
    ->Arg(1)
    ->Arg(2)
    ->Arg(3)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK(BM_SqliteSweep)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_StoreOverheadSqlite)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_StoreOverheadPostgresql)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
