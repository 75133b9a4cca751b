#ifndef CABLESIM_CLIENT_CLI_JOBS_H_
#define CABLESIM_CLIENT_CLI_JOBS_H_

// The job commands of `cablesim` (client/cli.h): submit, jobs, watch,
// cancel, energy. Each returns the exit code.

#include <ostream>

#include "client/cli_common.h"

namespace cablesim::cli_internal {

int Submit(const Arguments& a, std::ostream& out, std::ostream& err);
int Jobs(const Arguments& a, std::ostream& out, std::ostream& err);
int Watch(const Arguments& a, std::ostream& out, std::ostream& err);
int Cancel(const Arguments& a, std::ostream& out, std::ostream& err);
// SCENE (a file) runs in-process unless --server; anything else is a job id.
int Energy(const Arguments& a, std::ostream& out, std::ostream& err);

}  // namespace cablesim::cli_internal

#endif  // CABLESIM_CLIENT_CLI_JOBS_H_
