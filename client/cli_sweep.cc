#include "client/cli_sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/json_line.h"
#include "client/progress.h"
#include "convert/sweep_file.h"

namespace cablesim::cli_internal {
namespace {

std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) {
    if (ch == '"') quoted += '"';
    quoted += ch;
  }
  return quoted + "\"";
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

}  // namespace

absl::Status NarrowSweepToItem(int64_t item, v1::SubmitSweepRequest* request) {
  // The last axis varies fastest: item = sum_k i_k * prod_{j > k} n_j.
  for (int k = request->axes_size() - 1; k >= 0; --k) {
    v1::SweepAxis* axis = request->mutable_axes(k);
    if (axis->values_size() == 0) {
      return absl::InvalidArgumentError(absl::StrCat("axes[", k, "].values: empty"));
    }
    const double value = axis->values(static_cast<int>(item % axis->values_size()));
    item /= axis->values_size();
    axis->clear_values();
    axis->add_values(value);
  }
  return absl::OkStatus();
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
  absl::StatusOr<v1::SubmitSweepRequest> request =
      ReadSweepFile(path, a.options.count("allow-outside") > 0);
  if (!request.ok()) {
    err << "cablesim: " << request.status().message() << "\n";
    return kExitBadInput;
  }
  // --item I: the sweep narrowed to its item I (each axis to the one value
  // it takes there), reported under index I.
  int first_index = 0;
  if (auto it = a.options.find("item"); it != a.options.end()) {
    int64_t items = 1;
    for (const v1::SweepAxis& axis : request->axes()) items *= std::max(axis.values_size(), 1);
    int item = -1;
    if (!absl::SimpleAtoi(it->second, &item) || item < 0) {
      return UsageError(err, "--item: a number >= 0");
    }
    if (item >= items) {
      return UsageError(err, absl::StrCat("--item: ", item, " is not an item of ", path, " (",
                                          items, " items, 0 to ", items - 1, ")"));
    }
    const absl::Status narrowed = NarrowSweepToItem(item, &*request);
    if (!narrowed.ok()) {
      err << "cablesim: " << path << ": " << narrowed.message() << "\n";
      return kExitBadInput;
    }
    first_index = item;
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
    table << first_index + item.index() << "," << item.job_id() << "," << v1::JobState_Name(item.state());
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
    const std::string who =
        absl::StrCat("sweep item ", first_index + item.index(), " (", item.job_id(), ")");
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

}  // namespace cablesim::cli_internal
