#include "client/cli.h"

#include <google/protobuf/util/json_util.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/csv_writer.h"
#include "client/json_line.h"
#include "client/progress.h"
#include "client/service_client.h"
#include "client/summary_json.h"
#include "convert/run_proto.h"
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
  std::vector<std::string> positional;         // command first
  std::optional<std::string> out;              // --out
  std::optional<std::string> server;           // --server
  std::map<std::string, std::string> options;  // the other --name value
  bool help = false;
};

// Options that take a value, besides --out and --server.
const std::set<std::string>& ValueOptions() {
  static const std::set<std::string>* options =
      new std::set<std::string>{"state",
                                "sweep",
                                "limit",
                                "workers",
                                "max-energy-drift",
                                "max-wall-seconds",
                                "max-constraint-violation"};
  return *options;
}

// Parses `args`; returns an error message for a usage error.
absl::StatusOr<Arguments> ParseArguments(const std::vector<std::string>& args) {
  Arguments parsed;
  bool options_done = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_done || arg.size() < 2 || arg[0] != '-') {
      parsed.positional.push_back(arg);
      continue;
    }
    if (arg == "--") {
      options_done = true;
      continue;
    }
    if (arg == "--help" || arg == "-h" || arg == "-help") {
      parsed.help = true;
      continue;
    }
    std::string name = arg.substr(arg[1] == '-' ? 2 : 1);
    std::optional<std::string> value;
    if (const size_t eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    if (name == "o") name = "out";
    if (name != "out" && name != "server" && !ValueOptions().count(name)) {
      return absl::InvalidArgumentError(absl::StrCat("unknown option ", arg));
    }
    if (!value.has_value()) {
      if (i + 1 >= args.size()) {
        return absl::InvalidArgumentError(
            absl::StrCat(arg, name == "out" ? " needs a file" : " needs a value"));
      }
      value = args[++i];
    }
    if (value->empty()) {
      return absl::InvalidArgumentError(
          absl::StrCat("--", name, name == "out" ? " needs a file" : " needs a value"));
    }
    if (name == "out") {
      parsed.out = *value;
    } else if (name == "server") {
      parsed.server = *value;
    } else {
      parsed.options[name] = *value;
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

// Creates the CSV when the run's header arrives (so an invalid scene leaves
// no file behind) and remembers whether an error was its own.
class LazyCsvSink : public FrameSink {
 public:
  explicit LazyCsvSink(std::optional<std::string> path) : path_(std::move(path)) {}
  absl::Status OnStart(const ModelInfo& info) override {
    if (!path_.has_value()) return absl::OkStatus();
    absl::StatusOr<std::unique_ptr<CsvWriter>> created = CsvWriter::Create(*path_);
    if (!created.ok()) return Fail(created.status());
    csv_ = std::move(*created);
    return Fail(csv_->OnStart(info));
  }
  absl::Status OnFrame(const Frame& frame) override {
    return csv_ != nullptr ? Fail(csv_->OnFrame(frame)) : absl::OkStatus();
  }
  // Finishes the CSV; its first error (or the creation error).
  absl::Status Finish() {
    if (!error_.ok()) return error_;
    return csv_ != nullptr ? csv_->Finish() : absl::OkStatus();
  }
  bool failed() const { return !error_.ok(); }

 private:
  absl::Status Fail(absl::Status s) {
    if (!s.ok() && error_.ok()) error_ = s;
    return s;
  }
  std::optional<std::string> path_;
  std::unique_ptr<CsvWriter> csv_;
  absl::Status error_;
};

// The exit code for a failed call to the service.
int ExitCodeFor(const absl::Status& s) {
  switch (s.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kResourceExhausted:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kFailedPrecondition:
      return kExitBadInput;
    default:
      return kExitIoError;
  }
}

// Reports a failed call (`what` prefixes messages about the input, such
// as the scene file) and returns its exit code.
int CallFailed(std::ostream& err, const absl::Status& s, const std::string& what) {
  const int code = ExitCodeFor(s);
  err << "cablesim: " << (code == kExitBadInput && !what.empty() ? what + ": " : "")
      << (code == kExitBadInput
              ? std::string(s.message())
              : absl::StrCat(absl::StatusCodeToString(s.code()), ": ", s.message()))
      << "\n";
  err.flush();
  return code;
}

// Reads the scene file at `path`; on failure reports it on `err`.
std::optional<v1::Scene> ReadScene(const std::string& path, std::ostream& err,
                                   std::string* error_message) {
  absl::StatusOr<v1::Scene> proto = ReadSceneFile(path);
  if (!proto.ok()) {
    // ReadSceneFile's messages start with the path.
    *error_message = std::string(proto.status().message());
    err << "cablesim: " << *error_message << "\n";
    return std::nullopt;
  }
  return std::move(*proto);
}

std::unique_ptr<Connection> ConnectOrReport(const std::optional<std::string>& server, bool jobs,
                                            int workers, std::ostream& err) {
  absl::StatusOr<std::unique_ptr<Connection>> c = Connect(server, jobs, workers);
  if (!c.ok()) {
    err << "cablesim: " << c.status().message() << "\n";
    return nullptr;
  }
  return std::move(*c);
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
  out << json.ToString() << "\n";
  out.flush();
  return kExitOk;
}

// Prints the summary and returns the exit code of a finished run.
int ReportSummary(const RunSummary& summary, std::ostream& out, std::ostream& err) {
  out << SummaryToJson(summary) << "\n";
  out.flush();
  if (summary.status == "failed") {
    err << "cablesim: numerical failure at t = " << absl::StrFormat("%.10g", summary.failure_time_s)
        << ": " << summary.error << "\n";
    return kExitNumericalFailure;
  }
  if (summary.status != "ok") {
    err << "cablesim: run " << summary.status
        << (summary.error.empty() ? "" : absl::StrCat(": ", summary.error)) << "\n";
    return kExitIoError;
  }
  return kExitOk;
}

int Run(const std::string& path, const std::optional<std::string>& csv_path,
        const std::optional<std::string>& server, std::ostream& out, std::ostream& err) {
  std::string error;
  const std::optional<v1::Scene> proto = ReadScene(path, err, &error);
  if (!proto.has_value()) return kExitBadInput;
  std::unique_ptr<Connection> c = ConnectOrReport(server, false, 0, err);
  if (c == nullptr) return kExitIoError;

  LazyCsvSink sink(csv_path);
  Progress progress(&err, Progress::IsTerminal(err), "run");
  grpc::ClientContext context;
  v1::RunRequest request;
  *request.mutable_scene() = *proto;
  request.set_frames_per_batch(256);
  std::unique_ptr<grpc::ClientReader<v1::RunEvent>> reader = c->stub->Run(&context, request);
  const absl::StatusOr<RunSummary> summary =
      ReadRunStream(&context, reader.get(), &sink, [&](double t, double end) {
        progress.Update(end > 0 ? t / end : 0, absl::StrFormat("t = %.4g s", t));
      });
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

std::string JobJson(const v1::Job& job) {
  JsonLine json;
  json.Add("id", job.id())
      .Add("state", v1::JobState_Name(job.state()))
      .Add("name", job.name())
      .Add("attempts", job.attempts())
      .Add("progress_time_s", job.progress_time_s())
      .Add("end_time_s", job.end_time_s())
      .Add("created_unix_ms", static_cast<int64_t>(job.created_unix_ms()));
  if (!job.sweep_id().empty())
    json.Add("sweep_id", job.sweep_id()).Add("sweep_index", job.sweep_index());
  if (job.has_summary()) {
    json.Add("status", job.summary().status());
    if (!job.summary().error().empty()) json.Add("error", job.summary().error());
    json.Add("wall_seconds", job.summary().wall_seconds());
  }
  return json.ToString();
}

std::optional<std::string> NeedServer(const Arguments& a, std::ostream& err) {
  if (!a.server.has_value()) {
    UsageError(err, absl::StrCat(a.positional[0], ": needs --server HOST:PORT"));
  }
  return a.server;
}

int Submit(const Arguments& a, std::ostream& out, std::ostream& err) {
  if (!NeedServer(a, err)) return kExitBadInput;
  const std::string& path = a.positional[1];
  std::string error;
  const std::optional<v1::Scene> proto = ReadScene(path, err, &error);
  if (!proto.has_value()) return kExitBadInput;
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  v1::SubmitJobRequest request;
  *request.mutable_scene() = *proto;
  v1::Job job;
  const absl::Status status = FromGrpc(c->stub->SubmitJob(&context, request, &job));
  if (!status.ok()) return CallFailed(err, status, path);
  out << JobJson(job) << "\n";
  out.flush();
  return kExitOk;
}

int Jobs(const Arguments& a, std::ostream& out, std::ostream& err) {
  if (!NeedServer(a, err)) return kExitBadInput;
  v1::ListJobsRequest request;
  if (auto it = a.options.find("state"); it != a.options.end()) {
    v1::JobState state;
    if (!v1::JobState_Parse(absl::AsciiStrToUpper(it->second), &state)) {
      return UsageError(err, absl::StrCat("--state: unknown state \"", it->second, "\""));
    }
    request.set_state(state);
  }
  if (auto it = a.options.find("sweep"); it != a.options.end()) request.set_sweep_id(it->second);
  if (auto it = a.options.find("limit"); it != a.options.end()) {
    int limit = 0;
    if (!absl::SimpleAtoi(it->second, &limit)) return UsageError(err, "--limit: not a number");
    request.set_limit(limit);
  }
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  v1::ListJobsResponse response;
  const absl::Status status = FromGrpc(c->stub->ListJobs(&context, request, &response));
  if (!status.ok()) return CallFailed(err, status, "");
  for (const v1::Job& job : response.jobs()) out << JobJson(job) << "\n";
  out.flush();
  return kExitOk;
}

int Cancel(const Arguments& a, std::ostream& out, std::ostream& err) {
  if (!NeedServer(a, err)) return kExitBadInput;
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  v1::CancelJobRequest request;
  request.set_id(a.positional[1]);
  v1::Job job;
  const absl::Status status = FromGrpc(c->stub->CancelJob(&context, request, &job));
  if (!status.ok()) return CallFailed(err, status, "");
  out << JobJson(job) << "\n";
  out.flush();
  return kExitOk;
}

int Watch(const Arguments& a, std::ostream& out, std::ostream& err) {
  if (!NeedServer(a, err)) return kExitBadInput;
  const std::string& id = a.positional[1];
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  v1::Job job;
  {
    Progress progress(&err, Progress::IsTerminal(err), id);
    grpc::ClientContext context;
    v1::WatchJobRequest request;
    request.set_id(id);
    std::unique_ptr<grpc::ClientReader<v1::Job>> reader = c->stub->WatchJob(&context, request);
    v1::JobState last = v1::JOB_STATE_UNSPECIFIED;
    while (reader->Read(&job)) {
      if (job.state() != last && !Progress::IsTerminal(err)) {
        err << "cablesim: " << id << " " << v1::JobState_Name(job.state()) << "\n";
      }
      last = job.state();
      progress.Update(
          job.end_time_s() > 0 ? job.progress_time_s() / job.end_time_s() : 0,
          absl::StrFormat("%s t = %.4g s", v1::JobState_Name(job.state()), job.progress_time_s()));
    }
    const absl::Status status = FromGrpc(reader->Finish());
    if (!status.ok()) return CallFailed(err, status, "");
  }
  if (!job.has_summary()) {  // cancelled before it started
    out << JobJson(job) << "\n";
    out.flush();
    return kExitIoError;
  }
  if (a.out.has_value()) {
    LazyCsvSink sink(a.out);
    grpc::ClientContext context;
    v1::GetJobResultRequest request;
    request.set_id(id);
    request.set_frames_per_batch(1024);
    std::unique_ptr<grpc::ClientReader<v1::RunEvent>> reader =
        c->stub->GetJobResult(&context, request);
    const absl::StatusOr<RunSummary> summary = ReadRunStream(&context, reader.get(), &sink, {});
    const absl::Status csv_status = sink.Finish();
    if (!csv_status.ok()) {
      err << "cablesim: " << csv_status.message() << "\n";
      return kExitIoError;
    }
    if (!summary.ok()) return CallFailed(err, summary.status(), "");
  }
  return ReportSummary(SummaryFromProto(job.summary()), out, err);
}

std::string EnergyJson(const std::string& source, const v1::EnergyResponse& r) {
  const v1::EnergyReport& e = r.report();
  return JsonLine()
      .Add("source", source)
      .Add("status", r.summary().status())
      .Add("frames", static_cast<int64_t>(r.t_size()))
      .Add("initial", e.initial())
      .Add("final", e.final())
      .Add("min", e.min())
      .Add("max", e.max())
      .Add("relative_drift", e.relative_drift())
      .Add("scale", e.scale())
      .Add("energy_dissipated", e.energy_dissipated())
      .Add("max_constraint_violation", e.max_constraint_violation())
      .ToString();
}

absl::Status WriteEnergyCsv(const std::string& path, const v1::EnergyResponse& r) {
  std::ofstream file(path);
  if (!file) return absl::UnavailableError(absl::StrCat(path, ": cannot open for writing"));
  file << "t,kinetic,potential,axial,bending,total,constraint_violation\n";
  for (int i = 0; i < r.t_size(); ++i) {
    file << absl::StrFormat("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", r.t(i), r.kinetic(i),
                            r.potential(i), r.axial(i), r.bending(i), r.total(i),
                            r.constraint_violation(i));
  }
  file.close();
  if (!file) return absl::DataLossError(absl::StrCat(path, ": write failed"));
  return absl::OkStatus();
}

int Energy(const Arguments& a, std::ostream& out, std::ostream& err) {
  const std::string& source = a.positional[1];
  v1::EnergyRequest request;
  const bool is_file = std::ifstream(source).good();
  if (is_file) {
    std::string error;
    const std::optional<v1::Scene> proto = ReadScene(source, err, &error);
    if (!proto.has_value()) return kExitBadInput;
    *request.mutable_scene() = *proto;
  } else {
    if (!a.server.has_value()) {
      return UsageError(
          err, absl::StrCat("energy: \"", source, "\" is no scene file; a job id needs --server"));
    }
    request.set_job_id(source);
  }
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  v1::EnergyResponse response;
  const absl::Status status = FromGrpc(c->stub->GetEnergy(&context, request, &response));
  if (!status.ok()) return CallFailed(err, status, is_file ? source : "");
  if (a.out.has_value()) {
    if (absl::Status s = WriteEnergyCsv(*a.out, response); !s.ok()) {
      err << "cablesim: " << s.message() << "\n";
      return kExitIoError;
    }
  }
  out << EnergyJson(source, response) << "\n";
  out.flush();
  return kExitOk;
}

std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) {
    if (ch == '"') quoted += '"';
    quoted += ch;
  }
  return quoted + "\"";
}

// Reads a sweep file (SweepFile in service.proto, protobuf JSON).
absl::StatusOr<v1::SubmitSweepRequest> ReadSweepFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open"));
  std::stringstream text;
  text << in.rdbuf();
  v1::SweepFile file;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  if (auto s = google::protobuf::util::JsonStringToMessage(text.str(), &file, options); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", s.message().as_string()));
  }
  v1::SubmitSweepRequest request;
  request.set_name(file.name());
  *request.mutable_axes() = file.axes();
  if (!file.base_file().empty()) {
    if (file.has_base()) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": give base or base_file, not both"));
    }
    std::filesystem::path base = file.base_file();
    if (base.is_relative()) base = std::filesystem::path(path).parent_path() / base;
    absl::StatusOr<v1::Scene> scene = ReadSceneFile(base.string());
    if (!scene.ok()) return scene.status();
    *request.mutable_base() = std::move(*scene);
  } else {
    *request.mutable_base() = file.base();
  }
  if (request.name().empty()) request.set_name(std::filesystem::path(path).stem().string());
  return request;
}

