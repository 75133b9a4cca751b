#include "engine/output/probe_trajectory.h"

#include <algorithm>
#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace cablesim {

absl::Status ProbeTrajectory::OnStart(const ModelInfo& info) {
  probes_ = static_cast<int>(info.probe_names.size());
  times_.clear();
  positions_.clear();
  return absl::OkStatus();
}

absl::Status ProbeTrajectory::OnFrame(const Frame& frame) {
  times_.push_back(frame.t);
  std::vector<Eigen::Vector3d> row;
  row.reserve(frame.probes.size());
  for (const ProbeSample& p : frame.probes) row.push_back(p.position_m);
  positions_.push_back(std::move(row));
  return absl::OkStatus();
}

absl::StatusOr<double> MaxProbePositionError(const ProbeTrajectory& run,
                                             const ProbeTrajectory& reference,
                                             double time_tolerance) {
  if (run.probes() != reference.probes()) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "the runs have %d and %d probes", run.probes(), reference.probes()));
  }
  if (run.times().empty()) return absl::InvalidArgumentError("the run has no frame");
  const std::vector<double>& rt = reference.times();
  double error = 0;
  size_t j = 0;  // both are in time order
  for (size_t i = 0; i < run.times().size(); ++i) {
    const double t = run.times()[i];
    const double tol = time_tolerance * std::max(1.0, std::abs(t));
    while (j < rt.size() && rt[j] < t - tol) ++j;
    if (j == rt.size() || std::abs(rt[j] - t) > tol) {
      return absl::InvalidArgumentError(
          absl::StrFormat("the reference has no frame at t = %.9g s", t));
    }
    for (int p = 0; p < run.probes(); ++p) {
      error = std::max(error, (run.positions()[i][p] - reference.positions()[j][p]).norm());
    }
  }
  return error;
}

}  // namespace cablesim
