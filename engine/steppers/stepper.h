#ifndef CABLESIM_ENGINE_STEPPERS_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_STEPPER_H_

// What the dynamic run loop (simulation.cc) needs from a time stepper:
// consistent start, one step of size h [s] that either converges or leaves
// the state unchanged, a local error estimate for adaptive steps, and a way
// to take back the last accepted step when that estimate rejects it.
//
// The state is on the model's unknowns z (MultibodyModel): positions and
// slopes z, their rates v = dz/dt, accelerations a = d^2z/dt^2 (the
// physical ones, satisfying the equations of motion) and the Lagrange
// multipliers lambda.
//
// Implementations: ImplicitEulerStepper (the paper's backward Euler) and
// GeneralizedAlphaStepper (generalized-alpha and HHT), EnergyMomentumStepper
// (midpoint rule with a discrete gradient). Step() allocates
// nothing.

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "engine/steppers/newton_convergence.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"

namespace cablesim {

class MultibodyModel;

// The weighted max norm of an error estimate e = k d (k >= 0 a scalar, d a
// vector expression over the first n unknowns): max_i k |d_i| / (atol +
// rtol |z_i|). With rtol = 0 (the default) it is k max_i |d_i| / atol, one
// vectorised pass with no division per unknown, and the same number to the
// last bit: rounding is monotone, so the largest |d_i| gives the largest
// quotient. (d is finite: an accepted step's accelerations are.)
template <typename Diff>
double WeightedMaxNorm(double k, const Eigen::MatrixBase<Diff>& d, const Eigen::VectorXd& z,
                       int n, double atol, double rtol) {
  if (n == 0) return 0;
  if (rtol == 0) {
    const double m = d.head(n).cwiseAbs().maxCoeff();
    return m > 0 ? k * m / atol : 0;
  }
  double worst = 0;
  for (int i = 0; i < n; ++i)
    worst = std::max(worst, k * std::abs(d(i)) / (atol + rtol * std::abs(z(i))));
  return worst;
}

class Stepper {
 public:
  struct StepStats {
    bool converged = false;
    int newton_iterations = 0;
    int linear_iterations = 0;
    int factorizations = 0;            // Newton matrices assembled and factored
    int direct_fallbacks = 0;          // DIRECT solves that had to run MINRES
    int linear_solves = 0;             // Newton-step linear solves
    int inexact_solves = 0;            // accepted above kMaxLinearResidual
    double residual = 0;               // relative momentum residual accepted
    double residual_floor = 0;         // its rounding floor (newton_convergence.h)
    double max_linear_residual = 0;    // largest true relative residual
    std::string reason;                // why it did not converge
  };

  virtual ~Stepper() = default;

  // Consistent initial acceleration from M a + Phi_z^T lambda = f,
  // Phi_z a = gamma. Returns false (with `reason`) if the solve fails.
  virtual bool Initialize(std::string* reason) = 0;

  // Advances by h, or leaves the state unchanged and returns !converged.
  virtual StepStats Step(double h) = 0;

  // Undoes the last converged Step() (once).
  virtual void Restore() = 0;

  // Estimated local error of the last converged step of size h, in the
  // weighted max norm max_i |e_i| / (atol + rtol |z_i|): <= 1 means the step
  // meets the tolerance. Units of e_i are those of z (m for positions).
  virtual double LocalErrorNorm(double h, double atol, double rtol) const = 0;

  // A stepper's orders and every other fact about it that the run loop, the
  // model builder and convert/ need: engine/scene/integrator_traits.h.

