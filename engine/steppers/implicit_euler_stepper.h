#ifndef CABLESIM_ENGINE_STEPPERS_IMPLICIT_EULER_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_IMPLICIT_EULER_STEPPER_H_

// The paper's stepper (docs/model.md section 4): backward Euler on the index-3
// equations of motion,
//
//   v1 = v0 + h a1,   z1 = z0 + h v1,
//   M (v1 - v0) + h (Q_k(z1) - Q_a(z1) + C(z1) v1) + Phi_z(z1)^T mu = 0,
//   mu = h lambda,   Phi(z1) / h = 0,
//
// solved by Newton on (v1, mu) from the predictor v1 = v0 + h a0. Each Newton
// step solves the symmetric saddle-point system
//
//   [ M + h C + h^2 (K_T + H_lambda)   Phi_z^T ] [dv ]     [ R_v ]
//   [ Phi_z                            0       ] [dmu] = - [ R_c ]
//
// (C the damping matrix, MultibodyModel::DampingForce; absent without
// damping) with MINRES (or GMRES) under SaddlePointSolver's preconditioner. Newton
// stops when the position increment h |dv|_inf is below
// tol (1 + |z|_inf), the momentum residual below tol times its largest term
// and |Phi|_inf below tol (1 + |z|_inf) (a residual left above tol while the
// corrections move z only in its last bits, 16 eps (1 + |z|), or by less
// than tol / 1000 (1 + |z|), is the
// rounding floor of the forces and is accepted when below sqrt(tol));
// otherwise the step is reported as not converged and the caller retries with a smaller step. Nothing is
// accepted silently.
//
// Backward Euler is first order and removes energy at high frequencies;
// simulation.cc reports how much.
//
// Local error (for adaptive steps): against the second-order update
// z0 + h (v0 + v1) / 2, backward Euler's position is off by
// h (v1 - v0) / 2 = h^2 a1 / 2, the estimate LocalErrorNorm() uses.
//
// Step() allocates nothing.

#include <string>

#include <Eigen/Core>

#include "engine/model/multibody_model.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"
#include "engine/steppers/implicit_stepper.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

class ImplicitEulerStepper final : public ImplicitStepper {
 public:
  ImplicitEulerStepper(MultibodyModel* model, const SolverSettings& settings);

  bool Initialize(std::string* reason) override;
  StepStats Step(double h) override;
  double LocalErrorNorm(double h, double atol, double rtol) const override;

 private:
  // f = f(q_, v) (elastic, applied and damping forces: the damping's
  // velocity is v) and, when `a` is not null, h^2 K_T + h C added to it;
  // the force size (NetForce, DampingForce).
  double Forces(const Eigen::VectorXd& v, Eigen::VectorXd* f, SkylineLdlt* a, double h,
                Eigen::VectorXd* roundoff);
  // a = M + h^2 K_T(q_) + h C and f_ = f(q_, v1_) in one pass; returns the
  // force size.
  double AssembleForces(double h);

  // Newton's hooks (ImplicitStepper::Newton): the unknowns are v1_ and
  // mu = h lambda1_.
  void PlaceIterate() override;
  double EvaluateResidual(bool assemble, bool with_floor) override;
  void ComputeFloor(bool with_floor) override;
  bool FactorMatrix(bool assembled, StepStats* st) override;
  double ApplyCorrection() override;
  const Eigen::VectorXd& IterateVelocity() const override { return v1_; }

  // Newton work vectors (the state and the rounding floor's are
  // ImplicitStepper's). Each step sets the model's time to its end
  // (prescribed motions and varying loads at t_{n+1}, where backward Euler
  // imposes Phi(z_{n+1}, t_{n+1}) = 0).
  Eigen::VectorXd v1_, q_, qd_, f_, mdv_, bt_mu_;
  double h_ = 0;  // the step being taken [s]
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_IMPLICIT_EULER_STEPPER_H_