absl::StatusOr<double> DoubleOption(const Arguments& a, const std::string& name) {
  auto it = a.options.find(name);
  if (it == a.options.end()) return -1.0;
  double value;
  if (!absl::SimpleAtod(it->second, &value) || !(value >= 0)) {
    return absl::InvalidArgumentError(absl::StrCat("--", name, ": not a number >= 0"));
  }
  return value;
}

int SweepCommand(const Arguments& a, std::ostream& out, std::ostream& err) {
  const std::string& path = a.positional[1];
  const absl::StatusOr<double> max_drift = DoubleOption(a, "max-energy-drift");
  const absl::StatusOr<double> max_wall = DoubleOption(a, "max-wall-seconds");
  const absl::StatusOr<double> max_violation = DoubleOption(a, "max-constraint-violation");
  for (const auto* v : {&max_drift, &max_wall, &max_violation}) {
    if (!v->ok()) return UsageError(err, v->status().message());
  }
  int workers = 0;
  if (auto it = a.options.find("workers"); it != a.options.end()) {
    if (!absl::SimpleAtoi(it->second, &workers) || workers < 1) {
      return UsageError(err, "--workers: a number >= 1");
    }
  }
  const absl::StatusOr<v1::SubmitSweepRequest> request = ReadSweepFile(path);
  if (!request.ok()) {
    err << "cablesim: " << request.status().message() << "\n";
    return kExitBadInput;
  }
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, true, workers, err);
  if (c == nullptr) return kExitIoError;
  v1::Sweep sweep;
  {
    grpc::ClientContext context;
    const absl::Status status = FromGrpc(c->stub->SubmitSweep(&context, *request, &sweep));
    if (!status.ok()) return CallFailed(err, status, path);
  }
  err << "cablesim: sweep " << sweep.id() << ": " << sweep.items() << " items queued\n";
  {
    Progress progress(&err, Progress::IsTerminal(err), absl::StrCat("sweep ", sweep.id()));
    // The server may restart while we wait: watch again while it is
    // unavailable (up to a minute).
    for (int attempt = 0;; ++attempt) {
      grpc::ClientContext context;
      v1::WatchSweepRequest watch;
      watch.set_id(sweep.id());
      std::unique_ptr<grpc::ClientReader<v1::SweepEvent>> reader =
          c->stub->WatchSweep(&context, watch);
      v1::SweepEvent event;
      while (reader->Read(&event)) {
        const v1::Sweep& p = event.progress();
        progress.Update(
            p.items() ? static_cast<double>(p.finished()) / p.items() : 1,
            absl::StrFormat("%d/%d items, %d failed", p.finished(), p.items(), p.failed()));
      }
      const absl::Status status = FromGrpc(reader->Finish());
      if (status.ok()) break;
      if (status.code() != absl::StatusCode::kUnavailable || attempt >= 60) {
        progress.Done();
        return CallFailed(err, status, "");
      }
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
  v1::SweepResults results;
  {
    grpc::ClientContext context;
    v1::GetSweepResultsRequest get;
    get.set_id(sweep.id());
    const absl::Status status = FromGrpc(c->stub->GetSweepResults(&context, get, &results));
    if (!status.ok()) return CallFailed(err, status, "");
  }
  // The table and the verdict.
  std::ostringstream table;
  table << "index,job_id,state";
  for (const v1::SweepAxis& axis : results.sweep().axes()) table << "," << CsvCell(axis.path());
  table << ",status,error,wall_seconds,frames,steps,rejected_steps,newton_iterations,end_time_s,"
           "energy_initial,energy_final,energy_dissipated,energy_relative_drift,"
           "max_constraint_violation";
  for (const std::string& column : results.final_columns()) {
    table << "," << CsvCell(absl::StrCat("final.", column));
  }
  table << "\n";
  int failed = 0, violations = 0;
  for (const v1::SweepItem& item : results.items()) {
    const v1::RunSummary& s = item.summary();
    table << item.index() << "," << item.job_id() << "," << v1::JobState_Name(item.state());
    for (double v : item.axis_values()) table << "," << JsonLine::Number(v);
    table << "," << CsvCell(s.status()) << "," << CsvCell(s.error());
    for (double v :
         {s.wall_seconds(), static_cast<double>(s.frames()), static_cast<double>(s.steps()),
          static_cast<double>(s.rejected_steps()), static_cast<double>(s.newton_iterations()),
          s.end_time_s(), s.energy_initial(), s.energy_final(), s.energy_dissipated(),
          item.energy().relative_drift(), s.max_constraint_violation()}) {
      table << "," << absl::StrFormat("%.17g", v);
    }
    for (int k = 0; k < results.final_columns_size(); ++k) {
      table << ","
            << (k < item.final_values_size() ? absl::StrFormat("%.17g", item.final_values(k))
                                             : std::string());
    }
    table << "\n";
    const std::string who = absl::StrCat("sweep item ", item.index(), " (", item.job_id(), ")");
    if (item.state() != v1::SUCCEEDED) {
      ++failed;
      err << "cablesim: " << who << ": " << v1::JobState_Name(item.state())
          << (s.error().empty() ? "" : absl::StrCat(": ", s.error())) << "\n";
      continue;
    }
    auto check = [&](double limit, double value, const char* what) {
      if (limit >= 0 && !(std::abs(value) <= limit)) {
        ++violations;
        err << "cablesim: " << who << ": " << what << " " << JsonLine::Number(value) << " exceeds "
            << JsonLine::Number(limit) << "\n";
      }
    };
    check(*max_drift, item.energy().relative_drift(), "energy drift");
    check(*max_wall, s.wall_seconds(), "wall time [s]");
    check(*max_violation, s.max_constraint_violation(), "constraint violation");
  }
  if (a.out.has_value()) {
    std::ofstream file(*a.out);
    file << table.str();
    file.close();
    if (!file) {
      err << "cablesim: " << *a.out << ": cannot write\n";
      return kExitIoError;
    }
  } else {
    out << table.str();
  }
  const bool ok = failed == 0 && violations == 0;
  err << "cablesim: sweep " << sweep.id() << ": " << results.items_size() - failed << " of "
      << results.items_size() << " items succeeded, " << violations << " threshold violations\n";
  err.flush();
  out.flush();
  return ok ? kExitOk : kExitNumericalFailure;
}

}  // namespace

