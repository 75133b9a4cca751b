#ifndef CABLESIM_CLIENT_CLI_H_
#define CABLESIM_CLIENT_CLI_H_

// The `cablesim` command line, callable in-process (tests call it directly;
// client/cablesim_main.cc forwards main's arguments):
//
//   cablesim run SCENE [--out FILE.csv]
//   cablesim validate SCENE
//   cablesim help | --help
//
// SCENE is a cablesim.v1.Scene in protobuf JSON or text format
// (convert/scene_file.h). `run` prints the run summary as one JSON line on
// `out` (client/summary_json.h) and, with --out, writes the trajectory CSV
// (client/csv_writer.h). `validate` prints one JSON line describing the
// scene. Errors go to `err` as `cablesim: MESSAGE`.
//
// Exit codes: 0 success; 1 I/O failure writing the CSV; 2 bad input (usage,
// unreadable or unparsable scene file, invalid scene); 3 numerical failure
// of the run (the summary is still printed).

#include <ostream>
#include <string>
#include <vector>

namespace cablesim {

// Exit codes of RunCli.
inline constexpr int kExitOk = 0;
inline constexpr int kExitIoError = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNumericalFailure = 3;

// Runs the command line `argv[0..argc)` (argv[0] is the program name).
// Keeps no state between calls.
int RunCli(int argc, char** argv, std::ostream& out, std::ostream& err);

// As above, with the arguments after the program name.
int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

// The --help text.
std::string CliUsage();

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_CLI_H_
