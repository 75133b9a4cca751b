#include "engine/run/run_warnings.h"

#include <string>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace cablesim {

void AddRunWarnings(const SolverSettings& settings, RunSummary* summary) {
  if (settings.analysis != Analysis::kDynamic) return;
  RunSummary& s = *summary;
  s.error_tolerance_m = settings.error_tolerance_m;
  if (s.local_error_ratio > 1) {
    s.warnings.push_back(absl::StrFormat(
        "the estimated local error of a step (%.3g m, local_error_estimate_m) exceeds the "
        "tolerance %.3g m%s (error_tolerance_m) %.3g times: use a smaller solver.step or "
        "solver.adaptive",
        s.local_error_estimate_m, settings.error_tolerance_m,
        settings.relative_tolerance > 0
            ? absl::StrFormat(" + %.3g |value|", settings.relative_tolerance)
            : std::string(),
        s.local_error_ratio));
  }
  if (s.inexact_linear_solves > 0) {
    s.warnings.push_back(absl::StrFormat(
        "%d linear solves were accepted inexact (solver.accept_inexact_solves; "
        "max_linear_residual %.3g): Newton steps used solutions whose residual stayed above "
        "1e-6",
        s.inexact_linear_solves, s.max_linear_residual));
  }
  if (!settings.adaptive &&
      s.smallest_cut_step_s * kStepCutWarning <= settings.step_s * (1 + 1e-12)) {
    s.warnings.push_back(absl::StrFormat(
        "steps were cut to %.3g s, 1/%.0f of solver.step (%.3g s), after %d rejected steps: "
        "the requested step does not hold for this scene; use a smaller solver.step or "
        "solver.adaptive",
        s.smallest_cut_step_s, settings.step_s / s.smallest_cut_step_s, settings.step_s,
        s.rejected_steps));
  }
  if (settings.strict && s.status == "ok" && !s.warnings.empty()) {
    s.status = "failed";
    s.failure_time_s = s.end_time_s;
    s.error = "solver.strict: " + absl::StrJoin(s.warnings, "; ");
  }
}

}  // namespace cablesim