std::string CliUsage() {
  return R"(Usage:
  cablesim run SCENE [--out FILE.csv] [--server HOST:PORT]
      Run the scene's analysis and print the run summary as one JSON line.
      With --out, write the trajectory (one row per output frame) as CSV.
      The run goes through the cablesim service: one started in this
      process, or the cablesim-server at --server.
  cablesim validate SCENE [--server HOST:PORT]
      Check the scene and print one JSON line describing it.
  cablesim submit SCENE --server HOST:PORT
      Queue the scene as a durable job; print the job (its id) at once.
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
                 [--max-constraint-violation X]
      Queue a parameter sweep, wait for every item and write one row per
      item (axis values, summary, final probe values). Without --server the
      sweep runs in this process on N workers (default: the cores).
  cablesim help
      Print this text.

SCENE is a cablesim.v1.Scene (proto/cablesim/v1/scene.proto) in protobuf
JSON, or in text format when its name ends in .txtpb, .textproto or .pbtxt.
SWEEP.json is a cablesim.v1.SweepFile (proto/cablesim/v1/service.proto).

Exit status: 0 success, 1 error writing the output or reaching the server,
2 bad input (usage, scene file or scene), 3 numerical failure of the run
(for sweep: an item failed or a threshold was exceeded).
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
  static const std::map<std::string, const char*> kArgument = {
      {"run", "SCENE"}, {"validate", "SCENE"}, {"submit", "SCENE"},        {"jobs", nullptr},
      {"watch", "JOB"}, {"cancel", "JOB"},     {"energy", "SCENE or JOB"}, {"sweep", "SWEEP.json"}};
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
  for (const auto& [name, value] : a.options) {
    const bool allowed =
        (command == "jobs" && (name == "state" || name == "sweep" || name == "limit")) ||
        (command == "sweep" && name != "state" && name != "sweep" && name != "limit");
    if (!allowed) return UsageError(err, absl::StrCat(command, ": no option --", name));
  }
  if (a.out.has_value() && command != "run" && command != "watch" && command != "energy" &&
      command != "sweep") {
    return UsageError(err, absl::StrCat(command, ": --out is only for run"));
  }
  if (command == "validate") return Validate(a.positional[1], a.server, out, err);
  if (command == "run") return Run(a.positional[1], a.out, a.server, out, err);
  if (command == "submit") return Submit(a, out, err);
  if (command == "jobs") return Jobs(a, out, err);
  if (command == "watch") return Watch(a, out, err);
  if (command == "cancel") return Cancel(a, out, err);
  if (command == "energy") return Energy(a, out, err);
  return SweepCommand(a, out, err);
}

int RunCli(int argc, char** argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  return RunCli(args, out, err);
}

}  // namespace cablesim
