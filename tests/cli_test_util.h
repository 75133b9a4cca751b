#ifndef CABLESIM_TESTS_CLI_TEST_UTIL_H_
#define CABLESIM_TESTS_CLI_TEST_UTIL_H_

// `cablesim ARGS...` run in this process (client/cli.h's RunCli), for
// tests of the command line: its exit code, its standard output in `out`
// and its standard error in `err`.

#include <sstream>
#include <string>
#include <vector>

#include "client/cli.h"

namespace cablesim::testing {

inline int Cli(const std::vector<std::string>& args, std::string* out, std::string* err) {
  std::ostringstream o, e;
  const int code = RunCli(args, o, e);
  *out = o.str();
  *err = e.str();
  return code;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_CLI_TEST_UTIL_H_
