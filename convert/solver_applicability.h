#ifndef CABLESIM_CONVERT_SOLVER_APPLICABILITY_H_
#define CABLESIM_CONVERT_SOLVER_APPLICABILITY_H_

// Solver settings that a scene gives but that would do nothing in its run
// are refused, naming the field and why (`solver.load_steps: applies to
// ...`), as the explicit steppers' Newton and linear-solver settings are.
// One table (solver_applicability.cc), checked after the solver section
// is converted (SceneFromProto), so that every other check of a field
// (its range, its integrator) speaks first.
//
// Not in the table, because they do apply: linear_tolerance with DIRECT
// (it triggers DIRECT's refinement pass), and max_linear_iterations and
// preconditioner with DIRECT in a DYNAMIC run (DIRECT falls back to MINRES
// with them when its factorisation is not ready: the summary's
// direct_fallbacks).

#include "absl/status/status.h"
#include "cablesim/v1/scene.pb.h"
#include "engine/scene/scene.h"

namespace cablesim {

// `proto` the scene file's solver section, `settings` as converted from
// it. OK, or INVALID_ARGUMENT for the first setting that does not apply.
absl::Status CheckSolverSettingsApply(const v1::Solver& proto, const SolverSettings& settings);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SOLVER_APPLICABILITY_H_
