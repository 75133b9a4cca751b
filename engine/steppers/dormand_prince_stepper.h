#ifndef CABLESIM_ENGINE_STEPPERS_DORMAND_PRINCE_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_DORMAND_PRINCE_STEPPER_H_

// DORMAND_PRINCE: the explicit Runge-Kutta pair 5(4) of Dormand and Prince
// (J. Comput. Appl. Math. 6:19-26, 1980; coefficients as in Hairer, Norsett
// and Wanner, Solving ODEs I, 2nd ed., table II.5.2), on the first-order
// form of the unconstrained equations of motion on the unknowns z,
//
//   z' = v,   M v' = f(t, z, v) = Q_a(z, t) - Q_k(z) - C(z) v,
//
// with M the constant reduced mass matrix, factored once (SkylineLdlt).
// A step of size h evaluates the accelerations a = M^-1 f at seven stages
// (t + c_i h, Z_i, V_i), Z_i = z + h sum_j a_ij V_j, V_i = v + h sum_j a_ij
// A_j; the seventh is the step's end (z1 = Z_7, v1 = V_7: the method's b
// row is its a_7 row), and its acceleration is the next step's first stage
// ("first same as last"): six force evaluations and six back-substitutions
// with the mass per step, no Newton, no tangent. Fifth order in z and v.
//
// Local error (adaptive steps): the difference to the embedded fourth-order
// solution in positions, e_z = h sum_i (b_i - bhat_i) V_i, and in
// velocities times h, h e_v = h^2 sum_i (b_i - bhat_i) A_i (metres too: a
// stiff mode's error shows in the velocities omega h times larger); the
// power of h in it is 5 (local extrapolation as in DOPRI5).
//
// Where it applies. An explicit method is stable only while h lambda stays
// within its stability region, lambda = +-i omega for an undamped mode. The
// DOPRI5 region reaches -3.3 on the real axis but meets the imaginary axis
// only up to omega h = 1: beyond, an undamped mode grows by |R(i omega h)|
// a step, 1.003 at omega h = 1.5, 1.03 at 2, 1.44 at 3 (R the method's
// stability polynomial, sum_{k<=5} z^k / k! + z^6 / 600); moderate
// damping moves modes left, into the region, heavy damping (2 xi omega h
// beyond 3.3) out of it again. So without damping: h omega_max <= 1, half
// central difference's limit, bought back by the order. omega_max is the cable's
// stiffest element mode, an axial one: omega_max = 9.6 sqrt(E / rho) / l
// for elements of length l at rest (MODAL analysis of 12 and 24 soft and 12
// steel elements: 9.57, 9.56, 9.55), higher under tension. It pays where that step is as
// large as accuracy asks for anyway (soft cables, ropes, slack lines with
// fine output); a steel cable of short elements needs micro-steps (an
// implicit stepper then). Adaptive steps stay below stable_step() (the
// stiffness estimate of the last step); a fixed
// step beyond 1.725 / omega_max at the initial state (growth 1 % a step) is
// refused by Initialize, one that tension makes unstable later grows until
// the run's energy guard stops the run.
// The model's constraint rows (joints other than to ground, bodies' axes)
// and winches (a mass that changes) are refused when the model is built
// (ModelBuilder::CheckIntegratorFits); lambda() is empty.
//
// Step() allocates nothing.

#include <array>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "engine/steppers/explicit_stepper.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"

namespace cablesim {

class DormandPrinceStepper final : public ExplicitStepper {
 public:
  DormandPrinceStepper(MultibodyModel* model, const SolverSettings& settings);

  bool Initialize(std::string* reason) override;
  StepStats Step(double h) override;
  double LocalErrorNorm(double h, double atol, double rtol) const override;

  // 0.99 / max(rho, omega_max): within the stability region's reach along
  // the imaginary axis (0.997), where no undamped mode grows. (A cap at
  // 1.5 let the 30 s falling pendulum's energy rise by 0.5 J of 81 J at a
  // whip; at 0.99 it does not rise.) rho = |f(y7) - f(y6)| / |y7 - y6| from the last
  // step's two stages at t + h (Hairer and Wanner's stiffness estimate for
  // DOPRI5, Solving ODEs II, section IV.2: the dominant |eigenvalue| of the
  // Jacobian along the difference, omega for an oscillating mode) sees a
  // stiff mode once it is excited; omega_max (power iteration on M^-1 K_T,
  // at the start and every 50 steps, 20 warm iterations) sees it before.
  double stable_step() const override { return stable_step_; }

  static constexpr int kStages = 7;

 private:
  double stable_step_ = std::numeric_limits<double>::infinity();
  double omega_max_ = 0;  // last power-iteration estimate [rad/s]
  int steps_ = 0;
  // Stage velocities V_i (= the stages' z') and accelerations A_i.
  std::array<Eigen::VectorXd, kStages> vs_, as_;
  Eigen::VectorXd zs_, err_z_, err_v_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_DORMAND_PRINCE_STEPPER_H_
