#include "engine/steppers/stepper.h"

#include <algorithm>

#include "absl/strings/str_format.h"
#include "engine/steppers/newton_convergence.h"

namespace cablesim {

bool SolveInitialAcceleration(SaddlePointSolver* solver, const SolverSettings& settings,
                              const Eigen::VectorXd& f, const Eigen::VectorXd& gamma,
                              Eigen::VectorXd* rhs, Eigen::VectorXd* dx, std::string* reason) {
  if (!solver->Prepare()) {
    *reason = "the mass matrix could not be factorized";
    return false;
  }
  const Eigen::Index n = f.size();
  rhs->head(n) = f;
  if (gamma.size() > 0) rhs->tail(gamma.size()) = gamma;
  const auto stats = solver->Solve(settings.linear_solver, *rhs, 1e-12,
                                   std::max(settings.max_linear_iterations, 1000), dx);
  if (!(stats.relative_residual <= 1e-8)) {
    *reason = absl::StrFormat(
        "the initial acceleration solve did not converge (relative residual %.3g)",
        stats.relative_residual);
    return false;
  }
  return true;
}

bool FactorNewtonMatrix(SaddlePointSolver* solver, const SparseRows& jac, double c,
                        KeptNewtonMatrix* kept, Stepper::StepStats* st) {
  std::copy(jac.value.begin(), jac.value.end(), solver->b().value.begin());
  ++st->factorizations;
  kept->have = false;
  if (!solver->Prepare()) {
    st->reason = "the Newton matrix has a non-finite pivot";
    return false;
  }
  kept->have = true;
  kept->c = c;
  kept->refresh = false;
  return true;
}

bool SolveNewtonSystem(SaddlePointSolver* solver, const SolverSettings& settings,
                       Eigen::VectorXd* rhs, Eigen::VectorXd* dx, Stepper::StepStats* st) {
  *rhs = -*rhs;
  const auto ls = solver->Solve(settings.linear_solver, *rhs, settings.linear_tolerance,
                                settings.max_linear_iterations, dx);
  ++st->newton_iterations;
  ++st->linear_solves;
  st->linear_iterations += ls.iterations;
  st->max_linear_residual = std::max(st->max_linear_residual, ls.relative_residual);
  st->direct_fallbacks += ls.fallback ? 1 : 0;
  st->inexact_solves += LinearSolveInexact(ls) ? 1 : 0;
  if (!LinearSolveGoodEnough(ls)) {
    st->reason = LinearSolveFailure(ls, settings.linear_solver);
    return false;
  }
  return true;
}

void AddFailedAttempt(const Stepper::StepStats& first, Stepper::StepStats* retry) {
  retry->newton_iterations += first.newton_iterations;
  retry->linear_iterations += first.linear_iterations;
  retry->factorizations += first.factorizations;
  retry->direct_fallbacks += first.direct_fallbacks;
  retry->linear_solves += first.linear_solves;
  retry->inexact_solves += first.inexact_solves;
  retry->max_linear_residual = std::max(retry->max_linear_residual, first.max_linear_residual);
}

}  // namespace cablesim
