#ifndef CABLESIM_ENGINE_RUN_RUN_WARNINGS_H_
#define CABLESIM_ENGINE_RUN_RUN_WARNINGS_H_

// A run that finished may still not be trustworthy. After a DYNAMIC run,
// RunSummary::warnings names each reason found, one sentence each:
//  - a step's estimated local error (the stepper's embedded estimate,
//    local_error_estimate_m) exceeded the tolerance it is held to
//    (error_tolerance_m, with solver.relative_tolerance);
//  - linear solves were accepted inexact (solver.accept_inexact_solves);
//  - fixed steps were cut to kStepCutWarning times below solver.step or
//    further (the requested step did not hold; the run was not the one
//    asked for).
// The scene's plausibility warnings (Scene::warnings, convert/
// plausibility_warnings.h) come first in the list (RunPrepared puts them).
// With SolverSettings::strict, a run with warnings (plausibility ones
// included) fails (status "failed", the warnings as its error).

#include "engine/output/results.h"
#include "engine/scene/scene.h"

namespace cablesim {

// Fixed steps cut to 1/16 of solver.step or less (four halvings) warn
// (the sample mooring-line-in-waves cuts to 1/8 once, without warning).
inline constexpr double kStepCutWarning = 16;

void AddRunWarnings(const SolverSettings& settings, RunSummary* summary);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_RUN_WARNINGS_H_