  // The largest next step [s] the stepper can take stably, from what its
  // last step saw (infinity: no limit, the implicit steppers). Adaptive
  // steps never grow beyond it: an explicit stepper's local error estimate
  // is small for a mode that grows just beyond its stability limit, so the
  // error controller alone lets such a mode grow to many tolerances first.
  virtual double stable_step() const { return std::numeric_limits<double>::infinity(); }
  // Goes on from state (z, v) at time t [s], reached by another stepper
  // (AUTO's return from a trial of HHT), keeping what was set up at the
  // start (the factored mass, the stable step). False: this stepper cannot
  // (the implicit ones, and any with constraint rows); then make a new one.
  virtual bool Restart(const Eigen::VectorXd& z, const Eigen::VectorXd& v, double t) {
    return false;
  }

  virtual const Eigen::VectorXd& z() const = 0;
  virtual const Eigen::VectorXd& v() const = 0;
  virtual const Eigen::VectorXd& a() const = 0;
  virtual const Eigen::VectorXd& lambda() const = 0;
};

// Shared pieces of the implicit steppers' Newton solves (backward Euler,
// generalized-alpha, HHT and energy-momentum).
//
// The consistent initial acceleration: with solver->a() holding M and
// solver->b() Phi_z, solves [M Phi_z^T; Phi_z 0] [a; lambda] = [f; gamma]
// into dx (rhs is scratch of size n + m). False with `reason` on failure.
bool SolveInitialAcceleration(SaddlePointSolver* solver, const SolverSettings& settings,
                              const Eigen::VectorXd& f, const Eigen::VectorXd& gamma,
                              Eigen::VectorXd* rhs, Eigen::VectorXd* dx, std::string* reason);

// The factored Newton matrix a stepper keeps across iterations and steps
// with solver.reuse_factorization: valid while its stiffness coefficient c
// (the factor of K_T in it) stays within 20 % of the current one, so that
// Newton still contracts by about that fraction (the steppers refresh it
// when an increment shrinks by less than half, and retry a failed step
// once fresh).
struct KeptNewtonMatrix {
  bool have = false;    // a factor is in the solver
  double c = 0;         // its stiffness coefficient
  bool refresh = true;  // the next step starts with a fresh one
  bool Stale(double c_now) const { return !have || !(std::abs(c_now - c) <= 0.2 * c); }
};

// Copies the constraint Jacobian `jac` into solver->b(), factors it with
// solver->a() (the Newton matrix assembled with coefficient c), records it
// in `kept` and counts it in `st`. False with st->reason on a non-finite
// pivot.
bool FactorNewtonMatrix(SaddlePointSolver* solver, const SparseRows& jac, double c,
                        KeptNewtonMatrix* kept, Stepper::StepStats* st);

// With the factor in place, solves for dx = -(Newton matrix)^-1 rhs (rhs
// negated in place) and counts the iteration and the linear statistics in
// `st`. False with st->reason when the linear solve is not good enough.
bool SolveNewtonSystem(SaddlePointSolver* solver, const SolverSettings& settings,
                       Eigen::VectorXd* rhs, Eigen::VectorXd* dx, Stepper::StepStats* st);

// Records a converged Newton iterate in the step's statistics.
inline void AcceptIterate(const NewtonIterate& it, Stepper::StepStats* st) {
  st->converged = true;
  st->residual = it.residual;
  st->residual_floor = it.floor;
}

// Adds the counts of a failed first attempt at a step to its retry's.
void AddFailedAttempt(const Stepper::StepStats& first, Stepper::StepStats* retry);

// A step's Newton solve, solve(fresh) (fresh: start with a new Newton
// matrix). With a kept matrix (`reuse`) the first attempt starts fresh only
// when `refresh`; a failure other than a non-finite pivot is then retried
// once fresh (the kept matrix may be what failed), both attempts counted.
template <typename Solve>
Stepper::StepStats SolveWithFreshRetry(bool reuse, bool refresh, Solve solve) {
  Stepper::StepStats st = solve(!reuse || refresh);
  if (!st.converged && reuse && st.reason.find("non-finite pivot") == std::string::npos) {
    Stepper::StepStats again = solve(true);
    AddFailedAttempt(st, &again);
    return again;
  }
  return st;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_STEPPER_H_
