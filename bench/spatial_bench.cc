// Wall-clock cost of whole runs of the sample scenes (RunScene, model build
// included, frames discarded):
//
//   SpatialPendulum:            scenes/spatial-pendulum.json, the paper's
//                               spatial pendulum (16 elements, 2 s, h = 1e-4,
//                               backward Euler + MINRES).
//   FallingPendulum/Planar and  scenes/falling-pendulum.json (12 elements,
//   FallingPendulum/Spatial:    1 s, h = 1e-4) in the planar model and forced
//                               into the spatial one: what "model only what
//                               the scene needs" saves. Both follow the same
//                               trajectory (tests/spatial_test.cc).
//
// Counters: steps_per_s, newton_per_step, linear_per_step, coordinates.

#include <string>

#include <benchmark/benchmark.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/simulation.h"

namespace cablesim {
namespace {

class DiscardingSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame& frame) override {
    benchmark::DoNotOptimize(frame.t);
    return absl::OkStatus();
  }
};

absl::StatusOr<Scene> SampleScene(const std::string& file, ModelChoice model) {
  auto proto = ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + file);
  if (!proto.ok()) return proto.status();
  auto scene = SceneFromProto(*proto);
  if (scene.ok()) scene->model = model;
  return scene;
}

void RunSample(benchmark::State& state, const std::string& file, ModelChoice model) {
  const absl::StatusOr<Scene> scene = SampleScene(file, model);
  if (!scene.ok()) {
    state.SkipWithError(std::string(scene.status().message()).c_str());
    return;
  }
  DiscardingSink sink;
  int64_t steps = 0, newton = 0, linear = 0;
  double wall = 0;
  int coordinates = 0;
  for (auto _ : state) {
    absl::StatusOr<RunSummary> summary = RunScene(*scene, &sink);
    if (!summary.ok() || summary->status != "ok") {
      state.SkipWithError(summary.ok() ? summary->error.c_str()
                                       : std::string(summary.status().message()).c_str());
      return;
    }
    steps += summary->steps;
    newton += summary->newton_iterations;
    linear += summary->linear_iterations;
    wall += summary->wall_seconds;
    coordinates = summary->info.coordinates;
  }
  if (steps == 0) return;
  const double n = static_cast<double>(steps);
  state.counters["steps_per_s"] = benchmark::Counter(n / wall);
  state.counters["newton_per_step"] = benchmark::Counter(static_cast<double>(newton) / n);
  state.counters["linear_per_step"] = benchmark::Counter(static_cast<double>(linear) / n);
  state.counters["coordinates"] = benchmark::Counter(coordinates);
}

void BM_SpatialPendulum(benchmark::State& state) {
  RunSample(state, "spatial-pendulum.json", ModelChoice::kAuto);
}
void BM_FallingPendulum_Planar(benchmark::State& state) {
  RunSample(state, "falling-pendulum.json", ModelChoice::kPlanar);
}
void BM_FallingPendulum_Spatial(benchmark::State& state) {
  RunSample(state, "falling-pendulum.json", ModelChoice::kSpatial);
}

#define CABLESIM_RUN_BENCHMARK(fn)    \
  BENCHMARK(fn)                       \
      ->Unit(benchmark::kMillisecond) \
      ->UseRealTime()                 \
      ->Repetitions(5)                \
      ->ReportAggregatesOnly(true)

CABLESIM_RUN_BENCHMARK(BM_SpatialPendulum);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Planar);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Spatial);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
