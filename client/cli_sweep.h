#ifndef CABLESIM_CLIENT_CLI_SWEEP_H_
#define CABLESIM_CLIENT_CLI_SWEEP_H_

// `cablesim sweep SWEEP.json` (client/cli.h): queues the sweep, waits for
// every item, writes one CSV row per item and checks the thresholds.
// Returns the exit code (3 when an item failed or a threshold is exceeded).
// With --item I only item I runs (in-process, or on --server) and its row
// is written under index I: one pod of an Indexed Job per item
// (deploy/kubernetes/sweep-indexed-job.yaml).

#include <cstdint>
#include <ostream>

#include "absl/status/status.h"
#include "cablesim/v1/service.pb.h"
#include "client/cli_common.h"

namespace cablesim::cli_internal {

int SweepCommand(const Arguments& a, std::ostream& out, std::ostream& err);

// Narrows `request` to its item `item` (0 to the product of the axes' value
// counts - 1; the last axis varies fastest): each axis keeps only the value
// it takes there, so the one-item sweep runs exactly that item's scene.
// InvalidArgument for an axis without values.
absl::Status NarrowSweepToItem(int64_t item, v1::SubmitSweepRequest* request);

}  // namespace cablesim::cli_internal

#endif  // CABLESIM_CLIENT_CLI_SWEEP_H_
