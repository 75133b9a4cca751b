#ifndef CABLESIM_ENGINE_RUN_SIMULATION_H_
#define CABLESIM_ENGINE_RUN_SIMULATION_H_

// Runs a scene's analysis (DYNAMIC, STATIC or MODAL) and reports it frame by frame
// to a FrameSink, then returns the run's summary: what it cost (steps,
// iterations, wall time) and how far it can be trusted (energy balance,
// constraint violation, Newton and linear residuals).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"

namespace cablesim {

struct PreparedModel;

// A scene's model, built and checked, ready to run once (Prepare, then
// RunPrepared). A caller that must cost a scene before running it (the
// server checks the built model against its limits) builds the model once
// and runs the same one. Movable, not copyable.
class PreparedRun {
 public:
  PreparedRun();
  PreparedRun(PreparedRun&&) noexcept;
  PreparedRun& operator=(PreparedRun&&) noexcept;
  ~PreparedRun();

  // What the engine built (as DescribeModel).
  const ModelInfo& info() const;
  // Whether RunPrepared has already run it (a model runs once).
  bool used() const;

 private:
  friend absl::StatusOr<PreparedRun> Prepare(const Scene&, const std::function<bool()>&);
  friend absl::StatusOr<RunSummary> RunPrepared(PreparedRun*, FrameSink*, const RunControl&);
  std::unique_ptr<PreparedModel> model_;
};

// Builds the model for `scene` (copied into the result) and checks what a
// run needs before it starts (MODAL: the modes). InvalidArgument naming the
// field that prevents it; Cancelled when `should_stop` (asked during the
// build) said stop.
absl::StatusOr<PreparedRun> Prepare(const Scene& scene,
                                    const std::function<bool()>& should_stop = {});

// Runs a prepared model, as RunScene. Its wall_seconds include the build's.
// FailedPrecondition when `prepared` has run already.
absl::StatusOr<RunSummary> RunPrepared(PreparedRun* prepared, FrameSink* sink,
                                       const RunControl& control = {});

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
