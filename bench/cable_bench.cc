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
//
// Issue 5 configurations of the falling pendulum (frames every 0.01 s):
// generalized-alpha and HHT with DIRECT at the paper's step, the fastest
// configuration found with tip error <= 1e-3 m, and adaptive steps. Each
// reports tip_error_m, the largest tip distance over the frames from a
// converged run of the same mesh (generalized-alpha, rho 1, h = 1e-5).
//
//   step_scaling/N:   whole runs of that cable (100 steps of 1e-5 s, HHT +
//                     DIRECT): us_per_step against elements.
//   newton_iteration/N: one Newton iteration (assemble, factor, solve) on
//                     an N-element soft cable (as soft_cable_200), DIRECT
//                     and MINRES: time per iteration against elements.
//
// Sample scenes read from scenes/ (issue 3), as they are written:
//   SpatialPendulum:          scenes/spatial-pendulum.json, the paper's
//                             spatial pendulum (16 elements, 2 s, h = 1e-4,
//                             backward Euler + MINRES).
//   FallingPendulum_Planar,   scenes/falling-pendulum.json in the planar
//   FallingPendulum_Spatial:  model and forced into the spatial one: what
//                             "model only what the scene needs" saves (both
//                             follow the same trajectory, tests/spatial_test.cc).
//   CableInCurrent:           scenes/cable-in-current.json (10 elements, Morison
//                             drag in a current, 200 s at h = 0.05, backward
//                             Euler): the fluid-load path of a scene without
//                             waves.
//   CableWithEndCylinder:     scenes/cable-with-end-cylinder.json (a body,
//                             no fluid).
//   ThreeLineBuoy:            scenes/mooring-three-line-buoy.json (issue 17):
//                             sim_s_per_wall_s is the real-time ratio.

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numbers>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"
#include "engine/run/simulation.h"

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
  scene.solver.Use(Integrator::kImplicitEuler);
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

// Keeps the tip position of every frame.
class TipSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame& frame) override {
    tips.push_back(frame.probes[0].position_m);
    return absl::OkStatus();
  }
  std::vector<Eigen::Vector3d> tips;
};

Scene FastPendulum(Integrator integrator, LinearSolverKind ls, double step) {
  Scene scene = FallingPendulum(ls);
  scene.solver.Use(integrator);
  scene.solver.step_s = step;
  scene.solver.output_interval_s = 0.01;
  return scene;
}

// The converged reference of the falling pendulum (frames every 0.01 s).
const std::vector<Eigen::Vector3d>& ReferenceTips() {
  static const std::vector<Eigen::Vector3d> tips = [] {
    Scene scene = FastPendulum(Integrator::kGeneralizedAlpha, LinearSolverKind::kDirect, 1e-5);
    scene.solver.rho_infinity = 1;
    TipSink sink;
    (void)RunScene(scene, &sink);
    return sink.tips;
  }();
  return tips;
}

double TipError(const Scene& scene) {
  TipSink sink;
  auto summary = RunScene(scene, &sink);
  const auto& ref = ReferenceTips();
  if (!summary.ok() || summary->status != "ok" || sink.tips.size() != ref.size()) return -1;
  double worst = 0;
  for (size_t i = 0; i < ref.size(); ++i) worst = std::max(worst, (sink.tips[i] - ref[i]).norm());
  return worst;
}

void RunBenchmark(benchmark::State& state, const Scene& scene) {
  DiscardingSink sink;
  int64_t steps = 0, newton = 0, linear = 0;
  double wall = 0, simulated = 0, cpu = 0;
  int dofs = 0, coordinates = 0;
  for (auto _ : state) {
    const std::clock_t cpu_start = std::clock();
    absl::StatusOr<RunSummary> summary = RunScene(scene, &sink);
    cpu += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
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
    simulated += summary->end_time_s;
    dofs = summary->info.dofs;
    coordinates = summary->info.coordinates;
  }
  if (steps == 0) return;
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps) / wall);
  state.counters["newton_per_step"] =
      benchmark::Counter(static_cast<double>(newton) / static_cast<double>(steps));
  state.counters["linear_per_step"] =
      benchmark::Counter(static_cast<double>(linear) / static_cast<double>(steps));
  state.counters["dofs"] = benchmark::Counter(dofs);
  // Simulated seconds per wall second (the summary's wall time: the run,
  // model build and initial statics included).
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated / wall);
  // The same per second of this process's CPU time (a loaded machine
  // stretches the wall time, not this).
  state.counters["sim_s_per_cpu_s"] = benchmark::Counter(simulated / cpu);
  state.counters["coordinates"] = benchmark::Counter(coordinates);
  state.counters["us_per_step"] =
      benchmark::Counter(1e6 * wall / static_cast<double>(steps));
  state.counters["us_per_newton"] =
      benchmark::Counter(1e6 * wall / static_cast<double>(std::max<int64_t>(newton, 1)));
  if (scene.solver.output_interval_s == 0.01 && scene.cables[0].elements == 12)
    state.counters["tip_error_m"] = benchmark::Counter(TipError(scene));
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

