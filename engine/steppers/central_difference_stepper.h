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
// Scenes: as DORMAND_PRINCE (no constraint rows, no winches; refused when
// the model is built). lambda() is empty.
//
// Step() allocates nothing.

#include <string>

#include <Eigen/Core>

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

 private:
  Eigen::VectorXd z1_, v1_, a1_, v_pred_;  // the step's end and the damping's predictor
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_CENTRAL_DIFFERENCE_STEPPER_H_
