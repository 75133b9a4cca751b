#ifndef CABLESIM_ENGINE_STEPPERS_ENERGY_MOMENTUM_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_ENERGY_MOMENTUM_STEPPER_H_

// ENERGY_MOMENTUM: the midpoint rule with the discrete gradient of the
// strain energy (Simo and Tarnow, ZAMP 43:757-792, 1992; Gonzalez,
// J. Nonlinear Sci. 6:449-467, 1996, and Comput. Methods Appl. Mech. Eng.
// 173:1-24, 1999, for the constraints). On the unknowns z with the
// constant mass matrix M, a step of size h from (z0, v0) solves
//
//   z1 - z0 = h (v0 + v1) / 2,
//   M (v1 - v0) = h [ Q_a(zm, t + h/2) - DG U(z0, z1) - C(zm) (v0 + v1) / 2
//                     - Phi_z(zm)^T lambda ],                 zm = (z0 + z1) / 2,
//   Phi(z1, t + h) = 0,
//
// U the cables' strain energy and DG U its discrete gradient
// (AncfCableElement::AddDiscreteGradientCorrection: exact for the axial
// and LINEAR bending terms, a discrete product rule for the rational
// EXACT curvature term):
// DG U . (z1 - z0) = U(z1) - U(z0). Gravity and constant loads are linear
// potentials, exact at zm. Every constraint row is at most quadratic in z
// (joints, the bodies' orthonormality rows in natural coordinates), so
// Phi_z(zm) is its exact discrete gradient: Phi_z(zm) (z1 - z0) =
// Phi(z1) - Phi(z0), and the multipliers do no work once Phi(z0) = 0.
// Dotting the momentum equation with (v0 + v1) / 2 = (z1 - z0) / h then
// gives T1 + V1 = T0 + V0 (V = U - Q_a . z) minus the damping's dissipation,
// up to the Newton residual: energy conservation without numerical
// damping at any step size. The discrete gradient is built on rotation
// invariants, so angular momentum is conserved exactly when no external
// moment acts (the midpoint rule conserves it for forces with zero moment
// about the midpoint configuration). Second order.
//
// rho_infinity is not used: convert/ rejects solver.rho_infinity for this
// stepper (no dissipative variant). With solver.reuse_factorization (off
// by default for this stepper) the factored Newton matrix below is kept
// across iterations and steps while h^2/4 stays within 20 % of its own,
// refreshed when an increment shrinks by less than half and on a failed
// step (retried once fresh). Newton then converges linearly to the same
// residual test, but stops just under it rather than far below, so the
// energy error per step is larger (measured: the 100 s falling pendulum
// drifts by 2e-5 of its energy scale with it, 5e-7 without).
//
// Newton on (v1, mu = h lambda): with dz1/dv1 = h / 2 and dzm/dv1 = h / 4,
//
//   [ M + (h/2) C + (h^2/4) (K_T(zm) + H_lambda(zm))   Phi_z(zm)^T ] [dv ]     [ R_v       ]
//   [ Phi_z(zm)                                        0           ] [dmu] = - [ 2 Phi / h ],
//
// symmetric (the constraint rows' exact derivative is Phi_z(z1), which
// differs from Phi_z(zm) by O(h): Newton then contracts linearly at that
// rate, as it also does for the discrete gradient's difference from
// K_T(zm)), so every SaddlePointSolver (MINRES, GMRES, DIRECT) serves.
// Acceptance as in ImplicitEulerStepper (newton_convergence.h).
//
// Accelerations: a() is the step's mean acceleration (v1 - v0) / h
// extrapolated to t + h linearly through the previous step's mean
// (second order). Local error for adaptive steps: the trapezoidal/midpoint
// local error h^3 z''' / 12 with z''' from the change of the mean
// accelerations of the last two steps, e = h^2 |abar1 - abar0| / (6 (1 +
// h0 / h)).
//
// Step() allocates nothing.

#include <string>

#include <Eigen/Core>

#include "engine/model/multibody_model.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"
#include "engine/linear/sparse_rows.h"
#include "engine/steppers/implicit_stepper.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

class EnergyMomentumStepper final : public ImplicitStepper {
 public:
  EnergyMomentumStepper(MultibodyModel* model, const SolverSettings& settings);

  bool Initialize(std::string* reason) override;
  StepStats Step(double h) override;
  double LocalErrorNorm(double h, double atol, double rtol) const override;

 private:
  void RestoreScheme() override;
  // f = discrete-gradient forces between z_ and z1_ (qm_ and q1_ set) and,
  // when `a` is not null, (h^2/4) K_T(zm) + (h/2) C added to it; returns
  // the force size.
  double Forces(double h, Eigen::VectorXd* f, SkylineLdlt* a, Eigen::VectorXd* roundoff);
  // One Newton solve of the step; `fresh`: assemble and factor the Newton
  // matrix at the first iteration rather than keep the last one.
  StepStats Solve(double h, bool fresh);
  // Newton's hooks (ImplicitStepper::Newton): the unknowns are v1_ and
  // mu = h lambda1_.
  void PlaceIterate() override;
  double EvaluateResidual(bool assemble, bool with_floor) override;
  void ComputeFloor(bool with_floor) override;
  bool FactorMatrix(bool assembled, StepStats* st) override;
  double ApplyCorrection() override;
  const Eigen::VectorXd& IterateVelocity() const override { return v1_; }

  SparseRows jac1_;  // Phi_z(z1) (its values unused; Constraints fills it with Phi)
  SparseRows jacm_;  // Phi_z(zm), copied into the solver when it factors
  // The scheme's state beside ImplicitStepper's: abar_ the last step's mean
  // acceleration (v1 - v0) / h. kept_ (solver.reuse_factorization) has
  // c = h^2 / 4.
  Eigen::VectorXd abar_, abar_old_;
  // Newton work vectors.
  Eigen::VectorXd v1_, q0_, q1_, qm_, qd_, f_, phim_, mdv_, bt_mu_;
  double h_ = 0, c_ = 0;  // the step being taken [s] and c = h^2 / 4
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_ENERGY_MOMENTUM_STEPPER_H_
