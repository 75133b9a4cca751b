#include "engine/run/error_estimate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "absl/strings/str_format.h"
#include "engine/run/dynamic_run.h"
#include "engine/run/frame_recorder.h"
#include "engine/scene/integrator_traits.h"

namespace cablesim {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

void EstimateError(MultibodyModel* model, const SolverSettings& settings,
                   const RunControl& control, const ProbeRecordingSink& main,
                   RunSummary* summary, JointRelease* release) {
  const auto start = Clock::now();
  summary->has_error_estimate = true;
  SolverSettings companion = settings;
  companion.error_estimate = false;
  // The order of the frames (DORMAND_PRINCE is fifth order at its steps, but
  // frames between steps are cubic Hermite, fourth order).
  const int order = TraitsOf(settings.integrator).frame_order;
  double factor = 1;
  if (settings.adaptive) {
    companion.tolerance_m /= 32;
    companion.relative_tolerance /= 32;
    summary->error_estimate_method =
        "difference to a companion run with tolerance and relative_tolerance / 32";
  } else {
    companion.step_s /= 2;
    companion.max_step_halvings += 1;  // the same smallest step
    factor = std::ldexp(1.0, order) / (std::ldexp(1.0, order) - 1);
    summary->error_estimate_method = absl::StrFormat(
        "Richardson extrapolation against a companion run at half the step (order %d: "
        "%.4g times the difference)",
        order, factor);
  }
  ProbeRecordingSink recorded(nullptr);
  RunSummary companion_summary;
  FrameRecorder recorder(model, &recorded, &companion_summary);
  // The caller's stop request and step limit apply to the companion too.
  RunDynamic(model, companion, control, &recorder, &companion_summary, release);
  summary->error_estimate_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (companion_summary.status != "ok") {
    summary->error_estimate_method += " (the companion run failed: " + companion_summary.error + ")";
    return;
  }
  if (recorded.times().size() != main.times().size() ||
      recorded.positions().size() != main.positions().size()) {
    summary->error_estimate_method += " (the companion run's frames differ)";
    return;
  }
  double worst = 0;
  for (size_t i = 0; i < main.positions().size(); ++i)
    worst = std::max(worst, (main.positions()[i] - recorded.positions()[i]).norm());
  if (!std::isfinite(worst)) {
    summary->error_estimate_method += " (not finite)";
    return;
  }
  summary->error_estimate_m = factor * worst;
}

}  // namespace cablesim
