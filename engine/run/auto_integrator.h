#ifndef CABLESIM_ENGINE_RUN_AUTO_INTEGRATOR_H_
#define CABLESIM_ENGINE_RUN_AUTO_INTEGRATOR_H_

// solver.integrator AUTO (issue 32, item 1): the stepper chosen from the
// scene at the start of a DYNAMIC run, among the existing ones.
//
// Explicit when nothing in the scene rules it out, since an explicit step
// costs one force evaluation against a Newton iteration's assembly and
// factorisations (the falling pendulum at <= 1e-3 m: central difference
// 60-70 times faster than the paper's method, bench/results/summary.md):
//  - constraint rows (bodies, joints between parts, moving supports) only
//    at fixed steps: CENTRAL_DIFFERENCE holds them by RATTLE
//    (central_difference_stepper.h), within its stable step as checked
//    below; adaptive steps with rows keep HHT (not yet measured);
//  - no winch (they factor a constant mass once);
//  - no contact (seabed, sheaves, body contact points) and no fluid: these
//    stiffen or load the scene mid-run, and the explicit steppers' stable
//    step is checked at the start only (there is no switch back yet);
//  - no setting that only an implicit stepper uses
//    (SolverSettings::auto_keep_implicit);
//  - fixed steps: the stiffest mode at the initial state admits
//    solver.step (CENTRAL_DIFFERENCE's Initialize: h omega_max < 2);
//    adaptive steps: the controller holds the local error, which a mode
//    growing beyond the stable step raises at once.
// Then CENTRAL_DIFFERENCE (one force evaluation a step, second order like
// HHT; adaptive DORMAND_PRINCE, held to its stable step, was 2-7 times
// slower on the pendulums); else HHT, the default. The step, output
// interval and tolerance stay the scene's.

#include <string>

#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"

namespace cablesim {

// The stepper AUTO runs `scene` with, and in *reason why (one sentence).
// Leaves `model` as it found it (a trial stepper is started on it).
Integrator ChooseIntegrator(MultibodyModel* model, const Scene& scene, std::string* reason);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_AUTO_INTEGRATOR_H_
