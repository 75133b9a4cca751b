#include "client/cli.h"

#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>

#include <google/protobuf/util/json_util.h>

#include "CLI/CLI.hpp"
#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/ascii.h"
#include "cablesim/version.h"
#include "client/cli_common.h"
#include "client/cli_health.h"
#include "client/cli_jobs.h"
#include "client/cli_sweep.h"
#include "client/json_line.h"
#include "client/progress.h"
#include "client/service_client.h"
#include "client/summary_json.h"
#include "convert/run_proto.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"
#include "engine/scene/integrator_traits.h"

// The arguments are parsed with CLI11 rather than with absl flags: absl's
// parser exits the process (with status 1) on an unknown flag or --help and
// keeps the flag values in globals, while RunCli must return exit code 2 for
// usage errors and be callable any number of times in one process.

namespace cablesim {
namespace {

using cli_internal::Arguments;
using cli_internal::CallFailed;
using cli_internal::ConnectOrReport;
using cli_internal::LazyCsvSink;
using cli_internal::ReadScene;
using cli_internal::ReportSummary;
using cli_internal::UsageError;

// Options that take a value, besides --out and --server.
const std::set<std::string>& ValueOptions() {
  static const std::set<std::string>* options =
      new std::set<std::string>{"state",
                                "sweep",
                                "limit",
                                "workers",
                                "max-energy-drift",
                                "max-wall-seconds",
                                "max-constraint-violation",
                                "tls-ca",
                                "token-file",
                                "item",
                                "shape",
                                "max",
                                "min",
                                "junit"};
  return *options;
}

// Options that take no value.
const std::set<std::string>& FlagOptions() {
  static const std::set<std::string>* flags =
      new std::set<std::string>{"allow-outside", "no-limits", "strict"};
  return *flags;
}

// Parses `args` with CLI11 (Debian's libcli11-dev); returns an error
// message for a usage error. Kept from the parser this replaced: a single
// dash before a long name (`-out`, `-help`, as Go's flag package and the
// server's Abseil flags take them), `--name=value`, `-o` for --out, and the
// messages users' scripts have seen ("unknown option --x", "--out needs a
// file", "--strict takes no value").
absl::StatusOr<Arguments> ParseArguments(const std::vector<std::string>& args) {
  Arguments parsed;
  // CLI11 reads long names after two dashes only: `-name` becomes `--name`
  // (but `-o`, `-h` and what follows `--` stay as they are).
  std::vector<std::string> argv;
  bool options_done = false;
  for (const std::string& arg : args) {
    if (arg == "--") options_done = true;
    if (!options_done && arg.size() > 2 && arg[0] == '-' && arg[1] != '-' && arg[2] != '=') {
      argv.push_back("-" + arg);
    } else {
      argv.push_back(arg);
    }
  }
  CLI::App app("cablesim");
  app.set_help_flag();  // --help is a flag of ours: the usage text is CliUsage()
  app.allow_extras();   // unknown options are reported below, in our words
  app.add_flag("-h,--help", parsed.help);
  app.add_flag("--version", parsed.version);
  std::map<std::string, CLI::Option*> valued;
  auto add_valued = [&](const std::string& name) {
    CLI::Option* o = app.add_option(name == "out" ? "-o,--out" : "--" + name);
    o->type_size(1)->expected(1)->allow_extra_args(false);
    o->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    valued[name] = o;
  };
  add_valued("out");
  add_valued("server");
  for (const std::string& name : ValueOptions()) add_valued(name);
  std::map<std::string, CLI::Option*> flags;
  for (const std::string& name : FlagOptions()) {
    flags[name] = app.add_flag("--" + name)->disable_flag_override();
  }
  app.add_option("positional", parsed.positional);
  // CLI11 takes the arguments last first.
  std::vector<std::string> reversed(argv.rbegin(), argv.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    // The option CLI11 names: the first "--name" in its message.
    const std::string what = e.what();
    std::string name;
    // (some messages give the name without its dashes, first: "strict was
    // given a disallowed flag override").
    const size_t dashes = what.find("--");
    if (const size_t at = dashes != std::string::npos ? dashes + 2 : 0; true) {
      size_t end = at;
      while (end < what.size() && (absl::ascii_isalnum(what[end]) || what[end] == '-')) ++end;
      name = what.substr(at, end - at);
    }
    if (flags.count(name)) {
      return absl::InvalidArgumentError(absl::StrCat("--", name, " takes no value"));
    }
    if (valued.count(name)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", name, name == "out" ? " needs a file" : " needs a value"));
    }
    return absl::InvalidArgumentError(what);
  }
  for (const std::string& extra : app.remaining()) {
    return absl::InvalidArgumentError(absl::StrCat("unknown option ", extra));
  }
  for (const auto& [name, option] : flags) {
    if (option->count() > 0) parsed.options[name] = "";
  }
  // Values in the order given (the last wins for a single option; --max and
  // --min keep every one, in order).
  std::map<const CLI::Option*, size_t> seen;
  std::map<const CLI::Option*, std::string> name_of;
  for (const auto& [name, option] : valued) name_of[option] = name;
  for (const CLI::Option* option : app.parse_order()) {
    const auto named = name_of.find(option);
    if (named == name_of.end()) continue;
    const std::string& name = named->second;
    const std::string& value = option->results().at(seen[option]++);
    if (value.empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", name, name == "out" ? " needs a file" : " needs a value"));
    }
    if (name == "out") {
      parsed.out = value;
    } else if (name == "server") {
      parsed.server = value;
    } else {
      parsed.options[name] = value;
      if (name == "max" || name == "min") parsed.repeated.emplace_back(name, value);
    }
  }
  return parsed;
}

int Validate(const std::string& path, const std::optional<std::string>& server, std::ostream& out,
             std::ostream& err) {
  std::string error;
  const std::optional<v1::Scene> proto = ReadScene(path, err, &error);
  auto invalid = [&](const std::string& message) {
    out << JsonLine().Add("status", "invalid").Add("file", path).Add("error", message).ToString()
        << "\n";
    out.flush();
    return kExitBadInput;
  };
  if (!proto.has_value()) return invalid(error);
  std::unique_ptr<Connection> c = ConnectOrReport(server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  v1::ValidateRequest request;
  *request.mutable_scene() = *proto;
  v1::ValidateResponse response;
  const absl::Status status = FromGrpc(c->stub->Validate(&context, request, &response));
  if (!status.ok()) return CallFailed(err, status, path);
  if (!response.valid()) {
    const v1::FieldError& e = response.errors(0);
    const std::string message =
        e.path().empty() ? e.message() : absl::StrCat(e.path(), ": ", e.message());
    err << "cablesim: " << path << ": " << message << "\n";
    return invalid(message);
  }
  // Valid: describe it (the counts and settings, with the defaults applied).
  const absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  if (!scene.ok()) return invalid(std::string(scene.status().message()));
  const ModelInfo info = ModelInfoFromProto(response.model());
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
      .Add("model", info.model)
      .Add("coordinates", static_cast<int64_t>(info.coordinates))
      .Add("dofs", static_cast<int64_t>(info.dofs))
      .Add("multipliers", static_cast<int64_t>(info.multipliers))
      .Add("elements", static_cast<int64_t>(info.elements))
      .Add("nodes", static_cast<int64_t>(info.nodes));
  if (solver.analysis == Analysis::kDynamic) {
    json.Add("duration_s", solver.duration_s)
        .Add("step_s", solver.step_s)
        .Add("output_interval_s", solver.output_interval_s);
  } else {
    json.Add("load_steps", solver.load_steps);
  }
  // Plausibility warnings (the service's, so that --server lists its own).
  const std::vector<std::string> warnings(response.warnings().begin(),
                                          response.warnings().end());
  json.Add("warnings", warnings);
  out << json.ToString() << "\n";
  out.flush();
  for (const std::string& warning : warnings) err << "cablesim: warning: " << warning << "\n";
  return kExitOk;
}

// The shape CSV of a run: --shape FILE (which also asks the scene for its
// shape), else FILE.shape.csv beside --out FILE.csv when the scene's
// output.shape is true, else none.
std::optional<std::string> ShapePath(const std::optional<std::string>& shape_flag,
                                     const std::optional<std::string>& csv_path,
                                     v1::Scene* scene) {
  if (shape_flag.has_value()) {
    scene->mutable_output()->set_shape(true);
    return shape_flag;
  }
  if (!scene->output().shape() || !csv_path.has_value()) return std::nullopt;
  std::string base = *csv_path;
  if (absl::EndsWith(base, ".csv")) base.resize(base.size() - 4);
  return base + ".shape.csv";
}

int Run(const std::string& path, const std::optional<std::string>& csv_path,
        const std::optional<std::string>& shape_flag, const std::optional<std::string>& server,
        bool strict, std::ostream& out, std::ostream& err) {
  std::string error;
  std::optional<v1::Scene> proto = ReadScene(path, err, &error);
  if (!proto.has_value()) return kExitBadInput;
  const std::optional<std::string> shape_path = ShapePath(shape_flag, csv_path, &*proto);
  // Without --server: the service in this process, called directly (the
  // same service code, no gRPC start-up; see RunInProcess).
  std::unique_ptr<Connection> c;
  if (server.has_value()) {
    c = ConnectOrReport(server, false, 0, err);
  } else if (absl::StatusOr<std::unique_ptr<Connection>> local = ConnectInProcessDirect();
             local.ok()) {
    c = std::move(*local);
  } else {
    err << "cablesim: " << local.status().message() << "\n";
  }
  if (c == nullptr) return kExitIoError;

  LazyCsvSink sink(csv_path, shape_path);
  Progress progress(&err, Progress::IsTerminal(err), "run");
  v1::RunRequest request;
  *request.mutable_scene() = *proto;
  request.set_frames_per_batch(256);
  request.set_strict(strict);
  const auto on_frame_time = [&](double t, double end) {
    progress.Update(end > 0 ? t / end : 0, absl::StrFormat("t = %.4g s", t));
  };
  absl::StatusOr<RunSummary> summary;
  if (server.has_value()) {
    grpc::ClientContext context;
    std::unique_ptr<grpc::ClientReader<v1::RunEvent>> reader = c->stub->Run(&context, request);
    summary = ReadRunStream(&context, reader.get(), &sink, on_frame_time);
  } else {
    summary = RunInProcess(c.get(), request, &sink, on_frame_time);
  }
  progress.Done();
  const absl::Status csv_status = sink.Finish();
  // A failed CSV write stops the run, whatever the service then reports.
  if (!csv_status.ok()) {
    err << "cablesim: " << csv_status.message() << "\n";
    return kExitIoError;
  }
  if (!summary.ok()) return CallFailed(err, summary.status(), path);
  return ReportSummary(*summary, out, err);
}

// `cablesim import`: a MoorDyn deck (or any scene file) written as a JSON
// scene file, proto field names, two-space indents.
int Import(const std::string& path, const std::optional<std::string>& out_path,
           std::ostream& out, std::ostream& err) {
  if (!out_path.has_value()) return UsageError(err, "import: missing --out SCENE.json");
  std::string error;
  const std::optional<v1::Scene> proto = ReadScene(path, err, &error);
  if (!proto.has_value()) return kExitBadInput;
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  if (const auto s = google::protobuf::util::MessageToJsonString(*proto, &json, options); !s.ok()) {
    err << "cablesim: " << path << ": " << s.message() << "\n";
    return kExitBadInput;
  }
  std::ofstream file(*out_path, std::ios::binary);
  file << json;
  file.close();
  if (!file) {
    err << "cablesim: cannot write " << *out_path << "\n";
    return kExitIoError;
  }
  out << JsonLine().Add("status", "ok").Add("file", path).Add("out", *out_path).ToString()
      << "\n";
  out.flush();
  return kExitOk;
}

}  // namespace

std::string CliUsage() {
  return R"(Usage:
  cablesim run SCENE [--out FILE.csv] [--shape SHAPE.csv] [--server HOST:PORT] [--strict]
      Run the scene's analysis and print the run summary as one JSON line.
      With --out, write the trajectory (one row per output frame) as CSV.
      With --shape (or the scene's output.shape, beside --out as
      FILE.shape.csv), write every cable node's position per frame as CSV
      t,cable,node,s,x,y,z.
      The run goes through the cablesim service: one started in this
      process, or the cablesim-server at --server.
      Warnings (the error estimate over the tolerance, inexact linear
      solves accepted, steps cut far below solver.step) are printed on
      standard error and listed in the summary's "warnings"; with --strict
      they fail the run (exit 3). docs/honest-runs.md.
      SCENE may also be a MoorDyn v2 input file (a .dat file, or MoorDyn's
      .txt inputs): it is read as docs/moordyn-files.md describes (here and
      in validate, submit and energy).
  cablesim validate SCENE [--server HOST:PORT]
      Check the scene and print one JSON line describing it.
  cablesim import FILE.dat --out SCENE.json
      Translate a MoorDyn v2 input file into a cablesim scene file (JSON),
      to read or edit; a deck the scene cannot express exits 2 naming the
      file's line and field.
  cablesim submit SCENE --server HOST:PORT [--strict]
      Queue the scene as a durable job; print the job (its id) at once.
      With --strict, a job whose run has warnings fails.
  cablesim jobs --server HOST:PORT [--state STATE] [--sweep ID] [--limit N]
      List jobs, newest first, one JSON line each.
  cablesim watch JOB --server HOST:PORT [--out FILE.csv]
      Follow a job until it finishes; print its summary (and with --out
      write its trajectory).
  cablesim cancel JOB --server HOST:PORT
      Cancel a queued or running job.
  cablesim energy (SCENE | JOB) [--server HOST:PORT] [--out FILE.csv]
      Energy diagnostics of a scene (run for the purpose) or a finished job:
      one JSON line with the report; --out writes the time series.
  cablesim sweep SWEEP.json [--out results.csv] [--server HOST:PORT]
                 [--workers N] [--max-energy-drift X] [--max-wall-seconds X]
                 [--max-constraint-violation X] [--allow-outside] [--item I]
                 [--max COLUMN=X]... [--min COLUMN=X]... [--junit FILE.xml]
      Queue a parameter sweep, wait for every item and write one row per
      item (axis values, summary, final probe values). Without --server the
      sweep runs in this process on N workers (default: the cores). The
      sweep file's base_file must lie under the sweep file's directory
      unless --allow-outside. With --item I only item I (0-based, the last
      axis varying fastest) runs and its row is written, under index I.
      --max/--min (repeatable): an item fails when the frame column's
      largest value over its run is above X (smallest below X), e.g.
      --max hook.y=1.2 --min top.fz=0 (docs/outputs-statistics.md).
      --junit writes a JUnit XML report, one testcase per item.
  cablesim health --server HOST:PORT
      Ask the server's gRPC health service whether it is serving; print one
      JSON line; exit 0 only when it is SERVING.
  cablesim help | --help
      Print this text.
  cablesim --version
      Print the version and the build type.

SCENE is a cablesim.v1.Scene (proto/cablesim/v1/scene.proto) in protobuf
JSON, or in text format when its name ends in .txtpb, .textproto or .pbtxt,
or a MoorDyn v2 input file (docs/moordyn-files.md).
SWEEP.json is a cablesim.v1.SweepFile (proto/cablesim/v1/service.proto).

--server takes any gRPC target: HOST:PORT, several servers sharing one job
store (ipv4:127.0.0.1:50051,127.0.0.1:50052) or a DNS name with several
addresses (dns:///cablesim.example:50051); calls are spread over them
(gRPC's round_robin policy) and go on when one of them stops.

Without --server, scenes run in this process under the server's default
limits (cablesim-server --help lists them: elements, steps, frames, ...);
--no-limits lifts them.

With --server, every command also takes --tls-ca CA.pem (TLS, the server's
certificate checked against that CA) and --token-file FILE (the first word
of its first line that is not a # comment is sent as a bearer token).

Exit status: 0 success; 1 error writing the output or reaching the server,
or the run (watch: the job) was cancelled; 2 bad input (usage, scene or
sweep file, invalid scene, a server limit); 3 numerical failure of the run
(for sweep: an item failed or a threshold was exceeded). README.md has the
table for every command.
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
  if (a.version) {
    out << VersionLine("cablesim") << "\n";
    out.flush();
    return kExitOk;
  }
  if (a.positional.empty()) return UsageError(err, "missing command");
  const std::string& command = a.positional[0];
  static const std::map<std::string, const char*> kArgument = {
      {"run", "SCENE"}, {"validate", "SCENE"}, {"submit", "SCENE"},        {"jobs", nullptr},
      {"watch", "JOB"}, {"cancel", "JOB"},     {"energy", "SCENE or JOB"}, {"sweep", "SWEEP.json"},
      {"health", nullptr}, {"import", "FILE.dat"}};
  const auto known = kArgument.find(command);
  if (known == kArgument.end()) {
    return UsageError(err, absl::StrCat("unknown command \"", command, "\""));
  }
  const size_t wanted = known->second != nullptr ? 2 : 1;
  if (a.positional.size() < wanted) {
    return UsageError(err, absl::StrCat(command, ": missing ", known->second));
  }
  if (a.positional.size() > wanted) {
    return UsageError(
        err, absl::StrCat(command, ": unexpected argument \"", a.positional[wanted], "\""));
  }
  RemoteSecurity security;
  for (const auto& [name, value] : a.options) {
    if (name == "tls-ca" || name == "token-file") {
      if (!a.server.has_value()) {
        return UsageError(err, absl::StrCat("--", name, " is for a --server"));
      }
      std::ifstream in(value, std::ios::binary);
      std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (!in.good() && !in.eof()) text.clear();
      if (text.empty()) {
        err << "cablesim: cannot read " << value << " (--" << name << ")\n";
        return kExitIoError;
      }
      if (name == "tls-ca") {
        security.tls_ca_pem = text;
      } else {
        // The first token of the first line that is not a comment.
        for (absl::string_view line : absl::StrSplit(text, '\n')) {
          line = absl::StripAsciiWhitespace(line);
          if (line.empty() || line[0] == '#') continue;
          security.token = std::string(line.substr(0, line.find_first_of(" \t")));
          break;
        }
      }
      continue;
    }
    if (name == "no-limits") {
      if (a.server.has_value()) {
        return UsageError(err, "--no-limits is for runs in this process (a server sets its own)");
      }
      continue;
    }
    const bool allowed =
        (command == "run" && (name == "shape" || name == "strict")) ||
        (command == "submit" && name == "strict") ||
        (command == "jobs" && (name == "state" || name == "sweep" || name == "limit")) ||
        (command == "sweep" && name != "state" && name != "sweep" && name != "limit");
    if (!allowed) return UsageError(err, absl::StrCat(command, ": no option --", name));
  }
  if (a.out.has_value() && command != "run" && command != "watch" && command != "energy" &&
      command != "sweep" && command != "import") {
    return UsageError(err, absl::StrCat(command, ": --out is only for run"));
  }
  SetRemoteSecurity(security);
  SetInProcessLimits(a.options.count("no-limits") == 0);
  if (command == "validate") return Validate(a.positional[1], a.server, out, err);
  if (command == "run") {
    std::optional<std::string> shape;
    if (auto it = a.options.find("shape"); it != a.options.end()) shape = it->second;
    return Run(a.positional[1], a.out, shape, a.server, a.options.count("strict") > 0, out, err);
  }
  if (command == "import") return Import(a.positional[1], a.out, out, err);
  if (command == "submit") return cli_internal::Submit(a, out, err);
  if (command == "jobs") return cli_internal::Jobs(a, out, err);
  if (command == "watch") return cli_internal::Watch(a, out, err);
  if (command == "cancel") return cli_internal::Cancel(a, out, err);
  if (command == "energy") return cli_internal::Energy(a, out, err);
  if (command == "health") return cli_internal::Health(a, out, err);
  return cli_internal::SweepCommand(a, out, err);
}

int RunCli(int argc, char** argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  return RunCli(args, out, err);
}

}  // namespace cablesim
