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
// slower on the pendulums); else HHT. The step, output interval and
// tolerance stay the scene's. AUTO is the default (an unset
// solver.integrator, convert/scene/solver.cc).
//
// During a fixed-step run (RunDynamic) the choice is revisited when nothing
// structural rules the explicit steppers out (*may_switch):
//  - CENTRAL_DIFFERENCE -> HHT when a step's local error estimate exceeds
//    the run's error tolerance (SolverSettings::error_tolerance_m): the
//    step is taken back and HHT goes on from the state before it. A mode
//    that tension or large strain has pushed beyond the stable step grows
//    geometrically from rounding, so the estimate sees it long before the
//    energy guard would; an answer the estimate calls inaccurate is not
//    kept either way.
//  - HHT -> CENTRAL_DIFFERENCE, in a run that started on central
//    difference, when a trial start at the current state fits
//    (h omega_max < 2, TryExplicit): tried after 64 accepted HHT steps,
//    then after twice as many as the last try each time, so that a scene
//    that stays stiff, or sits at the edge of the stable step, pays a
//    logarithmic number of power iterations and switches; back to 64 after
//    an explicit stretch of at least four times the interval (the choice
//    was right there).
// The switch carries the state (z, v) exactly, as a joint's release does;
// the summary lists each stepper's stretch (RunSummary::
// integrator_segments).

#include <memory>
#include <string>

#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"

namespace cablesim {

class Stepper;

// The stepper AUTO runs `scene` with, and in *reason why (one sentence).
// Leaves `model` as it found it (a trial stepper is started on it).
// *may_switch (when given): the run may change stepper (see above).
Integrator ChooseIntegrator(MultibodyModel* model, const Scene& scene, std::string* reason,
                            bool* may_switch = nullptr);

// CENTRAL_DIFFERENCE started at the model's initial state with `settings`'
// step, or null (with *why) when that step is beyond its stable step there.
// Leaves the model's time at its initial time.
std::unique_ptr<Stepper> TryExplicit(MultibodyModel* model, const SolverSettings& settings,
                                     std::string* why);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_AUTO_INTEGRATOR_H_
