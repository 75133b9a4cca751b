#ifndef CABLESIM_CLIENT_CLI_COMMON_H_
#define CABLESIM_CLIENT_CLI_COMMON_H_

// What the `cablesim` commands (client/cli.cc, cli_jobs.cc, cli_sweep.cc)
// share: the parsed arguments, error reporting with the exit codes of
// client/cli.h, scene reading and the connection to the service.

#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/scene.pb.h"
#include "client/cli.h"
#include "client/csv_writer.h"
#include "client/shape_csv_writer.h"
#include "client/service_client.h"
#include "engine/run/simulation.h"

namespace cablesim::cli_internal {

// The command line after parsing.
struct Arguments {
  std::vector<std::string> positional;         // command first
  std::optional<std::string> out;              // --out
  std::optional<std::string> server;           // --server
  std::map<std::string, std::string> options;  // the other --name value
  // The options that may repeat (--max, --min), in order: name, value.
  std::vector<std::pair<std::string, std::string>> repeated;
  bool help = false;
  bool version = false;  // --version
};

// Prints `message` and the usage text; returns the exit code 2.
int UsageError(std::ostream& err, absl::string_view message);

// The exit code for a failed call to the service: 2 for bad input
// (InvalidArgument, ResourceExhausted, NotFound, FailedPrecondition), 1
// otherwise (the server cannot be reached, ...).
int ExitCodeFor(const absl::Status& s);

// Reports a failed call (`what` prefixes messages about the input, such
// as the scene file) and returns its exit code.
int CallFailed(std::ostream& err, const absl::Status& s, const std::string& what);

// Reads the scene file at `path`; on failure reports it on `err`, sets
// `error_message` and returns nullopt.
std::optional<v1::Scene> ReadScene(const std::string& path, std::ostream& err,
                                   std::string* error_message);

// Connect() (client/service_client.h); reports a failure on `err`.
std::unique_ptr<Connection> ConnectOrReport(const std::optional<std::string>& server, bool jobs,
                                            int workers, std::ostream& err);

// Prints the summary and returns the exit code of a finished run.
int ReportSummary(const RunSummary& summary, std::ostream& out, std::ostream& err);

// Creates the CSV (and the shape CSV, `shape_path`) when the run's header
// arrives (so an invalid scene leaves no file behind) and remembers whether
// an error was its own.
class LazyCsvSink : public FrameSink {
 public:
  explicit LazyCsvSink(std::optional<std::string> path,
                       std::optional<std::string> shape_path = std::nullopt)
      : path_(std::move(path)), shape_path_(std::move(shape_path)) {}
  absl::Status OnStart(const ModelInfo& info) override {
    if (shape_path_.has_value()) {
      absl::StatusOr<std::unique_ptr<ShapeCsvWriter>> created = ShapeCsvWriter::Create(*shape_path_);
      if (!created.ok()) return Fail(created.status());
      shape_ = std::move(*created);
      if (absl::Status s = shape_->OnStart(info); !s.ok()) return Fail(s);
    }
    if (!path_.has_value()) return absl::OkStatus();
    absl::StatusOr<std::unique_ptr<CsvWriter>> created = CsvWriter::Create(*path_);
    if (!created.ok()) return Fail(created.status());
    csv_ = std::move(*created);
    return Fail(csv_->OnStart(info));
  }
  absl::Status OnFrame(const Frame& frame) override {
    if (shape_ != nullptr) {
      if (absl::Status s = shape_->OnFrame(frame); !s.ok()) return Fail(s);
    }
    return csv_ != nullptr ? Fail(csv_->OnFrame(frame)) : absl::OkStatus();
  }
  // Finishes the CSVs; the first error (or the creation error).
  absl::Status Finish() {
    if (!error_.ok()) return error_;
    if (shape_ != nullptr) {
      if (absl::Status s = shape_->Finish(); !s.ok()) return s;
    }
    return csv_ != nullptr ? csv_->Finish() : absl::OkStatus();
  }
  bool failed() const { return !error_.ok(); }

 private:
  absl::Status Fail(absl::Status s) {
    if (!s.ok() && error_.ok()) error_ = s;
    return s;
  }
  std::optional<std::string> path_, shape_path_;
  std::unique_ptr<CsvWriter> csv_;
  std::unique_ptr<ShapeCsvWriter> shape_;
  absl::Status error_;
};

}  // namespace cablesim::cli_internal

#endif  // CABLESIM_CLIENT_CLI_COMMON_H_