void BM_FallingPendulum_GeneralizedAlpha_Direct_h1e4(benchmark::State& state) {
  RunBenchmark(state,
               FastPendulum(Integrator::kGeneralizedAlpha, LinearSolverKind::kDirect, 1e-4));
}
void BM_FallingPendulum_Hht_Direct_h1e4(benchmark::State& state) {
  RunBenchmark(state, FastPendulum(Integrator::kHht, LinearSolverKind::kDirect, 1e-4));
}
void BM_FallingPendulum_ImplicitEuler_Direct_h1e4(benchmark::State& state) {
  RunBenchmark(state,
               FastPendulum(Integrator::kImplicitEuler, LinearSolverKind::kDirect, 1e-4));
}
// The fastest configuration found with tip error <= 1e-3 m: generalized-
// alpha (rho 0.8), DIRECT, factorization reuse, h = 6.25e-4 (16 steps per
// frame), Newton tolerance 1e-5 (far below the 1e-3 m step error).
Scene Fastest() {
  Scene scene = FastPendulum(Integrator::kGeneralizedAlpha, LinearSolverKind::kDirect, 6.25e-4);
  scene.solver.newton_tolerance = 1e-5;
  scene.solver.rho_infinity = 0.8;
  return scene;
}
void BM_FallingPendulum_Fastest(benchmark::State& state) { RunBenchmark(state, Fastest()); }
void BM_FallingPendulum_Fastest_NoReuse(benchmark::State& state) {
  Scene scene = Fastest();
  scene.solver.reuse_factorization = false;
  RunBenchmark(state, scene);
}
// The same with output.statistics and a rainflow count of the tip's y
// (docs/outputs-statistics.md): what asking for them costs.
void BM_FallingPendulum_Fastest_Statistics(benchmark::State& state) {
  Scene scene = Fastest();
  scene.output.statistics = true;
  scene.output.rainflow = {{"tip.y"}, 3, 1e7};
  RunBenchmark(state, scene);
}
// HHT needs rho_infinity 0.9 (alpha = -0.053) for the same error bound.
void BM_FallingPendulum_Fastest_Hht(benchmark::State& state) {
  Scene scene = Fastest();
  scene.solver.Use(Integrator::kHht);
  scene.solver.rho_infinity = 0.9;
  RunBenchmark(state, scene);
}
void BM_FallingPendulum_Fastest_Minres(benchmark::State& state) {
  Scene scene = Fastest();
  scene.solver.linear_solver = LinearSolverKind::kMinres;
  RunBenchmark(state, scene);
}
// The energy-momentum stepper at h = 5e-4 (tip error 9.7e-4 m at every
// 1 ms frame, README), default Newton tolerance, as a scene gets it (a
// fresh Newton matrix every iteration) and with the matrix kept.
Scene EnergyMomentum() {
  Scene scene = FastPendulum(Integrator::kEnergyMomentum, LinearSolverKind::kDirect, 5e-4);
  scene.solver.reuse_factorization = false;
  return scene;
}
void BM_FallingPendulum_EnergyMomentum(benchmark::State& state) {
  RunBenchmark(state, EnergyMomentum());
}
void BM_FallingPendulum_EnergyMomentum_Reuse(benchmark::State& state) {
  Scene scene = EnergyMomentum();
  scene.solver.reuse_factorization = true;
  RunBenchmark(state, scene);
}
// The explicit steppers (README, "The explicit steppers"): central
// difference at h = 7e-4 (8.2e-4 m at every 1 ms frame), and adaptive with
// tolerance 1e-4 (4.4e-4 m); Dormand-Prince at h = 1e-3 (1.7e-5 m).
void BM_FallingPendulum_CentralDifference(benchmark::State& state) {
  RunBenchmark(state, FastPendulum(Integrator::kCentralDifference, LinearSolverKind::kAuto, 7e-4));
}
void BM_FallingPendulum_CentralDifference_Adaptive(benchmark::State& state) {
  Scene scene = FastPendulum(Integrator::kCentralDifference, LinearSolverKind::kAuto, 1e-3);
  scene.solver.adaptive = true;
  scene.solver.tolerance_m = 1e-4;
  RunBenchmark(state, scene);
}
void BM_FallingPendulum_DormandPrince(benchmark::State& state) {
  RunBenchmark(state, FastPendulum(Integrator::kDormandPrince, LinearSolverKind::kAuto, 1e-3));
}
void BM_FallingPendulum_Adaptive_tol1e4(benchmark::State& state) {
  Scene scene = Fastest();
  scene.solver.step_s = 1e-3;
  scene.solver.adaptive = true;
  scene.solver.tolerance_m = 1e-4;
  RunBenchmark(state, scene);
}

