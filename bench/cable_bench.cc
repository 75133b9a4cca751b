// Wall-clock cost of whole DYNAMIC runs (RunScene, model build included),
// with the frames discarded.
//
//   falling_pendulum: scenes/falling-pendulum.json built in C++ (12 elements,
//                     1 s at h = 1e-4).
//   soft_cable_200:   a 2 m, 200-element soft cable (rho 1000, E 1e7,
//                     d = 1 cm) pinned at s = 0, horizontal, falling under
//                     gravity for 0.1 s at h = 1e-4.
//
// Each is run with MINRES and with GMRES. Counters per run: steps_per_s
// (accepted steps over the summary's wall time), newton_per_step,
// linear_per_step (Krylov iterations per accepted step) and dofs.

#include <cmath>
#include <numbers>
#include <string>

#include <benchmark/benchmark.h>

#include "engine/scene.h"
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

Attachment OnCable(int cable, double s) {
  Attachment at;
  at.cable = cable;
  at.s_m = s;
  return at;
}

// A straight horizontal cable from the origin along +x, pinned to the
// ground at s = 0, with a probe at its tip, under gravity -9.81 y.
Scene PinnedCable(const std::string& name, double length, int elements, double density,
                  double youngs_modulus, double area, double second_moment, double duration,
                  LinearSolverKind linear_solver) {
  Scene scene;
  scene.name = name;
  scene.gravity_m_s2 = Eigen::Vector3d(0, -9.81, 0);

  CableSpec cable;
  cable.name = "beam";
  cable.points = {Eigen::Vector3d::Zero(), Eigen::Vector3d(length, 0, 0)};
  cable.length_m = length;
  cable.elements = elements;
  cable.density_kg_m3 = density;
  cable.youngs_modulus_pa = youngs_modulus;
  cable.area_m2 = area;
  cable.second_moment_m4 = second_moment;
  cable.bending = BendingModel::kExact;
  scene.cables.push_back(cable);

  JointSpec pin;
  pin.type = JointType::kPin;
  pin.a = OnCable(0, 0);
  pin.b = Attachment{};  // ground
  scene.joints.push_back(pin);

  ProbeSpec tip;
  tip.name = "tip";
  tip.at = OnCable(0, length);
  scene.probes.push_back(tip);

  scene.solver.analysis = Analysis::kDynamic;
  scene.solver.duration_s = duration;
  scene.solver.step_s = 1e-4;
  scene.solver.output_interval_s = 1e-3;
  scene.solver.integrator = Integrator::kImplicitEuler;
  scene.solver.linear_solver = linear_solver;
  return scene;
}

Scene FallingPendulum(LinearSolverKind linear_solver) {
  return PinnedCable("falling-pendulum", 1.2, 12, 5540, 0.7e6, 0.0018, 1.215e-8, 1.0,
                     linear_solver);
}

Scene SoftCable200(LinearSolverKind linear_solver) {
  constexpr double kPi = std::numbers::pi;
  const double d = 0.01;
  return PinnedCable("soft-cable-200", 2.0, 200, 1000, 1e7, kPi * d * d / 4,
                     kPi * d * d * d * d / 64, 0.1, linear_solver);
}

void RunBenchmark(benchmark::State& state, const Scene& scene) {
  DiscardingSink sink;
  int64_t steps = 0, newton = 0, linear = 0;
  double wall = 0;
  int dofs = 0;
  for (auto _ : state) {
    absl::StatusOr<RunSummary> summary = RunScene(scene, &sink);
    if (!summary.ok()) {
      state.SkipWithError(std::string(summary.status().message()).c_str());
      return;
    }
    if (summary->status != "ok") {
      state.SkipWithError((summary->status + ": " + summary->error).c_str());
      return;
    }
    steps += summary->steps;
    newton += summary->newton_iterations;
    linear += summary->linear_iterations;
    wall += summary->wall_seconds;
    dofs = summary->info.dofs;
  }
  if (steps == 0) return;
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps) / wall);
  state.counters["newton_per_step"] =
      benchmark::Counter(static_cast<double>(newton) / static_cast<double>(steps));
  state.counters["linear_per_step"] =
      benchmark::Counter(static_cast<double>(linear) / static_cast<double>(steps));
  state.counters["dofs"] = benchmark::Counter(dofs);
}

void BM_FallingPendulum_Minres(benchmark::State& state) {
  RunBenchmark(state, FallingPendulum(LinearSolverKind::kMinres));
}
void BM_FallingPendulum_Gmres(benchmark::State& state) {
  RunBenchmark(state, FallingPendulum(LinearSolverKind::kGmres));
}
void BM_SoftCable200_Minres(benchmark::State& state) {
  RunBenchmark(state, SoftCable200(LinearSolverKind::kMinres));
}
void BM_SoftCable200_Gmres(benchmark::State& state) {
  RunBenchmark(state, SoftCable200(LinearSolverKind::kGmres));
}

#define CABLESIM_RUN_BENCHMARK(fn)      \
  BENCHMARK(fn)                         \
      ->Unit(benchmark::kMillisecond)   \
      ->UseRealTime()                   \
      ->Repetitions(5)                  \
      ->ReportAggregatesOnly(true)

CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Minres);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Gmres);
CABLESIM_RUN_BENCHMARK(BM_SoftCable200_Minres);
CABLESIM_RUN_BENCHMARK(BM_SoftCable200_Gmres);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
