#ifndef CABLESIM_ENGINE_STEPPERS_IMPLICIT_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_IMPLICIT_STEPPER_H_

// What every implicit stepper (backward Euler, generalized-alpha and HHT,
// energy-momentum) keeps: the state (z, v = dz/dt, a = d2z/dt2, lambda) and
// the state before the last step for Restore(), the time, the saddle-point
// solver of its Newton systems (configured from the scene's
// preconditioner and accept_inexact_solves), the residual's rounding floor
// work vectors (newton_convergence.h), the last two step sizes and the
// Newton matrix kept across iterations (KeptNewtonMatrix). A scheme adds
// its own history (generalized-alpha's a_n and g_n, energy-momentum's mean
// acceleration) and restores it in RestoreScheme().
//
// Newton's iteration is written once, Newton() below: each iteration
// places the iterate (PlaceIterate), evaluates the residual and, when it
// starts a fresh matrix, assembles it in the same pass (EvaluateResidual),
// judges convergence against the residual's rounding floor (ComputeFloor,
// newton_convergence.h), assembles and factors the Newton matrix when it is
// not kept (FactorMatrix), solves and applies the correction
// (ApplyCorrection), and refuses a diverging one. A scheme supplies those
// hooks, its predictor before Newton() and its update after it. The other
// Newton helpers (SolveInitialAcceleration, FactorNewtonMatrix,
// SolveNewtonSystem, SolveWithFreshRetry) are in stepper.h.

#include <string>

#include <Eigen/Core>

#include "engine/linear/saddle_point_solver.h"
#include "engine/linear/sparse_rows.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

class ImplicitStepper : public Stepper {
 public:
  // Newton with a fresh matrix every iteration finishes on the last
  // factored one once its correction shrank kFinishRatio times against the
  // one before and is below kFinishNear times the convergence test's
  // tol (1 + |z|_inf) (Newton() says why and what it saves), in the
  // schemes that set finish_on_last_matrix_ (generalized-alpha and HHT;
  // energy-momentum diverged with it on the 100 s falling pendulum).
  static constexpr double kFinishRatio = 0.1;
  static constexpr double kFinishNear = 100;

  void Restore() final;

  const Eigen::VectorXd& z() const final { return z_; }
  const Eigen::VectorXd& v() const final { return v_; }
  const Eigen::VectorXd& a() const final { return a_; }
  const Eigen::VectorXd& lambda() const final { return lambda_; }

 protected:
  ImplicitStepper(MultibodyModel* model, const SolverSettings& settings);

  // The Newton matrix's block a = M.
  void LoadMass();
  // After Initialize() has set a_ and lambda_: they are also the state
  // before the (not yet taken) first step.
  void KeepInitialState();
  // Before a converged step's state replaces the current one: the current
  // z, v, a and lambda become the state Restore() returns to (swaps, no
  // copies: the caller then writes the new state into z_, v_, a_, lambda_).
  void KeepPreviousState();
  // Whether Newton() may finish a fresh-matrix solve on its last factored
  // matrix (kFinishRatio). Off unless the scheme turns it on.
  bool finish_on_last_matrix_ = false;
  // The scheme's own history back to before the last step (Restore()).
  virtual void RestoreScheme() {}

  // One Newton solve from the scheme's predictor: iterates until
  // NewtonConverged (st.converged, the iterate left in the scheme's
  // unknowns) or fails (st.reason). `fresh`: assemble and factor the Newton
  // matrix at the first iteration; `reuse` (solver.reuse_factorization):
  // keep it across iterations, refreshed when an increment shrinks by less
  // than half, and mark kept_ for refresh when the solve fails.
  StepStats Newton(bool fresh, bool reuse);

  // Newton's hooks, called in this order each iteration.
  // Sets z1_ (and the full coordinates the residual needs) from the
  // scheme's unknowns.
  virtual void PlaceIterate() = 0;
  // The residual: its momentum rows into rhs_.head(n_), the constraint rows
  // into rhs_.tail(m_) and Phi into phi_; returns the residual's scale (its
  // largest term). `assemble`: also load the Newton matrix's mass and force
  // parts into solver_.a() in the same pass; `with_floor`: also the forces'
  // rounding bound into floor_ (ComputeFloor then completes it).
  virtual double EvaluateResidual(bool assemble, bool with_floor) = 0;
  // The residual's rounding floor per unknown into floor_; `with_floor`: the
  // forces' part is already there (from EvaluateResidual).
  virtual void ComputeFloor(bool with_floor) = 0;
  // Completes the Newton matrix (its mass and force parts too unless
  // `assembled` by EvaluateResidual) and factors it, counted in `st`; false
  // with st->reason on a non-finite pivot.
  virtual bool FactorMatrix(bool assembled, StepStats* st) = 0;
  // Applies the correction dx_ to the unknowns; returns the position
  // increment |dz|_inf it makes [m].
  virtual double ApplyCorrection() = 0;
  // The velocity the forces of the iterate were evaluated with (for the
  // failure message of a non-finite residual only).
  virtual const Eigen::VectorXd& IterateVelocity() const { return v_; }
  // kNotFiniteResidual, with the force term and the place the non-finite
  // value came from (MultibodyModel::DescribeNonFinite at the iterate):
  // evaluated on this failure path only.
  std::string NotFiniteReason() const;
  // Whether an iteration that judges convergence only because it is the
  // last one (not a checking iteration) also takes the forces' rounding
  // bound in the force pass (generalized-alpha does).
  bool floor_with_forces_when_judged_ = false;

  // The momentum residual of the schemes on (v1, mu = h lambda1), backward
  // Euler and energy-momentum: R_v = M (v1 - v0) - h f + jac^T (h lambda1)
  // into rhs_.head(n_) (mdv and bt_mu are scratch); returns its scale, the
  // largest of its terms (force_size: f's, NetForce).
  double VelocityResidual(const Eigen::VectorXd& v1, const Eigen::VectorXd& f, double force_size,
                          const SparseRows& jac, double h, Eigen::VectorXd* mdv,
                          Eigen::VectorXd* bt_mu);
  // Its rounding floor: floor_ (holding the forces' rounding bound) becomes
  // h floor_ + the rounding of the other terms summed into R_v (M v1, M v0
  // and h jac^T lambda1).
  void VelocityResidualFloor(const Eigen::VectorXd& v1, const SparseRows& jac, double h);

  MultibodyModel* model_;
  SolverSettings settings_;
  SaddlePointSolver solver_;
  int n_ = 0, m_ = 0;
  Eigen::VectorXd z_, v_, a_, lambda_;
  Eigen::VectorXd z_old_, v_old_, a_old_, lambda_old_;  // before the last step
  // Time [s] of the state, and before the last step.
  double t_ = 0, t_old_ = 0;
  // The last step [s] (0: none yet) and the one before.
  double h_last_ = 0, h_old_ = 0;
  // Newton's right-hand side and correction (n + m).
  Eigen::VectorXd rhs_, dx_;
  // The residual's rounding floor per unknown, and the terms summed into it.
  Eigen::VectorXd floor_, abs_terms_, f_floor_;
  // Whether the last accepted step needed the floor (its residual was above
  // tol): the next step's checking iteration then bounds the forces'
  // rounding in the same pass as the forces.
  bool floor_expected_ = false;
  KeptNewtonMatrix kept_;
  // The Newton iterate's positions z_{n+1}, multipliers and Phi(z_{n+1}).
  Eigen::VectorXd z1_, lambda1_, phi_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_IMPLICIT_STEPPER_H_
