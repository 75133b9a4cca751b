#include "engine/run/static_run.h"

#include <algorithm>
#include <string>

#include "engine/analysis/static_solver.h"
#include "engine/run/external_work.h"

namespace cablesim {

void RunStatic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
               FrameRecorder* rec, RunSummary* summary) {
  StaticSolver solver(model, settings);
  // Statics is the equilibrium at t = 0: moving supports at their start,
  // time-varying loads at their value there (scaled by the load factor);
  // viscoelastic lines at their static EA.
  model->RelaxViscoelastic();
  model->SetTime(0);
  ExternalWork external_work(model);
  auto on_increment = [&](const Eigen::VectorXd& z0, const Eigen::VectorXd& z1, double alpha) {
    // Moving supports do not move at t = 0: their work is 0 (lambda unused).
    external_work.Before(z0, 0, solver.lambda());
    external_work.After(z1, 0, solver.lambda(), alpha);
  };
  auto on_target = [&](double alpha) {
    if (absl::Status s = rec->Emit(alpha, alpha, solver.z(), nullptr, nullptr, &solver.lambda());
        !s.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(s.message());
      return false;
    }
    return true;
  };
  FollowLoadPath(&solver, settings, control, summary, "", on_increment, on_target);
}

bool StartFromEquilibrium(MultibodyModel* model, const SolverSettings& settings,
                          const RunControl& control, RunSummary* summary) {
  SolverSettings statics = settings;
  statics.analysis = Analysis::kStatic;
  statics.newton_tolerance = std::min(settings.newton_tolerance, 1e-12);
  model->RelaxViscoelastic();  // viscoelastic lines at their static EA
  StaticSolver solver(model, statics);
  RunSummary path;
  const bool ok = FollowLoadPath(&solver, statics, control, &path,
                                 "solver.initial_state STATIC: ", nullptr, nullptr);
  summary->newton_iterations += path.newton_iterations;
  summary->linear_iterations += path.linear_iterations;
  summary->max_linear_residual = std::max(summary->max_linear_residual, path.max_linear_residual);
  summary->max_residual_floor = std::max(summary->max_residual_floor, path.max_residual_floor);
  if (!ok) {
    summary->status = path.status;
    summary->error = path.error;
    summary->failure_time_s = 0;
    return false;
  }
  model->SetInitialState(solver.z());
  return true;
}

}  // namespace cablesim
