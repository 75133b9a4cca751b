#include "client/cli.h"

#include <memory>
#include <optional>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/csv_writer.h"
#include "client/json_line.h"
#include "client/summary_json.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/simulation.h"

// The arguments are parsed here rather than with absl flags: absl's parser
// exits the process (with status 1) on an unknown flag or --help and keeps
// the flag values in globals, while RunCli must return exit code 2 for usage
// errors and be callable any number of times in one process.

namespace cablesim {
namespace {

struct Arguments {
  std::vector<std::string> positional;  // command first
  std::optional<std::string> out;       // --out
  bool help = false;
};

// Parses `args`; returns an error message for a usage error.
absl::StatusOr<Arguments> ParseArguments(const std::vector<std::string>& args) {
  Arguments parsed;
  bool options_done = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_done || arg.size() < 2 || arg[0] != '-') {
      parsed.positional.push_back(arg);
    } else if (arg == "--") {
      options_done = true;
    } else if (arg == "--help" || arg == "-h" || arg == "-help") {
      parsed.help = true;
    } else if (arg == "--out" || arg == "-out" || arg == "-o") {
      if (i + 1 >= args.size())
        return absl::InvalidArgumentError(absl::StrCat(arg, " needs a file"));
      parsed.out = args[++i];
    } else if (absl::StartsWith(arg, "--out=") || absl::StartsWith(arg, "-out=")) {
      parsed.out = arg.substr(arg.find('=') + 1);
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown option ", arg));
    }
    if (parsed.out.has_value() && parsed.out->empty()) {
      return absl::InvalidArgumentError("--out needs a file");
    }
  }
  return parsed;
}

int UsageError(std::ostream& err, absl::string_view message) {
  err << "cablesim: " << message << "\n\n" << CliUsage();
  err.flush();
  return kExitBadInput;
}

// Discards the frames of a run without --out.
class DiscardingSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame&) override { return absl::OkStatus(); }
};

// Reads and validates the scene at `path`; on failure reports it on `err`
// and returns nullopt.
std::optional<Scene> LoadScene(const std::string& path, std::ostream& err,
                               std::string* error_message) {
  absl::StatusOr<v1::Scene> proto = ReadSceneFile(path);
  if (!proto.ok()) {
    // ReadSceneFile's messages start with the path.
    *error_message = std::string(proto.status().message());
    err << "cablesim: " << *error_message << "\n";
    return std::nullopt;
  }
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  if (!scene.ok()) {
    *error_message = std::string(scene.status().message());
    err << "cablesim: " << path << ": " << *error_message << "\n";
    return std::nullopt;
  }
  return std::move(*scene);
}

int Validate(const std::string& path, std::ostream& out, std::ostream& err) {
  std::string error;
  const std::optional<Scene> scene = LoadScene(path, err, &error);
  if (!scene.has_value()) {
    out << JsonLine().Add("status", "invalid").Add("file", path).Add("error", error).ToString()
        << "\n";
    out.flush();
    return kExitBadInput;
  }
  // The engine's own checks (joint sides that do not meet at t = 0, ...)
  // and what it would build.
  const absl::StatusOr<ModelInfo> info = DescribeModel(*scene);
  if (!info.ok()) {
    err << "cablesim: " << path << ": " << info.status().message() << "\n";
    out << JsonLine()
               .Add("status", "invalid")
               .Add("file", path)
               .Add("error", std::string(info.status().message()))
               .ToString()
        << "\n";
    out.flush();
    return kExitBadInput;
  }
  const SolverSettings& solver = scene->solver;
  JsonLine json;
  json.Add("status", "ok")
      .Add("file", path)
      .Add("name", scene->name)
      .Add("cables", static_cast<int64_t>(scene->cables.size()))
      .Add("bodies", static_cast<int64_t>(scene->bodies.size()))
      .Add("joints", static_cast<int64_t>(scene->joints.size()))
      .Add("loads", static_cast<int64_t>(scene->loads.size()))
      .Add("probes", static_cast<int64_t>(scene->probes.size()))
      .Add("analysis", AnalysisName(solver.analysis))
      .Add("integrator", IntegratorName(solver.integrator))
      .Add("linear_solver", LinearSolverName(solver.linear_solver))
      .Add("model", info->model)
      .Add("coordinates", static_cast<int64_t>(info->coordinates))
      .Add("dofs", static_cast<int64_t>(info->dofs))
      .Add("multipliers", static_cast<int64_t>(info->multipliers))
      .Add("elements", static_cast<int64_t>(info->elements))
      .Add("nodes", static_cast<int64_t>(info->nodes));
  if (solver.analysis == Analysis::kDynamic) {
    json.Add("duration_s", solver.duration_s)
        .Add("step_s", solver.step_s)
        .Add("output_interval_s", solver.output_interval_s);
  } else {
    json.Add("load_steps", solver.load_steps);
  }
  out << json.ToString() << "\n";
  out.flush();
  return kExitOk;
}

