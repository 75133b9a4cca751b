#ifndef CABLESIM_ENGINE_STEPPERS_NEWTON_CONVERGENCE_H_
#define CABLESIM_ENGINE_STEPPERS_NEWTON_CONVERGENCE_H_

// Newton's acceptance test, shared by every stepper and by statics.
//
// An iterate is accepted when its last correction was already below
// tol (1 + |z|_inf) (the caller's "checking" iteration), the constraints
// hold to tol (1 + |z|_inf), and either
//   - the momentum residual is below tol times its scale (the largest term
//     summed into it), or
//   - Newton can do no more: the last correction moved z only in its last
//     bits (kRoundingIncrement (1 + |z|_inf)), or was computed from a
//     residual already at its floor (rounding alone drove it), or was not
//     even half the one before (Newton converges at least linearly until
//     rounding stops it), and every entry of the residual is within tol times its scale of its
//     rounding floor: |r_i| <= tol * scale + floor_i.
// floor_i bounds what double precision leaves in r_i whatever Newton does:
// the forces are computed from coordinates known only to eps |q| (for a
// short stiff element far from the origin that is EA eps |r| / l of force,
// MultibodyModel::NetForce's `roundoff`), plus eps times every term summed
// into the entry. A residual above its floor is never accepted; there is
// no other shortcut. The floor is a bound (sums of absolute values): the
// residuals Newton stalls at were measured 10 to 200 times below it on the
// 10 m steel cable of 100 to 10,000 elements.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "absl/strings/str_format.h"
#include "engine/linear/rounding.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"

namespace cablesim {

struct NewtonIterate {
  double last_increment = 0;  // |dz|_inf of the last correction [m]
  double previous_increment = 0;  // and of the one before (0: none)
  // Whether the previous iterate's residual was already at its floor, so
  // that the last correction was driven by rounding alone.
  bool previous_at_floor = false;
  double zscale = 1;          // 1 + |z|_inf
  double residual = 0;        // |r|_inf relative to the residual's scale
  double floor = 0;           // max_i floor_i, relative to the same scale
  double excess = 0;          // max_i (|r_i| - floor_i)+, relative
  double violation = 0;       // |Phi|_inf
};

// Fills residual, floor and excess of `it` from the residual r, its
// per-entry rounding floor and the scale (largest term summed into r).
template <typename R, typename F>
void MeasureResidual(const R& r, const F& floor, double scale, NewtonIterate* it) {
  double worst = 0, excess = 0, top = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    const double a = std::abs(r[i]);
    worst = std::max(worst, a);
    top = std::max(top, floor[i]);
    excess = std::max(excess, a - floor[i]);
  }
  it->residual = worst / scale;
  it->floor = top / scale;
  it->excess = excess / scale;
}

// A correction below this times (1 + |z|_inf) changes z only in its last
// few bits (16 machine epsilons).
constexpr double kRoundingIncrement = 16 * 2.220446049250313e-16;

// Starts a stepper's Newton iterate: the increments so far, zscale from
// z1, the residual r relative to `scale` and the largest constraint value
// of phi (0 without constraints). False when either is not finite (the
// step diverged: kNotFiniteResidual says so).
template <typename R>
bool BeginIterate(const R& r, double scale, const Eigen::VectorXd& phi,
                  const Eigen::VectorXd& z1, double last_increment, double previous_increment,
                  bool previous_at_floor, NewtonIterate* it) {
  it->last_increment = last_increment;
  it->previous_increment = previous_increment;
  it->zscale = 1 + z1.lpNorm<Eigen::Infinity>();
  // The largest entries, NaN if any entry is NaN: lpNorm<Infinity>'s
  // vectorised max may drop a NaN entry, and the step would go on to fail
  // later in the linear solve, its source unnamed. The sum, also one
  // vectorised pass, never drops one (Eigen's NaN-propagating max is a
  // scalar loop: 0.5 % of a pendulum run). The same value otherwise.
  const auto largest = [](const auto& x) -> double {
    if (x.size() == 0) return 0.0;
    const double m = x.template lpNorm<Eigen::Infinity>();
    return std::isnan(x.sum()) ? std::numeric_limits<double>::quiet_NaN() : m;
  };
  it->residual = largest(r) / scale;
  it->violation = largest(phi);
  it->previous_at_floor = previous_at_floor;
  return std::isfinite(it->residual) && std::isfinite(it->violation);
}
inline constexpr char kNotFiniteResidual[] = "the residual is not finite (the step diverged)";

inline bool NewtonConverged(const NewtonIterate& it, double tol) {
  const bool stalled = it.last_increment <= kRoundingIncrement * it.zscale ||
                       it.previous_at_floor ||
                       (it.previous_increment > 0 && it.last_increment > 0.5 * it.previous_increment);
  const bool at_floor = stalled && it.excess <= tol;
  return (it.residual <= tol || at_floor) && it.violation <= tol * it.zscale;
}

inline std::string NewtonFailure(int iterations, const NewtonIterate& it) {
  return absl::StrFormat(
      "Newton did not converge in %d iterations (position increment %.3g m, relative residual "
      "%.3g with a rounding floor of %.3g, constraint violation %.3g)",
      iterations, it.last_increment, it.residual, it.floor, it.violation);
}

// A Newton step needs its linear solve to this true relative residual: an
// inexact solve still gives a descent direction, a bad one does not.
constexpr double kMaxLinearResidual = 1e-6;

// A solve above that residual (a Krylov solve stopped by max_linear_iterations)
// is inexact: refused unless solver.accept_inexact_solves (then it must at
// least be finite), and counted either way.
inline bool LinearSolveInexact(const SaddlePointSolver::Stats& ls) {
  return !(ls.relative_residual <= kMaxLinearResidual);
}

inline bool LinearSolveGoodEnough(const SaddlePointSolver::Stats& ls) {
  return !LinearSolveInexact(ls) || (ls.accept_inexact && std::isfinite(ls.relative_residual));
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

#endif  // CABLESIM_ENGINE_STEPPERS_NEWTON_CONVERGENCE_H_
