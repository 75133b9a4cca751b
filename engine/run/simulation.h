#ifndef CABLESIM_ENGINE_RUN_SIMULATION_H_
#define CABLESIM_ENGINE_RUN_SIMULATION_H_

// Runs a scene's analysis (DYNAMIC, STATIC or MODAL) and reports it frame by frame
// to a FrameSink, then returns the run's summary: what it cost (steps,
// iterations, wall time) and how far it can be trusted (energy balance,
// constraint violation, Newton and linear residuals).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"

namespace cablesim {

// Builds the model for `scene` without running it: what the engine would
// build, or InvalidArgument naming the field that prevents it; Cancelled
// when `should_stop` (asked during the build) said stop.
absl::StatusOr<ModelInfo> DescribeModel(const Scene& scene,
                                        const std::function<bool()>& should_stop = {});

// Builds the model for `scene` and runs it. Returns InvalidArgument (naming
// the scene field) when the scene cannot be modelled; a numerical failure is
// not an error status: the summary's status is "failed" with the reason, and
// every frame up to the last converged one has been delivered. A stop
// request (control.should_stop) while the model is built gives a summary
// with status "cancelled" and no frame.
absl::StatusOr<RunSummary> RunScene(const Scene& scene, FrameSink* sink,
                                    const RunControl& control = {});

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_SIMULATION_H_
