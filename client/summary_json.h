#ifndef CABLESIM_CLIENT_SUMMARY_JSON_H_
#define CABLESIM_CLIENT_SUMMARY_JSON_H_

// The run summary as one line of JSON, the `cablesim run` output.

#include <string>

#include "engine/run/simulation.h"

namespace cablesim {

// One JSON object, without a trailing newline. Keys, in this order:
//   status, error (when not empty), failure_time_s (when status is
//   "failed"), model, analysis, integrator, linear_solver, coordinates,
//   dofs, multipliers, elements, nodes, frames, steps, rejected_steps,
//   newton_iterations, linear_iterations, min_step_s, end_time_s,
//   wall_seconds, energy_initial, energy_final, energy_dissipated,
//   energy_max_increase, max_constraint_violation, max_newton_residual,
//   max_linear_residual.
// Then, with the scene's output.statistics or output.rainflow, `statistics`:
//   {"columns":[{"column","count","min","min_t","max","max_t","mean",
//   "stddev"}...]} and, with rainflow columns, "sn_slope",
//   "equivalent_cycles", "rainflow":[{"column","cycles","half_cycles",
//   "max_range","damage_equivalent_load"}...] (docs/outputs-statistics.md).
// Units as in RunSummary (s, J, m). Non-finite numbers are written as null.
std::string SummaryToJson(const RunSummary& summary);

// The `statistics` object of SummaryToJson.
std::string StatisticsToJson(const RunStatistics& statistics);

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_SUMMARY_JSON_H_