int Run(const std::string& path, const std::optional<std::string>& csv_path, std::ostream& out,
        std::ostream& err) {
  std::string error;
  const std::optional<Scene> scene = LoadScene(path, err, &error);
  if (!scene.has_value()) return kExitBadInput;

  std::unique_ptr<CsvWriter> csv;
  DiscardingSink discard;
  FrameSink* sink = &discard;
  if (csv_path.has_value()) {
    absl::StatusOr<std::unique_ptr<CsvWriter>> created = CsvWriter::Create(*csv_path);
    if (!created.ok()) {
      err << "cablesim: " << created.status().message() << "\n";
      return kExitIoError;
    }
    csv = std::move(*created);
    sink = csv.get();
  }

  const absl::StatusOr<RunSummary> summary = RunScene(*scene, sink);
  const absl::Status csv_status = csv != nullptr ? csv->Finish() : absl::OkStatus();
  if (summary.ok()) {
    out << SummaryToJson(*summary) << "\n";
    out.flush();
  }
  // A failed CSV write stops the run, whatever the engine then reports.
  if (!csv_status.ok()) {
    err << "cablesim: " << csv_status.message() << "\n";
    return kExitIoError;
  }
  if (!summary.ok()) {
    err << "cablesim: " << path << ": " << summary.status().message() << "\n";
    return kExitBadInput;
  }
  if (summary->status == "failed") {
    err << "cablesim: numerical failure at t = "
        << absl::StrFormat("%.10g", summary->failure_time_s) << ": " << summary->error << "\n";
    return kExitNumericalFailure;
  }
  if (summary->status != "ok") {
    err << "cablesim: run " << summary->status
        << (summary->error.empty() ? "" : absl::StrCat(": ", summary->error)) << "\n";
    return kExitIoError;
  }
  return kExitOk;
}

}  // namespace

std::string CliUsage() {
  return R"(Usage:
  cablesim run SCENE [--out FILE.csv]
      Run the scene's analysis and print the run summary as one JSON line.
      With --out, write the trajectory (one row per output frame) as CSV.
  cablesim validate SCENE
      Check the scene and print one JSON line describing it.
  cablesim help
      Print this text.

SCENE is a cablesim.v1.Scene (proto/cablesim/v1/scene.proto) in protobuf
JSON, or in text format when its name ends in .txtpb, .textproto or .pbtxt.

Exit status: 0 success, 1 error writing the output, 2 bad input (usage,
scene file or scene), 3 numerical failure of the run.
)";
}

int RunCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const absl::StatusOr<Arguments> parsed = ParseArguments(args);
  if (!parsed.ok()) return UsageError(err, parsed.status().message());
  const Arguments& a = *parsed;
  if (a.help || (!a.positional.empty() && a.positional[0] == "help")) {
    out << CliUsage();
    out.flush();
    return kExitOk;
  }
  if (a.positional.empty()) return UsageError(err, "missing command");
  const std::string& command = a.positional[0];
  if (command != "run" && command != "validate") {
    return UsageError(err, absl::StrCat("unknown command \"", command, "\""));
  }
  if (a.positional.size() < 2) return UsageError(err, absl::StrCat(command, ": missing SCENE"));
  if (a.positional.size() > 2) {
    return UsageError(err,
                      absl::StrCat(command, ": unexpected argument \"", a.positional[2], "\""));
  }
  const std::string& scene_path = a.positional[1];
  if (command == "validate") {
    if (a.out.has_value()) return UsageError(err, "validate: --out is only for run");
    return Validate(scene_path, out, err);
  }
  return Run(scene_path, a.out, out, err);
}

int RunCli(int argc, char** argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  return RunCli(args, out, err);
}

}  // namespace cablesim