// One Newton iteration of generalized-alpha on an N-element cable (the
// soft cable, 2 m): assemble M + c K_T with the forces, factor, solve. The
// cost that a step repeats; per iteration rather than per run because the
// step count of that scene depends on N (short elements hit the rounding
// floor of the residual early in the run).
void NewtonIteration(benchmark::State& state, LinearSolverKind kind) {
  constexpr double kPi = std::numbers::pi;
  const double d = 0.01;
  const int n_el = static_cast<int>(state.range(0));
  Scene scene = PinnedCable("soft-cable", 2.0, n_el, 1000, 1e7, kPi * d * d / 4,
                            kPi * d * d * d * d / 64, 1e-3, kind);
  auto model = MultibodyModel::Build(scene);
  if (!model.ok()) {
    state.SkipWithError(std::string(model.status().message()).c_str());
    return;
  }
  SaddlePointSolver solver;
  solver.Resize(model->envelope(), model->jacobian_pattern());
  Eigen::VectorXd q(model->coordinates()), f(model->dofs()), rhs(model->dofs()), x(model->dofs());
  // The cable stretched by 0.1 % (tension everywhere: A positive definite).
  Eigen::VectorXd z = model->initial_z();
  model->ToFull(z, &q);
  for (int i = 0; i < q.size(); i += 4) q(i) *= 1.001;
  const double c = 0.25 * 1e-4 * 1e-4;
  int iterations = 0;
  for (auto _ : state) {
    const SkylineLdlt& mass = model->mass();
    std::copy(mass.values(), mass.values() + mass.stored(), solver.a().values());
    model->NetForce(q, 1.0, &f, &solver.a(), c);
    if (!solver.Prepare()) {
      state.SkipWithError("factorization failed");
      return;
    }
    rhs = f;
    const auto st = solver.Solve(kind, rhs, 1e-10, 200, &x);
    iterations += st.iterations;
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["dofs"] = benchmark::Counter(model->dofs());
  state.counters["krylov_per_solve"] =
      benchmark::Counter(static_cast<double>(iterations) / state.iterations());
}
// Whole runs: the N-element soft cable, 100 steps of 1e-5 s with the
// defaults (HHT, factorization reuse) and DIRECT; us_per_step includes the
// model build and the frames (every 10 steps); us_per_newton divides by
// the Newton iterations instead (their number per step grows with N).
void BM_StepScaling_Direct(benchmark::State& state) {
  constexpr double kPi = std::numbers::pi;
  const double d = 0.01;
  Scene scene = PinnedCable("soft-cable", 2.0, static_cast<int>(state.range(0)), 1000, 1e7,
                            kPi * d * d / 4, kPi * d * d * d * d / 64, 1e-3,
                            LinearSolverKind::kDirect);
  scene.solver.Use(Integrator::kHht);
  scene.solver.step_s = 1e-5;
  scene.solver.output_interval_s = 1e-4;
  RunBenchmark(state, scene);
}

// Issue 9's hard case as a user runs it: the 10 m steel cable (E = 2e11 Pa,
// d = 1 cm, density 7850) pinned and released horizontal, N elements, the
// defaults (HHT, rho 0.5, AUTO linear solver, factorization reuse) at
// h = 1e-4 for 5 ms (50 steps), frames every step; us_per_step includes the
// model build. The stepper is the argument's second value: 0 HHT, 1
// generalized-alpha, 2 backward Euler.
void BM_SteelCable(benchmark::State& state) {
  constexpr double kPi = std::numbers::pi;
  const double d = 0.01;
  Scene scene = PinnedCable("steel-cable", 10.0, static_cast<int>(state.range(0)), 7850, 2e11,
                            kPi * d * d / 4, kPi * d * d * d * d / 64, 5e-3,
                            LinearSolverKind::kAuto);
  scene.solver.Use(state.range(1) == 0   ? Integrator::kHht
                            : state.range(1) == 1 ? Integrator::kGeneralizedAlpha
                                                  : Integrator::kImplicitEuler);
  scene.solver.reuse_factorization = state.range(1) != 2;
  scene.solver.step_s = 1e-4;
  scene.solver.output_interval_s = 0;
  RunBenchmark(state, scene);
}

void BM_NewtonIteration_Direct(benchmark::State& state) {
  NewtonIteration(state, LinearSolverKind::kDirect);
}
void BM_NewtonIteration_Minres(benchmark::State& state) {
  NewtonIteration(state, LinearSolverKind::kMinres);
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
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_GeneralizedAlpha_Direct_h1e4);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Hht_Direct_h1e4);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_ImplicitEuler_Direct_h1e4);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Fastest);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Fastest_Statistics);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Fastest_NoReuse);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Fastest_Hht);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Fastest_Minres);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Adaptive_tol1e4);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_EnergyMomentum);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_EnergyMomentum_Reuse);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_CentralDifference);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_CentralDifference_Adaptive);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_DormandPrince);
CABLESIM_RUN_BENCHMARK(BM_StepScaling_Direct)->Arg(1000)->Arg(3000)->Arg(10000);
CABLESIM_RUN_BENCHMARK(BM_SteelCable)
    ->ArgsProduct({{1000, 2000, 5000, 10000}, {0, 1, 2}});

