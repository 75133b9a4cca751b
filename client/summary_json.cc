#include "client/summary_json.h"

#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/json_line.h"

namespace cablesim {
namespace {

// A JSON array of objects already written.
std::string JsonArray(const std::vector<std::string>& objects) {
  return absl::StrCat("[", absl::StrJoin(objects, ","), "]");
}

}  // namespace

std::string StatisticsToJson(const RunStatistics& statistics) {
  std::vector<std::string> columns;
  for (const ColumnStatistics& c : statistics.columns) {
    JsonLine item;
    item.Add("column", c.column)
        .Add("count", c.count)
        .Add("min", c.min)
        .Add("min_t", c.min_t)
        .Add("max", c.max)
        .Add("max_t", c.max_t)
        .Add("mean", c.mean)
        .Add("stddev", c.stddev);
    columns.push_back(item.ToString());
  }
  std::vector<std::string> rainflow;
  for (const RainflowStatistics& r : statistics.rainflow) {
    JsonLine item;
    item.Add("column", r.column)
        .Add("cycles", r.cycles)
        .Add("half_cycles", r.half_cycles)
        .Add("max_range", r.max_range)
        .Add("damage_equivalent_load", r.damage_equivalent_load);
    rainflow.push_back(item.ToString());
  }
  JsonLine json;
  json.AddJson("columns", JsonArray(columns));
  if (!statistics.rainflow.empty()) {
    json.Add("sn_slope", statistics.sn_slope)
        .Add("equivalent_cycles", statistics.equivalent_cycles)
        .AddJson("rainflow", JsonArray(rainflow));
  }
  return json.ToString();
}

std::string SummaryToJson(const RunSummary& summary) {
  JsonLine json;
  json.Add("status", summary.status);
  if (!summary.error.empty()) json.Add("error", summary.error);
  if (summary.status == "failed") json.Add("failure_time_s", summary.failure_time_s);
  json.Add("model", summary.info.model)
      .Add("analysis", summary.analysis)
      .Add("integrator", summary.integrator)
      .Add("integrator_requested", summary.integrator_requested)
      .Add("integrator_reason", summary.integrator_reason)
      .Add("linear_solver", summary.linear_solver)
      .Add("coordinates", summary.info.coordinates)
      .Add("dofs", summary.info.dofs)
      .Add("multipliers", summary.info.multipliers)
      .Add("elements", summary.info.elements)
      .Add("nodes", summary.info.nodes)
      .Add("frames", summary.frames)
      .Add("steps", summary.steps)
      .Add("rejected_steps", summary.rejected_steps)
      .Add("newton_iterations", summary.newton_iterations)
      .Add("linear_iterations", summary.linear_iterations)
      .Add("min_step_s", summary.min_step_s)
      .Add("end_time_s", summary.end_time_s)
      .Add("wall_seconds", summary.wall_seconds)
      .Add("energy_initial", summary.energy_initial)
      .Add("energy_final", summary.energy_final)
      .Add("energy_dissipated", summary.energy_dissipated)
      .Add("energy_damped", summary.energy_damped)
      .Add("energy_max_increase", summary.energy_max_increase)
      .Add("max_constraint_violation", summary.max_constraint_violation)
      .Add("max_newton_residual", summary.max_newton_residual)
      .Add("max_residual_floor", summary.max_residual_floor)
      .Add("max_linear_residual", summary.max_linear_residual);
  if (summary.analysis == "MODAL") json.Add("frequencies_hz", summary.frequencies_hz);
  if (summary.analysis == "DYNAMIC") {
    json.Add("linear_solver_used", summary.linear_solver_used)
        .Add("accepted_steps", summary.steps)
        .Add("max_step_s", summary.max_step_s)
        .Add("factorizations", summary.factorizations)
        .Add("direct_fallbacks", summary.direct_fallbacks)
        .Add("linear_solves", summary.linear_solves)
        .Add("inexact_linear_solves", summary.inexact_linear_solves)
        .Add("adaptive", summary.adaptive);
    // rho_infinity: the implicit second-order steppers' (the explicit ones
    // have no such parameter).
    if (summary.integrator != "IMPLICIT_EULER" && summary.integrator != "CENTRAL_DIFFERENCE" &&
        summary.integrator != "DORMAND_PRINCE")
      json.Add("rho_infinity", summary.rho_infinity);
    // Every run's error estimate and what it is held to, and the
    // warnings (docs/honest-runs.md).
    json.Add("local_error_estimate_m", summary.local_error_estimate_m)
        .Add("accumulated_error_estimate_m", summary.accumulated_error_estimate_m)
        .Add("error_tolerance_m", summary.error_tolerance_m)
        .Add("warnings", summary.warnings);
    // The joints that let go (Joint.release), an empty list when none did.
    std::vector<std::string> releases;
    for (const JointReleaseEvent& e : summary.releases) {
      JsonLine item;
      item.Add("joint", e.joint)
          .Add("name", e.name)
          .Add("time_s", e.time_s)
          .Add("force_n", e.force_n)
          .Add("cause", e.cause);
      releases.push_back(item.ToString());
    }
    json.AddJson("releases", JsonArray(releases));
    // Which stepper ran when (AUTO may change it during the run).
    std::vector<std::string> segments;
    for (const IntegratorSegment& g : summary.integrator_segments) {
      JsonLine item;
      item.Add("integrator", g.integrator)
          .Add("start_s", g.start_s)
          .Add("steps", g.steps)
          .Add("reason", g.reason);
      segments.push_back(item.ToString());
    }
    json.AddJson("integrator_segments", JsonArray(segments));
    if (summary.has_error_estimate) {
      if (summary.error_estimate_m >= 0) json.Add("error_estimate_m", summary.error_estimate_m);
      json.Add("error_estimate_method", summary.error_estimate_method)
          .Add("error_estimate_seconds", summary.error_estimate_seconds);
    }
  }
  if (summary.has_statistics) json.AddJson("statistics", StatisticsToJson(summary.statistics));
  return json.ToString();
}

}  // namespace cablesim
