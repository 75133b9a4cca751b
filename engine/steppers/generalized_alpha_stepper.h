#ifndef CABLESIM_ENGINE_STEPPERS_GENERALIZED_ALPHA_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_GENERALIZED_ALPHA_STEPPER_H_

// Second-order implicit steppers for the index-3 equations of motion
//
//   M zdd + Phi_z^T lambda = f(z),   Phi(z) = 0        (docs/model.md section 3)
//
// in two variants that users of other codes know.
//
// GENERALIZED_ALPHA (Chung and Hulbert, J. Appl. Mech. 60:371-375, 1993) in
// the form of Arnold and Bruls (Multibody Syst. Dyn. 18:185-202, 2007,
// section 2): the physical acceleration zdd_{n+1} satisfies the equations of
// motion at t_{n+1} exactly, and an algorithmic acceleration a filters it,
//
//   (1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) zdd_{n+1} + alpha_f zdd_n
//   z_{n+1} = z_n + h v_n + h^2 (1/2 - beta) a_n + h^2 beta a_{n+1}
//   v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1}
//
// with the parameters of the spectral radius at infinite frequency
// rho = rho_infinity in [0, 1] (Chung and Hulbert's optimal choice, as
// Arnold and Bruls use it):
//
//   alpha_m = (2 rho - 1) / (rho + 1),   alpha_f = rho / (rho + 1),
//   gamma = 1/2 + alpha_f - alpha_m,     beta = (gamma + 1/2)^2 / 4.
//
// Second order in z and v; rho = 1 adds no numerical damping (for linear
// problems it conserves energy), rho = 0 removes the highest frequencies in
// one step.
//
// HHT (Hilber, Hughes and Taylor, Earthquake Eng. Struct. Dyn. 5:283-292,
// 1977) in the index-3 form of Negrut, Rampalli, Ottarsson and Sajdak
// (J. Comput. Nonlinear Dynam. 2:73-85, 2007), the one Project
// Chrono's ChTimestepperHHT implements: with alpha in [-1/3, 0],
//
//   M zdd_{n+1} + (1 + alpha) (Phi_z^T lambda - f)_{n+1}
//               - alpha (Phi_z^T lambda - f)_n = 0,
//   z_{n+1} = z_n + h v_n + h^2 ((1/2 - beta) zdd_n + beta zdd_{n+1}),
//   v_{n+1} = v_n + h ((1 - gamma) zdd_n + gamma zdd_{n+1}),
//   beta = (1 - alpha)^2 / 4,   gamma = 1/2 - alpha,
//
// and alpha = (rho - 1) / (rho + 1), so rho_infinity in [1/2, 1] maps onto
// HHT's range (Chrono's default alpha = -0.2 is rho = 2/3).
//
// Newton. Both variants are z_{n+1} = z_pred + s zdd_{n+1},
// v_{n+1} = v_pred + s_v zdd_{n+1}, and a residual
// R = M zdd + w (Phi_z^T lambda - f) + (1 - w) g_n (g_n = (Phi_z^T lambda -
// f)_n; w = 1 for generalized-alpha, 1 + alpha for HHT), with
// s = h^2 beta (1 - alpha_f) / (1 - alpha_m) (generalized-alpha) or
// h^2 beta (HHT). Newton on (zdd, w lambda) solves the symmetric system
//
//   [ M + w s_v C + c (K_T + H_lambda)   Phi_z^T ] [ d zdd      ]     [ R       ]
//   [ Phi_z                              0       ] [ w d lambda ] = - [ Phi / s ],
//
// c = w s, C the damping matrix when the scene has damping (f then holds
// the damping force at v_{n+1}, MultibodyModel::DampingForce): the structure of backward Euler's (c = h^2 there), so the same
// SaddlePointSolver (MINRES, GMRES, DIRECT) serves. The scaling by 1/s of
// the constraint rows is Arnold and Bruls' remedy (with Bottasso et al.'s) for
// the O(h^-2) conditioning of index-3 Newton matrices.
//
// Convergence is judged as in ImplicitEulerStepper: position increment
// s |d zdd|_inf below tol (1 + |z|_inf), momentum residual below tol times
// its largest term (or the rounding floor), |Phi|_inf below tol (1 + |z|).
// A residual that stays above tol while the corrections are at the last
// bits of z (16 eps (1 + |z|)) or below tol / 1000 (1 + |z|) is rounding,
// and is accepted when below sqrt(tol).
//
// Newton economy (settings.reuse_factorization): the factored Newton matrix
// is kept across iterations and steps while c (below) stays within 20 % of
// the kept matrix's; it is refreshed when an increment shrinks by less than half (slow
// contraction) and, when a step fails with a kept matrix, the step is
// retried once with a fresh one before it is reported as failed.
//
// Local error (for adaptive steps): Zienkiewicz and Xie's estimate for
// Newmark-type methods (Earthquake Eng. Struct. Dyn. 20:871-887, 1991),
// e = h^2 |beta - 1/6| (zdd_{n+1} - zdd_n).
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

