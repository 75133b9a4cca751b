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
// During an adaptive run (no constraint rows), the cost model below weighs
// the two (RunDynamic):
//  - on CENTRAL_DIFFERENCE, after a window of accepted steps (32), if its
//    stable step held most of them, HHT is tried for kTrialSteps steps
//    from the step central difference's error estimate suggests; HHT is
//    kept if its Newton iterations a step at the step its own estimate
//    allows cost less per second of the run than one unit per stable step
//    (by kSwitchMargin), else central difference resumes where HHT got to
//    (Stepper::Restart: no new power iteration) and the next trial is
//    kTrialSpacing times further off. Central difference's own estimate
//    cannot tell HHT's step: the undamped stiff modes ring in it.
//  - on HHT, after windows that double, a trial start of central
//    difference gives the stable step at the current state; it takes over
//    if the window's time over that step costs less than HHT's Newton
//    iterations did.
// Adaptive central difference stays below 0.9 of its stable step
// (CentralDifferenceStepper::stable_step).
// The switch carries the state (z, v) exactly, as a joint's release does;
// the summary lists each stepper's stretch (RunSummary::
// integrator_segments).

#include <memory>
#include <string>

#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"

namespace cablesim {

class Stepper;

// AUTO's cost model: counted operations, not wall time (a choice that
// depended on a clock would make runs irreproducible). The unit is one
// unconstrained central-difference step: one force evaluation a = M^-1 f
// with the constant mass factored once, plus the step's vector updates and
// its error estimate. Every term is linear in the coordinates (the cables'
// matrices are banded), so the ratios hold per coordinate, whatever the
// scene's size. Measured with `cablesim run` on scenes/spatial-pendulum.json
// (114 coordinates), wall time per operation:
//  - a central-difference step: 3.3 us at h = 1e-4 (fixed), 4.0 us per
//    attempt with adaptive steps;
//  - an HHT Newton iteration (residual and tangent assembly, the banded
//    factorisation, one solve, the step's share of its predictor and error
//    estimate): 12.6 us at tolerance 1e-3 m (10.4 us on the pendulum with
//    a body of bench/work_precision_constrained.json): 3 units
//    (kNewtonIterationCost);
//  - Newton iterations per accepted HHT step: 5.4 to 7.9 at tolerances
//    1e-3 and 1e-4 m on the two pendulums (22 at 1e-2 m on the spatial
//    pendulum, whose steps are then long); kNewtonIterationsPerStep is the
//    guess before an HHT stretch of the run has counted its own.
// At a fixed step within the stable step both would take the same steps,
// and a central-difference step costs less than one Newton iteration, with
// constraint rows too (RATTLE's projections cost about as much as the rows
// add to HHT's system: per step 2.7 times cheaper on the end cylinder, 2.6
// times on the pendulum with a body, issue 32's note); so the model only
// weighs adaptive runs, where the stable step may hold the explicit step
// far below the one HHT's accuracy allows.
inline constexpr double kNewtonIterationCost = 3.0;
inline constexpr double kNewtonIterationsPerStep = 5.0;
// The other stepper must be this much cheaper by the model before AUTO
// changes to it (the model is good to tens of per cent, and a change costs
// a power iteration and a restart).
inline constexpr double kSwitchMargin = 1.25;

// Covering a stretch of time: `explicit_steps` central-difference steps
// (the stretch over the smaller of the stable step and the step the
// accuracy allows) against `implicit_steps` HHT steps (over the step the
// accuracy allows) of `newton_per_step` Newton iterations each. Their costs
// in the model's unit.
struct CostEstimate {
  double explicit_cost = 0;
  double implicit_cost = 0;
};
inline CostEstimate EstimateCosts(double explicit_steps, double implicit_steps,
                                  double newton_per_step) {
  return {explicit_steps, implicit_steps * kNewtonIterationCost * newton_per_step};
}

// Adaptive runs weigh the two after this many accepted steps, then after
// twice as many as the last window each time the stepper stays (a
// logarithmic number of trial starts; RunDynamic).
inline constexpr int kFirstCostWindow = 32;
// HHT's trial on an adaptive run: this many accepted steps; a lost trial
// puts the next one this many times further off (so that a scene where
// central difference wins pays for few trials: two on the falling pendulum).
inline constexpr int kTrialSteps = 4;
inline constexpr int kTrialSpacing = 8;

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
