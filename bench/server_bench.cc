// The cost of the service layer, and the parallel efficiency of its job
// workers.
//
//   Stream/InProcessEngine:  RunScene on the falling pendulum (scenes/,
//                            0.2 s at h = 1e-4) with a frame every step
//                            (2001 frames), frames discarded.
//   Stream/ServerLoopback:   the same run through cablesim-server's service
//                            over TCP on 127.0.0.1 (batches of 64 frames),
//                            every frame decoded by the client.
//   Stream/InProcessChannel: the same through the in-process channel that
//                            `cablesim run` uses.
//   The ratio ServerLoopback / InProcessEngine is the price of the service.
//
//   Sweep/workers:N:         a sweep of 8 items (the pendulum for 0.2 s at
//                            h = 1e-4, a frame every 10 ms) queued as jobs in
//                            a fresh SQLite store and run by N workers until
//                            the last finishes. items_per_s counter; parallel
//                            efficiency = rate(2) / (2 rate(1)).
//   EngineThreads/N:         the same 8 runs on N plain threads without the
//                            service: the machine's own parallel efficiency,
//                            the ceiling for Sweep.
//
// Run with --benchmark_repetitions=5 and read the medians.

#include <benchmark/benchmark.h>

#include <atomic>
#include <filesystem>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

#include "bench/sweep_bench_util.h"
#include "client/service_client.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "server/cablesim_server.h"

namespace cablesim {
namespace {

class DiscardingSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame& frame) override {
    benchmark::DoNotOptimize(frame.t);
    return absl::OkStatus();
  }
};

v1::Scene Pendulum(double output_interval_s) {
  v1::Scene scene =
      *ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/falling-pendulum.json");
  scene.mutable_solver()->set_duration(0.2);
  scene.mutable_solver()->set_step(1e-4);
  scene.mutable_solver()->set_output_interval(output_interval_s);
  return scene;
}

void BM_StreamInProcessEngine(benchmark::State& state) {
  const Scene scene = *SceneFromProto(Pendulum(1e-4));
  DiscardingSink sink;
  int64_t frames = 0;
  for (auto _ : state) frames += RunScene(scene, &sink)->frames;
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
}

void StreamThrough(benchmark::State& state, bool loopback) {
  ServerOptions options;
  options.listen = loopback ? "127.0.0.1:0" : "";
  options.limits = NoLimits();
  auto server = *CablesimServer::Start(options);
  std::shared_ptr<grpc::Channel> channel =
      loopback ? grpc::CreateChannel(absl::StrCat("127.0.0.1:", server->port()),
                                     grpc::InsecureChannelCredentials())
               : server->InProcessChannel();
  auto stub = v1::CablesimService::NewStub(channel);
  v1::RunRequest request;
  *request.mutable_scene() = Pendulum(1e-4);
  request.set_frames_per_batch(64);
  DiscardingSink sink;
  int64_t frames = 0;
  for (auto _ : state) {
    grpc::ClientContext context;
    auto reader = stub->Run(&context, request);
    absl::StatusOr<RunSummary> summary = ReadRunStream(&context, reader.get(), &sink, {});
    if (!summary.ok()) {
      state.SkipWithError(std::string(summary.status().message()).c_str());
      break;
    }
    frames += summary->frames;
  }
  state.counters["frames_per_s"] = benchmark::Counter(frames, benchmark::Counter::kIsRate);
  stub.reset();
  channel.reset();
  server->Shutdown(absl::ZeroDuration());
}

void BM_StreamServerLoopback(benchmark::State& state) { StreamThrough(state, true); }
void BM_StreamInProcessChannel(benchmark::State& state) { StreamThrough(state, false); }

void BM_Sweep(benchmark::State& state) {
  const int workers = static_cast<int>(state.range(0));
  constexpr int kItems = 8;
  v1::SubmitSweepRequest request;
  *request.mutable_base() = Pendulum(1e-2);
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("gravity.y");
  for (int i = 0; i < kItems; ++i) axis->add_values(-9.81 + 0.01 * i);
  int64_t items = 0;
  for (auto _ : state) {
    state.PauseTiming();
    const std::string dir =
        (std::filesystem::temp_directory_path() / absl::StrCat("cablesim_sweep_bench_", ::getpid()))
            .string();
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    ServerOptions options;
    options.data_dir = dir;
    options.workers = workers;
    options.limits = NoLimits();
    auto server = *CablesimServer::Start(options);
    auto stub = v1::CablesimService::NewStub(server->InProcessChannel());
    state.ResumeTiming();
    absl::StatusOr<int> finished = RunSweepToTheEnd(stub.get(), request);
    if (!finished.ok()) {
      state.SkipWithError(std::string(finished.status().message()).c_str());
      break;
    }
    items += *finished;
    state.PauseTiming();
    stub.reset();
    server->Shutdown(absl::ZeroDuration());
    server.reset();
    std::filesystem::remove_all(dir);
    state.ResumeTiming();
  }
  state.counters["items_per_s"] = benchmark::Counter(items, benchmark::Counter::kIsRate);
}

// The reference for BM_Sweep: the same 8 runs on N plain threads, engine
// only (no service, no SQLite): what the machine itself gives in parallel.
void BM_EngineThreads(benchmark::State& state) {
  const int threads = static_cast<int>(state.range(0));
  constexpr int kItems = 8;
  std::vector<Scene> scenes;
  for (int i = 0; i < kItems; ++i) {
    v1::Scene proto = Pendulum(1e-2);
    proto.mutable_gravity()->set_y(-9.81 + 0.01 * i);
    scenes.push_back(*SceneFromProto(proto));
  }
  int64_t items = 0;
  for (auto _ : state) {
    std::atomic<int> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      pool.emplace_back([&] {
        DiscardingSink sink;
        for (int i; (i = next.fetch_add(1)) < kItems;)
          benchmark::DoNotOptimize(RunScene(scenes[i], &sink));
      });
    }
    for (std::thread& t : pool) t.join();
    items += kItems;
  }
  state.counters["items_per_s"] = benchmark::Counter(items, benchmark::Counter::kIsRate);
}

BENCHMARK(BM_StreamInProcessEngine)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StreamServerLoopback)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_StreamInProcessChannel)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Sweep)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_EngineThreads)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
