#include "engine/simulation.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "absl/strings/str_format.h"
#include "engine/implicit_euler_stepper.h"
#include "engine/modal_solver.h"
#include "engine/multibody_model.h"
#include "engine/static_solver.h"

namespace cablesim {
namespace {

using Clock = std::chrono::steady_clock;

// Tracks the frame-level quantities of the summary.
class FrameRecorder {
 public:
  FrameRecorder(MultibodyModel* model, FrameSink* sink, RunSummary* summary)
      : model_(model), sink_(sink), summary_(summary) {
    q_.setZero(model->coordinates());
    qd_.setZero(model->coordinates());
    qdd_.setZero(model->coordinates());
    phi_.setZero(model->multipliers());
  }

  absl::Status Emit(double t, double load_factor, const Eigen::VectorXd& z,
                    const Eigen::VectorXd* v, const Eigen::VectorXd* a) {
    model_->ToFull(z, &q_);
    if (v) model_->RateToFull(*v, &qd_);
    if (a) model_->RateToFull(*a, &qdd_);
    frame_.t = t;
    model_->Probes(q_, qd_, qdd_, &frame_.probes);
    frame_.energy = model_->Energy(q_, qd_, load_factor);
    frame_.angular_momentum = model_->AngularMomentum(q_, qd_);
    model_->Constraints(q_, &phi_, nullptr);
    frame_.constraint_violation = phi_.size() ? phi_.lpNorm<Eigen::Infinity>() : 0.0;
    if (summary_->frames == 0) summary_->energy_initial = frame_.energy.total;
    summary_->energy_final = frame_.energy.total;
    summary_->energy_max_increase =
        std::max(summary_->energy_max_increase, frame_.energy.total - summary_->energy_initial);
    summary_->max_constraint_violation =
        std::max(summary_->max_constraint_violation, frame_.constraint_violation);
    ++summary_->frames;
    return sink_->OnFrame(frame_);
  }

 private:
  MultibodyModel* model_;
  FrameSink* sink_;
  RunSummary* summary_;
  Frame frame_;
  Eigen::VectorXd q_, qd_, qdd_, phi_;
};

// Sums the work of torque loads over accepted steps, for the energy
// balance (MultibodyModel::AccumulateTorqueWork); nothing without torques.
class TorqueWork {
 public:
  explicit TorqueWork(MultibodyModel* model) : model_(model) {
    if (!model->has_torques()) return;
    before_.setZero(model->coordinates());
    after_.setZero(model->coordinates());
  }
  void Before(const Eigen::VectorXd& z) {
    if (model_->has_torques()) model_->ToFull(z, &before_);
  }
  void After(const Eigen::VectorXd& z, double load_factor) {
    if (!model_->has_torques()) return;
    model_->ToFull(z, &after_);
    model_->AccumulateTorqueWork(before_, after_, load_factor);
  }

