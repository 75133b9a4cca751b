#ifndef CABLESIM_ENGINE_RUN_ERROR_ESTIMATE_H_
#define CABLESIM_ENGINE_RUN_ERROR_ESTIMATE_H_

// solver.error_estimate: an estimate of a dynamic run's largest probe
// position error, from a companion run (Richardson extrapolation at fixed
// steps, a tighter tolerance when adaptive), and the sink that records the
// main run's probe positions for it.

#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "engine/model/multibody_model.h"
#include "engine/run/joint_release.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"

namespace cablesim {

// Forwards frames and keeps every probe position (for the error estimate).
class ProbeRecordingSink : public FrameSink {
 public:
  explicit ProbeRecordingSink(FrameSink* next) : next_(next) {}
  absl::Status OnStart(const ModelInfo& info) override {
    return next_ ? next_->OnStart(info) : absl::OkStatus();
  }
  bool wants_angular_momentum() const override {
    return next_ != nullptr && next_->wants_angular_momentum();
  }
  absl::Status OnFrame(const Frame& frame) override {
    times_.push_back(frame.t);
    for (const ProbeSample& p : frame.probes) positions_.push_back(p.position_m);
    return next_ ? next_->OnFrame(frame) : absl::OkStatus();
  }
  const std::vector<double>& times() const { return times_; }
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }

 private:
  FrameSink* next_;
  std::vector<double> times_;
  std::vector<Eigen::Vector3d> positions_;
};


// The error estimate of a DYNAMIC run (solver.error_estimate): a companion
// run of the same model, with half the step (fixed steps) or tolerances 32
// times tighter (adaptive steps), compared frame by frame at the probes.
// Fixed steps: Richardson extrapolation for a method of order p,
// e(h) ~ |x_h - x_{h/2}| 2^p / (2^p - 1). Adaptive: the companion is much
// more accurate, so the difference itself is the estimate.
// `release`: the main run's line failures (joint_release.h), which the
// companion run repeats from the scene's own model (null: none).
void EstimateError(MultibodyModel* model, const SolverSettings& settings,
                   const RunControl& control, const ProbeRecordingSink& main,
                   RunSummary* summary, JointRelease* release = nullptr);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_ERROR_ESTIMATE_H_
