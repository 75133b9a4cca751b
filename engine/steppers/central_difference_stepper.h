#ifndef CABLESIM_ENGINE_STEPPERS_CENTRAL_DIFFERENCE_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_CENTRAL_DIFFERENCE_STEPPER_H_

// CENTRAL_DIFFERENCE: the explicit central difference method of structural
// dynamics (Newmark's method with beta = 0, gamma = 1/2; Newmark, J. Eng.
// Mech. Div. ASCE 85:67-94, 1959) in its velocity-Verlet form, on the
// unconstrained equations of motion M zdd = f(t, z, zd) with the constant
// reduced mass matrix M factored once:
//
//   v_half = v_n + (h/2) a_n,        z_{n+1} = z_n + h v_half,
//   a_{n+1} = M^-1 f(t_{n+1}, z_{n+1}, v_n + h a_n),
//   v_{n+1} = v_half + (h/2) a_{n+1}.
//
// One force evaluation and one back-substitution with the mass per step (the
// end's acceleration is the next step's first). Second order in z and v.
// Without damping it is symplectic at a fixed step: the energy error stays
// bounded (no drift) over long runs; its phase error for a mode of frequency
// omega is (omega h)^2 / 24 per radian, half the trapezoidal rule's. A
// velocity-dependent force (damping, drag) is evaluated at the explicit
// predictor v_n + h a_n, an O(h^2) change of it, which keeps the order two.
//
// Stability: h omega_max < 2 for the undamped modes (omega_max the stiffest
// element mode, see dormand_prince_stepper.h); damping at the predictor
// lowers the limit on omega h (for a damping ratio xi: 1.64 at xi = 0.1,
// 0.83 at 0.5, 0.47 at 1, about 1 / (2 xi) beyond; Kelvin-Voigt damping gives the stiffest mode
// xi = omega tau / 2), which the check at the start does not count: the
// energy guard catches it. A fixed step beyond the undamped limit at the
// initial state is refused by Initialize (ExplicitAcceleration::Prepare);
// one that tension makes unstable later grows until the run's energy guard
// stops it.
//
// Local error (adaptive steps): Zienkiewicz and Xie's estimate for Newmark
// methods (Earthquake Eng. Struct. Dyn. 20:871-887, 1991) at beta = 0,
// e = h^2 |a_{n+1} - a_n| / 6, in positions (power of h: 3).
//
// Constraint rows (bodies' axes, joints between parts, moving and turning
// supports; issue 32): RATTLE (Andersen, J. Comput. Phys. 52:24-34, 1983;
// Leimkuhler and Skeel, J. Comput. Phys. 112:117-125, 1994), the velocity
// Verlet above with the rows' forces -G^T lambda, G = dPhi/dz:
//
//   v_half = v_n + (h/2) a_n - W_n x / h,   z_{n+1} = z_n + h v_half,
//     x such that Phi(z_{n+1}, t_{n+1}) = 0 (simplified Newton with
//     S_n = G_n W_n, W_n = M^-1 G_n^T; to 1e-13 (1 + |z|_inf), or to
//     1e-10 (1 + |z|_inf) where rounding stalls it: the drift bound);
//   a_free = M^-1 f(t_{n+1}, z_{n+1}, v_n + h a_n),
//   v_{n+1} = v_half + (h/2) a_free - W_{n+1} y,
//     y such that G_{n+1} v_{n+1} + Phi_t(z_{n+1}, t_{n+1}) = 0 (linear);
//   a_{n+1} = a_free - W_{n+1} lambda_{n+1},
//     S_{n+1} lambda_{n+1} = G_{n+1} a_free - gamma(z_{n+1}, v_{n+1}, t_{n+1}).
//
// (a_n in the first line is the consistent acceleration of the step's start;
// RATTLE's position multiplier is lambda_n + 2 x / h^2, and any split of it
// gives the same step.) Why RATTLE and not the accelerations of the index-1
// system [M G^T; G 0][a; lambda] = [f; gamma] with a drift fix: the
// positions stay on Phi = 0 to the projection's tolerance at every step (no
// Baumgarte constants to tune, no drift that grows with the run), and the
// method stays symplectic and time-reversible for holonomic rows at a fixed
// step, so the energy error stays bounded as for the unconstrained method
// instead of drifting as a projected index-1 integration does. It stays
// second order (for rheonomic rows too: the position step holds Phi(z, t)
// at t_{n+1}, the velocity step the rate Phi_t there). The reported
// multipliers are the last line's: those of the index-1 system at the
// step's end state, exactly the equations the implicit steppers' lambda
// satisfies (M a + G^T lambda = f, G a = gamma), so the support reactions,
// joint forces and tensions read from them mean the same; this costs one
// more m x m back-substitution. The constant mass stays factored once;
// a step adds m back-substitutions with it (W), one dense m x m LDL^T and
// one to three evaluations of the rows (m the rows: 6 for a free body's
// axes, 3 more per joint). Stability: the rows only remove modes, so the
// limit on the unconstrained mesh's omega_max (checked at the start) still
// holds, apart from the stiffness lambda . Phi_zz of the multipliers.
// Winches stay refused (the mass must be constant).
//
// Step() allocates nothing.

#include <limits>
#include <string>

#include <Eigen/Core>

#include "engine/steppers/constraint_projection.h"
#include "engine/steppers/explicit_stepper.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"

namespace cablesim {

class CentralDifferenceStepper final : public ExplicitStepper {
 public:
  CentralDifferenceStepper(MultibodyModel* model, const SolverSettings& settings);

  bool Initialize(std::string* reason) override;
  StepStats Step(double h) override;
  double LocalErrorNorm(double h, double atol, double rtol) const override;
  void Restore() override;
  // Adaptive steps stay below 0.9 of the stable step 2 / omega_max, with
  // omega_max from the initial state's power iteration (Initialize): the
  // controller would otherwise grow the step past it, see the stiffest mode
  // grow and reject the step, about one attempt in three on the spatial
  // pendulum. Tension that raises omega_max later is still caught by the
  // error estimate. Infinite before Initialize or for a model without
  // stiffness.
  double stable_step() const override { return stable_step_; }

 private:
  double stable_step_ = std::numeric_limits<double>::infinity();
  Eigen::VectorXd z1_, v1_, a1_, v_pred_;  // the step's end and the damping's predictor
  Eigen::VectorXd lambda1_;                 // the end's multipliers (rows only)
  ConstraintProjection rows_;
  bool rows_current_ = false;  // rows_ was built at the state z_ (not after a Restore)
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_CENTRAL_DIFFERENCE_STEPPER_H_