class GeneralizedAlphaStepper final : public ImplicitStepper {
 public:
  enum class Variant { kGeneralizedAlpha, kHht };

  // settings.rho_infinity must be in [0, 1] ([0.5, 1] for HHT; convert/
  // validates it).
  GeneralizedAlphaStepper(MultibodyModel* model, const SolverSettings& settings, Variant variant);

  bool Initialize(std::string* reason) override;
  StepStats Step(double h) override;
  double LocalErrorNorm(double h, double atol, double rtol) const override;

  double alpha_m() const { return alpha_m_; }
  double alpha_f() const { return alpha_f_; }
  double beta() const { return beta_; }
  double gamma() const { return gamma_; }

 private:
  // One Newton solve of the step; `fresh` forces a new Newton matrix first.
  StepStats Solve(double h, bool fresh);
  void RestoreScheme() override;
  // f = f(q_, v) (elastic, applied and damping forces, the damping's
  // velocity v) and, when `a` is not null, c K_T + cd C added to it; the
  // force size (NetForce, DampingForce).
  double Forces(const Eigen::VectorXd& v, Eigen::VectorXd* f, SkylineLdlt* a, double c,
                double cd, Eigen::VectorXd* roundoff);

  // Newton's hooks (ImplicitStepper::Newton): the unknowns are zdd1_ and
  // lambda1_ (scaled by w in the matrix).
  void PlaceIterate() override;
  double EvaluateResidual(bool assemble, bool with_floor) override;
  void ComputeFloor(bool with_floor) override;
  bool FactorMatrix(bool assembled, StepStats* st) override;
  double ApplyCorrection() override;
  const Eigen::VectorXd& IterateVelocity() const override { return v1_; }

  Variant variant_;
  double alpha_m_ = 0, alpha_f_ = 0, beta_ = 0.25, gamma_ = 0.5, w_ = 1;
  SparseRows jac_;  // Phi_z at the current iterate (solver_.b() holds the factored one)
  // The scheme's state beside ImplicitStepper's (z, v, a = the physical
  // acceleration, lambda): the algorithmic acceleration, and
  // g = Phi_z^T lambda - f at the state (HHT); kept_ is the factorization
  // with c = w s. Every step sets the model's time to t_{n+1}: both
  // variants impose Phi(z_{n+1}, t_{n+1}) = 0 and evaluate f at t_{n+1}
  // (HHT's f_n is kept in g_ from the step before, so the alpha-weighted
  // sum takes the load at t_n and t_{n+1}).
  Eigen::VectorXd acc_, g_;
  Eigen::VectorXd acc_h_;  // a_n shifted to the current step (variable steps)
  Eigen::VectorXd acc_old_, g_old_;
  // Newton work vectors.
  // v1_ and qd_: the iterate's velocity, with damping only.
  Eigen::VectorXd z_pred_, v_pred_, v1_, zdd1_, q_, qd_, f_, bt_lambda_;
  // The cables' added-mass correction -D(q) zdd (MultibodyModel::
  // AddedMassCorrection; zero without it).
  Eigen::VectorXd added_;
  // The step's coefficients: z_{n+1} = z_pred + s zdd_{n+1}, v_{n+1} =
  // v_pred + sv zdd_{n+1}, and the Newton matrix's c = w s (of K_T) and
  // cd = w sv (of the damping matrix).
  double s_ = 0, sv_ = 0, c_ = 0, cd_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_GENERALIZED_ALPHA_STEPPER_H_
