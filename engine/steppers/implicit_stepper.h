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
// The Newton helpers shared with the schemes (SolveInitialAcceleration,
// FactorNewtonMatrix, SolveNewtonSystem, SolveWithFreshRetry) are in
// stepper.h.

#include <string>

#include <Eigen/Core>

#include "engine/linear/saddle_point_solver.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

class ImplicitStepper : public Stepper {
 public:
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
  // The scheme's own history back to before the last step (Restore()).
  virtual void RestoreScheme() {}

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
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_IMPLICIT_STEPPER_H_
