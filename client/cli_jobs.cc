#include "client/cli_jobs.h"

#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/json_line.h"
#include "client/progress.h"
#include "convert/run_proto.h"

namespace cablesim::cli_internal {
namespace {

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
      .Add("energy_damped", e.energy_damped())
      .Add("max_constraint_violation", e.max_constraint_violation())
      .ToString();
}

absl::Status WriteEnergyCsv(const std::string& path, const v1::EnergyResponse& r) {
  std::ofstream file(path);
  if (!file) return absl::UnavailableError(absl::StrCat(path, ": cannot open for writing"));
  // The run CSV's names for the same quantities (FrameColumns without
  // probes), the parts only when the response has them (a job stored
  // before they were recorded has none).
  ModelInfo info;
  for (const v1::PartEnergySeries& c : r.cables()) info.cable_names.push_back(c.name());
  for (const v1::PartEnergySeries& b : r.bodies()) info.body_names.push_back(b.name());
  std::vector<std::string> columns = FrameColumns(info);
  const bool parts = r.loads_size() == r.t_size();
  if (!parts) columns.resize(1 + kTotalValues);
  file << absl::StrJoin(columns, ",") << "\n";
  for (int i = 0; i < r.t_size(); ++i) {
    std::string row = absl::StrFormat(
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", r.t(i), r.kinetic(i), r.potential(i),
        r.axial(i), r.bending(i), r.total(i), r.constraint_violation(i),
        i < r.damped_size() ? r.damped(i) : 0.0);
    if (parts) {
      for (const v1::PartEnergySeries& c : r.cables()) {
        absl::StrAppendFormat(&row, ",%.17g,%.17g,%.17g,%.17g", c.kinetic(i), c.gravity(i),
                              c.axial(i), c.bending(i));
      }
      for (const v1::PartEnergySeries& b : r.bodies())
        absl::StrAppendFormat(&row, ",%.17g,%.17g", b.kinetic(i), b.gravity(i));
      absl::StrAppendFormat(&row, ",%.17g", r.loads(i));
    }
    file << row << "\n";
  }
  file.close();
  if (!file) return absl::DataLossError(absl::StrCat(path, ": write failed"));
  return absl::OkStatus();
}

}  // namespace

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
  request.set_strict(a.options.count("strict") > 0);
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

}  // namespace cablesim::cli_internal