// A sample scene from scenes/, run as written except for the model.
void RunSample(benchmark::State& state, const std::string& file, ModelChoice model) {
  auto proto = ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + file);
  absl::StatusOr<Scene> scene =
      proto.ok() ? SceneFromProto(*proto) : absl::StatusOr<Scene>(proto.status());
  if (!scene.ok()) {
    state.SkipWithError(std::string(scene.status().message()).c_str());
    return;
  }
  scene->model = model;
  RunBenchmark(state, *scene);
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
CABLESIM_RUN_BENCHMARK(BM_SpatialPendulum);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Planar);
CABLESIM_RUN_BENCHMARK(BM_FallingPendulum_Spatial);
void BM_CableInCurrent(benchmark::State& state) {
  RunSample(state, "cable-in-current.json", ModelChoice::kAuto);
}
CABLESIM_RUN_BENCHMARK(BM_CableInCurrent);
// A scene with a body and no fluid: what body hydrodynamics cost a scene
// without them.
void BM_CableWithEndCylinder(benchmark::State& state) {
  RunSample(state, "cable-with-end-cylinder.json", ModelChoice::kAuto);
}
CABLESIM_RUN_BENCHMARK(BM_CableWithEndCylinder);
// Issue 17: scenes/mooring-three-line-buoy.json as written (3 lines of 50
// elements, a floating buoy in regular waves, from static equilibrium).
void BM_ThreeLineBuoy(benchmark::State& state) {
  RunSample(state, "mooring-three-line-buoy.json", ModelChoice::kAuto);
}
CABLESIM_RUN_BENCHMARK(BM_ThreeLineBuoy);
BENCHMARK(BM_NewtonIteration_Direct)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Arg(1000)
    ->Arg(3000)
    ->Arg(10000);
BENCHMARK(BM_NewtonIteration_Minres)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Arg(1000)
    ->Arg(3000)
    ->Arg(10000);

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
