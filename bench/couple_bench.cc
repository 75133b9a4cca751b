// The physics cost of a coupling step (engine/run/coupling.h): the
// three-line buoy (scenes/mooring-three-line-buoy.json) with its buoy
// replaced by the host: the three fairleads become coupled supports, driven
// in heave and surge (1 m, 10 s) at a coupling step of 0.05 s (one scene
// step inside each). The time per iteration is one CouplingSession::Step.
// (The gRPC Couple stream, whose loopback round trip this is to be set
// against, is not there yet: docs/coupling.md.)

#include <cmath>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/coupling.h"

namespace cablesim {
namespace {

Scene CoupledBuoy() {
  auto proto = ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) +
                             "/scenes/mooring-three-line-buoy.json");
  if (!proto.ok()) std::abort();
  auto scene = SceneFromProto(*proto);
  if (!scene.ok()) std::abort();
  // The fairleads (joints to the buoy) become coupled supports; the buoy
  // and its probe go.
  for (JointSpec& j : scene->joints) {
    if (j.b.body < 0) continue;
    j.b = Attachment{};
    j.coupled = true;
  }
  scene->bodies.clear();
  std::vector<ProbeSpec> probes;
  for (const ProbeSpec& p : scene->probes)
    if (p.at.body < 0) probes.push_back(p);
  scene->probes = probes;
  return *scene;
}

void BM_CoupledBuoyStep(benchmark::State& state) {
  const double dt = 0.05;
  auto session = CouplingSession::Open(CoupledBuoy());
  if (!session.ok()) {
    state.SkipWithError(std::string(session.status().message()).c_str());
    return;
  }
  CouplingSession& s = **session;
  const int n = s.coupled_points();
  std::vector<Eigen::Vector3d> x(n), v(n, Eigen::Vector3d::Zero());
  for (int i = 0; i < n; ++i) x[i] = s.scene_position(i);
  if (!s.Initialize(x, v).ok()) {
    state.SkipWithError("Initialize");
    return;
  }
  const double w = 2 * std::numbers::pi / 10;
  long k = 0;
  for (auto _ : state) {
    const double t = dt * static_cast<double>(++k);
    const Eigen::Vector3d d(std::sin(w * t), 0, std::sin(w * t));
    for (int i = 0; i < n; ++i) {
      x[i] = s.scene_position(i) + d;
      v[i] = w * Eigen::Vector3d(std::cos(w * t), 0, std::cos(w * t));
    }
    if (absl::Status st = s.Step(t, x, v); !st.ok()) {
      state.SkipWithError(std::string(st.message()).c_str());
      return;
    }
  }
  state.counters["sim_s_per_wall_s"] =
      benchmark::Counter(dt * static_cast<double>(k), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CoupledBuoyStep)->Unit(benchmark::kMillisecond)->MinTime(3);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