 private:
  MultibodyModel* model_;
  Eigen::VectorXd before_, after_;
};

void Fail(RunSummary* s, double t, const std::string& reason) {
  s->status = "failed";
  s->failure_time_s = t;
  s->error = reason;
}

// Checks the caller's stop request and step limit before a step attempt;
// false (with the summary filled in) means stop now.
bool MayStep(const RunControl& control, double t, RunSummary* s) {
  if (control.should_stop && control.should_stop()) {
    s->status = "cancelled";
    s->error = absl::StrFormat("stopped by the caller at t = %.9g", t);
    return false;
  }
  if (control.max_steps > 0 && s->steps + s->rejected_steps >= control.max_steps) {
    Fail(s, t, absl::StrFormat("step limit of %d step attempts reached at t = %.9g",
                               control.max_steps, t));
    return false;
  }
  return true;
}

void RunDynamic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
                FrameRecorder* rec, RunSummary* summary) {
  ImplicitEulerStepper stepper(model, settings);
  std::string reason;
  if (!stepper.Initialize(&reason)) {
    Fail(summary, 0, reason);
    return;
  }
  if (absl::Status s = rec->Emit(0, 1, stepper.z(), &stepper.v(), &stepper.a()); !s.ok()) {
    summary->status = "cancelled";
    summary->error = std::string(s.message());
    return;
  }
  TorqueWork torque_work(model);
  const double h_nominal = settings.step_s;
  const double h_min = std::ldexp(h_nominal, -settings.max_step_halvings);
  const double interval =
      settings.output_interval_s > 0 ? settings.output_interval_s : settings.step_s;
  const double duration = settings.duration_s;
  const long frames = std::max(1L, std::lround(std::ceil(duration / interval - 1e-9)));
  double t = 0;
  double h = h_nominal;
  int successes = 0;
  summary->min_step_s = h_nominal;
  for (long k = 1; k <= frames; ++k) {
    const double t_frame = std::min(duration, k * interval);
    while (t_frame - t > 1e-12 * std::max(1.0, t_frame)) {
      if (!MayStep(control, t, summary)) return;
      const double remaining = t_frame - t;
      const double substeps = std::ceil(remaining / h - 1e-9);
      const double h_try = remaining / substeps;
      torque_work.Before(stepper.z());
      const auto st = stepper.Step(h_try);
      summary->newton_iterations += st.newton_iterations;
      summary->linear_iterations += st.linear_iterations;
      summary->max_linear_residual = std::max(summary->max_linear_residual, st.max_linear_residual);
      if (st.converged) {
        t += h_try;
        torque_work.After(stepper.z(), 1);
        ++summary->steps;
        summary->min_step_s = std::min(summary->min_step_s, h_try);
        summary->max_newton_residual = std::max(summary->max_newton_residual, st.residual);
        summary->end_time_s = t;
        // After a run of good steps, go back up towards the nominal step.
        if (h < h_nominal && ++successes >= 4) {
          h = std::min(h_nominal, 2 * h);
          successes = 0;
        }
        continue;
      }
      ++summary->rejected_steps;
      successes = 0;
      h = h_try / 2;
      if (h < h_min * (1 - 1e-12)) {
        Fail(summary, t + h_try,
             absl::StrFormat("step from t = %.9g s failed %d times down to h = %.3g s: %s", t,
                             settings.max_step_halvings + 1, h_try, st.reason));
        return;
      }
    }
    t = t_frame;
    if (absl::Status s = rec->Emit(t, 1, stepper.z(), &stepper.v(), &stepper.a()); !s.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(s.message());
      return;
    }
  }
}

void RunStatic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
               FrameRecorder* rec, RunSummary* summary) {
  StaticSolver solver(model, settings);
  TorqueWork torque_work(model);
  const int n = settings.load_steps;
  const double min_increment = std::ldexp(1.0 / n, -settings.max_step_halvings);
  double alpha = 0;
  for (int k = 1; k <= n; ++k) {
    const double target = static_cast<double>(k) / n;
    double d = target - alpha;
    while (target - alpha > 1e-12) {
      if (!MayStep(control, alpha, summary)) return;
      d = std::min(d, target - alpha);
      torque_work.Before(solver.z());
      const auto st = solver.Solve(alpha + d);
      summary->newton_iterations += st.newton_iterations;
      summary->linear_iterations += st.linear_iterations;
      summary->max_linear_residual = std::max(summary->max_linear_residual, st.max_linear_residual);
      if (st.converged) {
        alpha += d;
        torque_work.After(solver.z(), alpha);
        ++summary->steps;
        summary->max_newton_residual = std::max(summary->max_newton_residual, st.residual);
        summary->end_time_s = alpha;
        continue;
      }
      ++summary->rejected_steps;
      d /= 2;
      if (d < min_increment * (1 - 1e-12)) {
        Fail(summary, alpha,
             absl::StrFormat("load increment from load factor %.6g failed after %d bisections: %s",
                             alpha, settings.max_step_halvings, st.reason));
        return;
      }
    }
    alpha = target;
    if (absl::Status s = rec->Emit(alpha, alpha, solver.z(), nullptr, nullptr); !s.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(s.message());
      return;
    }
  }
}

}  // namespace

absl::StatusOr<ModelInfo> DescribeModel(const Scene& scene) {
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene);
  if (!built.ok()) return built.status();
  if (scene.solver.analysis == Analysis::kModal) {
    if (absl::StatusOr<int> modes = ModalSolver::ModeCount(*built, scene.solver); !modes.ok())
      return modes.status();
  }
  return built->Info();
}

absl::StatusOr<RunSummary> RunScene(const Scene& scene, FrameSink* sink,
                                    const RunControl& control) {
  const auto start = Clock::now();
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene);
  if (!built.ok()) return built.status();
  MultibodyModel& model = *built;
  RunSummary summary;
  summary.info = model.Info();
  const SolverSettings& settings = scene.solver;
  summary.analysis = settings.analysis == Analysis::kStatic  ? "STATIC"
                     : settings.analysis == Analysis::kModal ? "MODAL"
                                                             : "DYNAMIC";
  int modes = 0;
  if (settings.analysis == Analysis::kModal) {
    absl::StatusOr<int> count = ModalSolver::ModeCount(model, settings);
    if (!count.ok()) return count.status();
    modes = *count;
  }
  summary.integrator = "IMPLICIT_EULER";
  summary.linear_solver = settings.linear_solver == LinearSolverKind::kGmres ? "GMRES" : "MINRES";
  if (absl::Status s = sink->OnStart(summary.info); !s.ok()) return s;
  FrameRecorder recorder(&model, sink, &summary);
  if (settings.analysis == Analysis::kStatic) {
    RunStatic(&model, settings, control, &recorder, &summary);
  } else if (settings.analysis == Analysis::kModal) {
    RunModalAnalysis(&model, settings, modes, control, sink, &summary);
  } else {
    RunDynamic(&model, settings, control, &recorder, &summary);
  }
  if (settings.analysis == Analysis::kDynamic)
    summary.energy_dissipated = summary.energy_initial - summary.energy_final;
  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

}  // namespace cablesim
