#include "engine/run/simulation.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "engine/analysis/modal_solver.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/model/multibody_model.h"
#include "engine/output/run_statistics.h"
#include "engine/run/auto_integrator.h"
#include "engine/run/dynamic_run.h"
#include "engine/run/error_estimate.h"
#include "engine/run/frame_recorder.h"
#include "engine/run/joint_release.h"
#include "engine/run/run_warnings.h"
#include "engine/run/static_run.h"
#include "engine/scene/integrator_traits.h"

namespace cablesim {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

struct PreparedModel {
  Scene scene;
  MultibodyModel model;
  ModelInfo info;
  int modes = 0;  // MODAL: the modes to compute
  double build_seconds = 0;
  bool used = false;
};

PreparedRun::PreparedRun() = default;
PreparedRun::PreparedRun(PreparedRun&&) noexcept = default;
PreparedRun& PreparedRun::operator=(PreparedRun&&) noexcept = default;
PreparedRun::~PreparedRun() = default;
const ModelInfo& PreparedRun::info() const { return model_->info; }
bool PreparedRun::used() const { return model_->used; }

absl::StatusOr<PreparedRun> Prepare(const Scene& scene,
                                    const std::function<bool()>& should_stop) {
  const auto start = Clock::now();
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene, should_stop);
  if (!built.ok()) return built.status();
  int modes = 0;
  if (scene.solver.analysis == Analysis::kModal) {
    absl::StatusOr<int> count = ModalSolver::ModeCount(*built, scene.solver);
    if (!count.ok()) return count.status();
    modes = *count;
  }
  PreparedRun prepared;
  ModelInfo info = built->Info();
  if (absl::Status s = CheckStatisticsSpec(scene.output, info,
                                           scene.solver.analysis == Analysis::kModal);
      !s.ok())
    return s;
  prepared.model_.reset(new PreparedModel{scene, std::move(*built), std::move(info), modes,
                                          std::chrono::duration<double>(Clock::now() - start).count(),
                                          false});
  return prepared;
}

absl::StatusOr<ModelInfo> DescribeModel(const Scene& scene,
                                        const std::function<bool()>& should_stop) {
  absl::StatusOr<PreparedRun> prepared = Prepare(scene, should_stop);
  if (!prepared.ok()) return prepared.status();
  return prepared->info();
}

absl::StatusOr<RunSummary> RunScene(const Scene& scene, FrameSink* sink,
                                    const RunControl& control) {
  const auto start = Clock::now();
  absl::StatusOr<PreparedRun> prepared = Prepare(scene, control.should_stop);
  if (absl::IsCancelled(prepared.status())) {
    RunSummary stopped;
    stopped.status = "cancelled";
    stopped.error = std::string(prepared.status().message());
    stopped.analysis = std::string(AnalysisName(scene.solver.analysis));
    stopped.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return stopped;
  }
  if (!prepared.ok()) return prepared.status();
  return RunPrepared(&*prepared, sink, control);
}

absl::StatusOr<RunSummary> RunPrepared(PreparedRun* prepared, FrameSink* sink,
                                       const RunControl& control) {
  if (prepared->model_ == nullptr || prepared->model_->used)
    return absl::FailedPreconditionError("a prepared model runs once; prepare it again");
  const auto start = Clock::now();
  PreparedModel& p = *prepared->model_;
  p.used = true;
  MultibodyModel& model = p.model;
  RunSummary summary;
  // AUTO holds while the integrator is the one convert/ left (HHT); code
  // that set another itself meant it (SolverSettings::Use).
  if (p.scene.solver.integrator != Integrator::kHht) p.scene.solver.auto_integrator = false;
  summary.integrator_requested =
      p.scene.solver.auto_integrator ? "AUTO" : std::string(IntegratorName(p.scene.solver.integrator));
  if (p.scene.solver.auto_integrator && p.scene.solver.analysis == Analysis::kDynamic)
    p.scene.solver.integrator = ChooseIntegrator(&model, p.scene, &summary.integrator_reason,
                                                 &p.scene.solver.auto_may_switch);
  const Scene& scene = p.scene;
  summary.info = p.info;
  summary.warnings = scene.warnings;
  const SolverSettings& settings = scene.solver;
  summary.analysis = std::string(AnalysisName(settings.analysis));
  const int modes = p.modes;
  summary.integrator = std::string(IntegratorName(settings.integrator));
  summary.linear_solver = std::string(LinearSolverName(settings.linear_solver));
  summary.linear_solver_used = std::string(LinearSolverName(
      SaddlePointSolver::Resolve(settings.linear_solver, model.dofs(), model.multipliers())));
  summary.adaptive = settings.adaptive;
  if (TraitsOf(settings.integrator).has_rho_infinity)
    summary.rho_infinity = settings.rho_infinity;
  const bool estimate = settings.analysis == Analysis::kDynamic && settings.error_estimate;
  // output.statistics, output.rainflow: a sink in front of the caller's
  // (none otherwise, so that a run without them costs nothing more).
  std::unique_ptr<StatisticsSink> statistics;
  if (WantsStatistics(scene.output) && settings.analysis != Analysis::kModal) {
    statistics = std::make_unique<StatisticsSink>(sink, scene.output);
    sink = statistics.get();
  }
  ProbeRecordingSink recording(sink);
  FrameSink* out = estimate ? &recording : sink;
  if (absl::Status s = out->OnStart(summary.info); !s.ok()) return s;
  FrameRecorder recorder(&model, out, &summary);
  // The stop request is also asked inside a step (StopPoll): a step of a
  // costly scene (many wave components) ends within about a millisecond
  // of work after it.
  StopPoll poll(control.should_stop);
  model.set_stop_poll(&poll);
  if (settings.analysis == Analysis::kStatic) {
    RunStatic(&model, settings, control, &recorder, &summary);
  } else if (settings.analysis == Analysis::kModal) {
    RunModalAnalysis(&model, settings, modes, control, sink, &summary);
  } else if (settings.initial_state == InitialState::kStatic &&
             !StartFromEquilibrium(&model, settings, control, &summary)) {
    // The summary says why; no frame was delivered.
  } else {
    // Line failure: only a scene that asks for it holds a JointRelease.
    std::unique_ptr<JointRelease> release;
    if (JointRelease::Wanted(scene)) release = std::make_unique<JointRelease>(scene);
    RunDynamic(&model, settings, control, &recorder, &summary, release.get());
    if (!std::isfinite(summary.min_step_s)) summary.min_step_s = 0;
    if (estimate) {
      if (summary.status == "ok") {
        EstimateError(&model, settings, control, recording, &summary, release.get());
      } else {
        summary.has_error_estimate = true;
        summary.error_estimate_method = "none: the run did not finish";
      }
    }
  }
  model.set_stop_poll(nullptr);
  // A step (or load increment, or the initial solve) cut short by the
  // stop request failed for that reason alone.
  if (poll.stopped() && summary.status != "cancelled") {
    summary.status = "cancelled";
    summary.error = "stopped by the caller during a step";
  }
  if (statistics != nullptr) {
    summary.has_statistics = true;
    summary.statistics = statistics->Finish();
  }
  if (settings.analysis == Analysis::kDynamic)
    summary.energy_dissipated =
        summary.energy_initial - summary.energy_final - summary.energy_damped;
  AddRunWarnings(settings, &summary);
  summary.wall_seconds =
      p.build_seconds + std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

}  // namespace cablesim
