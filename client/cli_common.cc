#include "client/cli_common.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/cli.h"
#include "client/summary_json.h"
#include "convert/scene_file.h"

namespace cablesim::cli_internal {

int UsageError(std::ostream& err, absl::string_view message) {
  err << "cablesim: " << message << "\n\n" << CliUsage();
  err.flush();
  return kExitBadInput;
}

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

// Prints the summary and returns the exit code of a finished run.
int ReportSummary(const RunSummary& summary, std::ostream& out, std::ostream& err) {
  out << SummaryToJson(summary) << "\n";
  out.flush();
  for (const std::string& warning : summary.warnings) {
    err << "cablesim: warning: " << warning << "\n";
  }
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

}  // namespace cablesim::cli_internal
