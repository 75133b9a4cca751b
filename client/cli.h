#ifndef CABLESIM_CLIENT_CLI_H_
#define CABLESIM_CLIENT_CLI_H_

// The `cablesim` command line, callable in-process (tests call it directly;
// client/cablesim_main.cc forwards main's arguments):
//
//   cablesim run SCENE [--out FILE.csv] [--shape SHAPE.csv] [--server HOST:PORT]
//   cablesim validate SCENE [--server HOST:PORT]
//   cablesim submit SCENE --server HOST:PORT
//   cablesim jobs --server HOST:PORT [--state S] [--sweep ID] [--limit N]
//   cablesim watch JOB --server HOST:PORT [--out FILE.csv]
//   cablesim cancel JOB --server HOST:PORT
//   cablesim energy (SCENE | JOB) [--server HOST:PORT] [--out FILE.csv]
//   cablesim sweep SWEEP.json [--out results.csv] [--server HOST:PORT]
//                  [--workers N] [--max-energy-drift X] [--max-wall-seconds X]
//                  [--max-constraint-violation X]
//   cablesim help | --help
//
// Every command goes through cablesim.v1.CablesimService: the cablesim-server
// at --server, or one started in this process (in-process channel), so a
// local and a remote run share one code path (client/service_client.h).
// SCENE is a cablesim.v1.Scene in protobuf JSON or text format
// (convert/scene_file.h). `run` prints the run summary as one JSON line on
// `out` (client/summary_json.h) and, with --out, writes the trajectory CSV
// (client/csv_writer.h). `validate` prints one JSON line describing the
// scene. The job commands print one JSON line per job; `sweep` writes one CSV
// row per item. Errors go to `err` as `cablesim: MESSAGE`.
//
// Exit codes: 0 success; 1 I/O failure writing the output or reaching the
// server; 2 bad input (usage, unreadable or unparsable scene file, invalid
// scene); 3 numerical failure of the run (sweep: an item failed or a
// threshold was exceeded; the summary or table is still written).

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
