#ifndef CABLESIM_BENCH_SWEEP_BENCH_UTIL_H_
#define CABLESIM_BENCH_SWEEP_BENCH_UTIL_H_

// Shared by the service benchmarks: limits that bound nothing, and what
// the sweep benchmarks time: submit a sweep and follow it (WatchSweep)
// until its last item has finished.

#include <cstdint>
#include <limits>
#include <string>

#include "absl/status/statusor.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "server/request_checks.h"

namespace cablesim {

// The server's limits with no bound on frames, trajectory or steps.
inline ServerLimits NoLimits() {
  ServerLimits limits;
  limits.max_frames = std::numeric_limits<int64_t>::max();
  limits.max_trajectory_values = std::numeric_limits<int64_t>::max();
  limits.max_steps = std::numeric_limits<int64_t>::max() / 4;
  return limits;
}

// The number of items finished; an error when the submission or the
// watch failed, or an item did not succeed.
inline absl::StatusOr<int> RunSweepToTheEnd(v1::CablesimService::Stub* stub,
                                            const v1::SubmitSweepRequest& request) {
  v1::Sweep sweep;
  {
    grpc::ClientContext context;
    const grpc::Status s = stub->SubmitSweep(&context, request, &sweep);
    if (!s.ok()) return absl::InternalError("SubmitSweep failed: " + s.error_message());
  }
  grpc::ClientContext context;
  v1::WatchSweepRequest watch;
  watch.set_id(sweep.id());
  auto reader = stub->WatchSweep(&context, watch);
  v1::SweepEvent event;
  while (reader->Read(&event)) {
  }
  if (!reader->Finish().ok() || event.progress().failed() != 0) {
    return absl::InternalError("sweep failed");
  }
  return event.progress().finished();
}

}  // namespace cablesim

#endif  // CABLESIM_BENCH_SWEEP_BENCH_UTIL_H_
