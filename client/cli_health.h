#ifndef CABLESIM_CLIENT_CLI_HEALTH_H_
#define CABLESIM_CLIENT_CLI_HEALTH_H_

// `cablesim health --server HOST:PORT` (client/cli.h): asks the server's
// standard gRPC health service (grpc.health.v1.Health/Check, the whole
// server: service "") whether it is serving, prints one JSON line
// {"server": ..., "status": "SERVING" | "NOT_SERVING" | ...} and returns 0
// only for SERVING (1 otherwise, or when the server cannot be reached
// within 5 s). A probe for container health checks (deploy/Dockerfile,
// deploy/compose.yaml) on images without grpc_health_probe.

#include <ostream>

#include "client/cli_common.h"

namespace cablesim::cli_internal {

int Health(const Arguments& a, std::ostream& out, std::ostream& err);

}  // namespace cablesim::cli_internal

#endif  // CABLESIM_CLIENT_CLI_HEALTH_H_
