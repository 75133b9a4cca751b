#ifndef CABLESIM_ENGINE_RUN_STEP_CONTROL_H_
#define CABLESIM_ENGINE_RUN_STEP_CONTROL_H_

// The dynamic run's step control helpers: a failed run's summary, the
// caller's stop request and step limit before every step attempt, and the
// adaptive controller's step factor.

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_format.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"

namespace cablesim {

inline void Fail(RunSummary* s, double t, const std::string& reason) {
  s->status = "failed";
  s->failure_time_s = t;
  s->error = reason;
}

// Checks the caller's stop request and step limit before a step attempt;
// false (with the summary filled in) means stop now.
inline bool MayStep(const RunControl& control, double t, RunSummary* s) {
  if (control.should_stop && control.should_stop()) {
    s->status = "cancelled";
    s->error = absl::StrFormat("stopped by the caller at t = %.9g", t);
    return false;
  }
  if (control.max_steps > 0 && s->steps + s->rejected_steps >= control.max_steps) {
    Fail(s, t, absl::StrFormat("step limit of %d step attempts reached at t = %.9g",
                               control.max_steps, t));
    return false;
  }
  return true;
}

// Step-size factor of the error controller: the usual safety factor 0.9 on
// err^(-1/k) (k the power of h in the local error), bounded to [0.2, 2] so
// that one estimate never moves the step far (Hairer, Norsett and Wanner,
// Solving ODEs I, section II.4).
inline double StepFactor(double err, int k) {
  if (!(err > 0)) return 2.0;
  return std::clamp(0.9 * std::pow(err, -1.0 / k), 0.2, 2.0);
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_STEP_CONTROL_H_
