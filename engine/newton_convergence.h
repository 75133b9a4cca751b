#ifndef CABLESIM_ENGINE_NEWTON_CONVERGENCE_H_
#define CABLESIM_ENGINE_NEWTON_CONVERGENCE_H_

// Newton's acceptance test, shared by every stepper. An iterate is accepted
// when the constraints hold to tol (1 + |z|_inf) and either
//   - the relative momentum residual is below tol plus the rounding floor of
//     the elastic forces (MultibodyModel::force_roundoff over the residual's
//     scale), or
//   - the last correction moved z only in its last bits (16 eps (1 + |z|))
//     or by a thousandth of the tolerance, so Newton cannot usefully improve
//     the state, and the residual left (the rounding of the forces: short,
//     stiff elements far from the origin, eps |x| / l amplified by EA) is
//     still below sqrt(tol).
// The caller also requires that the last increment was already below
// tol (1 + |z|) before it checks (its "checking" iteration).

#include <cmath>
#include <string>

#include "absl/strings/str_format.h"
#include "engine/saddle_point_solver.h"
#include "engine/scene.h"

namespace cablesim {

struct NewtonIterate {
  double last_increment = 0;  // |dz|_inf of the last correction [m]
  double zscale = 1;          // 1 + |z|_inf
  double residual = 0;        // momentum residual relative to its largest term
  double floor = 0;           // rounding floor of that relative residual
  double violation = 0;       // |Phi|_inf
};

inline bool NewtonConverged(const NewtonIterate& it, double tol) {
  constexpr double kRoundingIncrement = 16 * 2.220446049250313e-16;
  const bool at_rounding =
      it.last_increment <= std::max(kRoundingIncrement, 1e-3 * tol) * it.zscale &&
      it.residual <= std::sqrt(tol);
  return (it.residual <= tol + it.floor || at_rounding) && it.violation <= tol * it.zscale;
}

inline std::string NewtonFailure(int iterations, const NewtonIterate& it) {
  return absl::StrFormat(
      "Newton did not converge in %d iterations (position increment %.3g m, relative residual "
      "%.3g, constraint violation %.3g)",
      iterations, it.last_increment, it.residual, it.violation);
}

// A Newton step needs its linear solve to this true relative residual: an
// inexact solve still gives a descent direction, a bad one does not.
constexpr double kMaxLinearResidual = 1e-6;

inline bool LinearSolveGoodEnough(const SaddlePointSolver::Stats& ls) {
  return ls.relative_residual <= kMaxLinearResidual;
}

inline std::string LinearSolveFailure(const SaddlePointSolver::Stats& ls,
                                      LinearSolverKind requested) {
  return absl::StrFormat(
      "the %s solve did not converge (true relative residual %.3g after %d iterations)",
      ls.direct                                 ? "direct"
      : requested == LinearSolverKind::kGmres ? "GMRES"
                                              : "MINRES",
      ls.relative_residual, ls.iterations);
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_NEWTON_CONVERGENCE_H_
