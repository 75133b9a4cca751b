#ifndef CABLESIM_CLIENT_CLI_SWEEP_H_
#define CABLESIM_CLIENT_CLI_SWEEP_H_

// `cablesim sweep SWEEP.json` (client/cli.h): queues the sweep, waits for
// every item, writes one CSV row per item and checks the thresholds.
// Returns the exit code (3 when an item failed or a threshold is exceeded).

#include <ostream>

#include "client/cli_common.h"

namespace cablesim::cli_internal {

int SweepCommand(const Arguments& a, std::ostream& out, std::ostream& err);

}  // namespace cablesim::cli_internal

#endif  // CABLESIM_CLIENT_CLI_SWEEP_H_
