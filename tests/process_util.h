#ifndef CABLESIM_TESTS_PROCESS_UTIL_H_
#define CABLESIM_TESTS_PROCESS_UTIL_H_

// Runs a shell command line as a user would (the built binaries), for the
// tests of the command line.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace cablesim::testing {

struct Process {
  int exit_code = -1;  // -1: it did not exit normally
  std::string out;
};

// Runs `command` with /bin/sh, capturing its stdout (stderr passes through
// unless the command redirects it, e.g. with 2>&1).
inline Process RunCommand(const std::string& command) {
  Process result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.out.append(buffer, n);
  const int status = pclose(pipe);
  if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_PROCESS_UTIL_H_
