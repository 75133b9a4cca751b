#ifndef CABLESIM_TESTS_ENERGY_MOMENTUM_SCENES_H_
#define CABLESIM_TESTS_ENERGY_MOMENTUM_SCENES_H_

// The reference paper's falling pendulum (12 elements, E = 0.7 MPa, exact
// bending, pinned at one end and released horizontal) run by the
// ENERGY_MOMENTUM stepper, frames every `output_interval_s`; `extra` adds
// solver fields (", \"linear_solver\": \"DIRECT\"").

#include <string>

#include "absl/strings/str_format.h"

namespace cablesim::testing {

// The same scene with `solver` fields of the caller's (integrator, step...).
inline std::string FallingPendulumWithSolver(double duration_s, double output_interval_s,
                                             const std::string& solver) {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "beam", "length": 1.2, "elements": 12, "direction": {"x": 1},
                "density": 5540, "youngs_modulus": 0.7e6,
                "area": 0.0018, "second_moment": 1.215e-8, "bending": "EXACT"}],
    "joints": [{"type": "PIN", "a": {"cable": "beam", "s": 0}}],
    "probes": [{"name": "tip", "cable": "beam", "s": 1.2}],
    "solver": {"duration": %g, "output_interval": %g, %s}})",
                         duration_s, output_interval_s, solver);
}

inline std::string EnergyMomentumFallingPendulum(double duration_s, double step_s,
                                                 const std::string& extra,
                                                 double output_interval_s = 0.01) {
  return FallingPendulumWithSolver(
      duration_s, output_interval_s,
      absl::StrFormat(R"("step": %g, "integrator": "ENERGY_MOMENTUM" %s)", step_s, extra));
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_ENERGY_MOMENTUM_SCENES_H_
