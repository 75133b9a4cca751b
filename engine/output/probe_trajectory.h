#ifndef CABLESIM_ENGINE_OUTPUT_PROBE_TRAJECTORY_H_
#define CABLESIM_ENGINE_OUTPUT_PROBE_TRAJECTORY_H_

// The probe positions of a run, frame by frame (a FrameSink that keeps
// them), and the largest probe-position distance between two runs of the
// same scene: the error measure of the work-precision report (bench/) and
// of step-halving error estimates.
//
//   E = max over common frame times t and probes p of |r_p(t) - r'_p(t)|_2  [m]

#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "engine/output/results.h"

namespace cablesim {

class ProbeTrajectory : public FrameSink {
 public:
  absl::Status OnStart(const ModelInfo& info) override;
  absl::Status OnFrame(const Frame& frame) override;

  // Frame times [s] and, per frame, one position [m] per probe.
  const std::vector<double>& times() const { return times_; }
  const std::vector<std::vector<Eigen::Vector3d>>& positions() const { return positions_; }
  int probes() const { return probes_; }

 private:
  int probes_ = 0;
  std::vector<double> times_;
  std::vector<std::vector<Eigen::Vector3d>> positions_;
};

// E (above) over the frames of `run` whose time matches a frame of
// `reference` within `time_tolerance` [s] (relative to max(1, |t|)): both
// runs must have written frames at the same output times. InvalidArgument
// when the probe counts differ, when `run` has no frame, or when a frame of
// `run` has no reference frame at its time (the reference must cover the
// run: a failed reference cannot judge a longer run).
absl::StatusOr<double> MaxProbePositionError(const ProbeTrajectory& run,
                                             const ProbeTrajectory& reference,
                                             double time_tolerance = 1e-9);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_OUTPUT_PROBE_TRAJECTORY_H_
