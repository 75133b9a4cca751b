#include "client/cli_sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
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

// "path=value, path=value" of an item's axis values.
std::string AxisValuesText(const v1::SweepResults& results, const v1::SweepItem& item) {
  std::string text;
  for (int k = 0; k < results.sweep().axes_size() && k < item.axis_values_size(); ++k) {
    absl::StrAppend(&text, k ? ", " : "", results.sweep().axes(k).path(), "=",
                    JsonLine::Number(item.axis_values(k)));
  }
  return text;
}

// The thresholds of --max and --min (NAME=VALUE each, in order), and the
// flag each came from (for messages).
absl::Status ParseThresholds(const Arguments& a, v1::SubmitSweepRequest* request,
                             std::vector<std::string>* flags) {
  for (const auto& [name, value] : a.repeated) {
    const std::string flag = absl::StrCat("--", name, " ", value);
    const size_t eq = value.rfind('=');
    double limit = 0;
    if (eq == std::string::npos || eq == 0) {
      return absl::InvalidArgumentError(absl::StrCat(flag, ": expected COLUMN=VALUE"));
    }
    if (!absl::SimpleAtod(value.substr(eq + 1), &limit) || !std::isfinite(limit)) {
      return absl::InvalidArgumentError(absl::StrCat(flag, ": VALUE is not a finite number"));
    }
    v1::SweepThreshold* t = request->add_thresholds();
    t->set_column(value.substr(0, eq));
    if (name == "max") {
      t->set_max(limit);
    } else {
      t->set_min(limit);
    }
    flags->push_back(flag);
  }
  return absl::OkStatus();
}

// `text` with &, <, >, " and ' escaped, and the control characters XML 1.0
// cannot hold replaced by '?'.
std::string XmlEscape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        out += (static_cast<unsigned char>(ch) < 0x20 && ch != '\n' && ch != '\t') ? '?' : ch;
    }
  }
  return out;
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
  std::vector<std::string> threshold_flags;
  if (absl::Status s = ParseThresholds(a, &*request, &threshold_flags); !s.ok()) {
    return UsageError(err, s.message());
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
    if (!status.ok()) {
      // A threshold's error names the flag it came from.
      for (size_t k = 0; k < threshold_flags.size(); ++k) {
        if (absl::StartsWith(status.message(), absl::StrCat("thresholds[", k, "]"))) {
          return CallFailed(err, status, threshold_flags[k]);
        }
      }
      return CallFailed(err, status, path);
    }
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
  // Then per threshold the value it judged: max.COLUMN or min.COLUMN (a
  // threshold with both: both).
  std::vector<std::pair<std::string, bool>> judged;  // column, is max
  for (const v1::SweepThreshold& t : request->thresholds()) {
    if (t.has_max()) judged.emplace_back(t.column(), true);
    if (t.has_min()) judged.emplace_back(t.column(), false);
  }
  for (const auto& [column, is_max] : judged) {
    table << "," << CsvCell(absl::StrCat(is_max ? "max." : "min.", column));
  }
  table << "\n";
  int failed = 0, violations = 0;
  // Per item, for --junit: its name and why it failed (empty: passed).
  std::vector<std::pair<std::string, std::vector<std::string>>> verdicts;
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
    for (const auto& [column, is_max] : judged) {
      std::string cell;
      for (const v1::ColumnStatistics& c : s.statistics().columns()) {
        if (c.column() == column) cell = absl::StrFormat("%.17g", is_max ? c.max() : c.min());
      }
      table << "," << cell;
    }
    table << "\n";
    // The item by its index, its axis values and its job.
    const std::string axes = AxisValuesText(results, item);
    const std::string who = absl::StrCat("sweep item ", first_index + item.index(), " (", axes,
                                         axes.empty() ? "" : "; ", item.job_id(), ")");
    verdicts.emplace_back(absl::StrCat("item ", first_index + item.index(),
                                       axes.empty() ? "" : ": ", axes),
                          std::vector<std::string>());
    std::vector<std::string>& reasons = verdicts.back().second;
    if (item.state() != v1::SUCCEEDED) {
      ++failed;
      reasons.push_back(absl::StrCat(v1::JobState_Name(item.state()),
                                     s.error().empty() ? "" : absl::StrCat(": ", s.error())));
      err << "cablesim: " << who << ": " << reasons.back() << "\n";
      continue;
    }
    auto check = [&](double limit, double value, const char* what) {
      if (limit >= 0 && !(std::abs(value) <= limit)) {
        ++violations;
        reasons.push_back(absl::StrCat(what, " ", JsonLine::Number(value), " exceeds ",
                                       JsonLine::Number(limit)));
        err << "cablesim: " << who << ": " << reasons.back() << "\n";
      }
    };
    check(*max_drift, item.energy().relative_drift(), "energy drift");
    check(*max_wall, s.wall_seconds(), "wall time [s]");
    check(*max_violation, s.max_constraint_violation(), "constraint violation");
    for (const std::string& failure : item.threshold_failures()) {
      ++violations;
      reasons.push_back(failure);
      err << "cablesim: " << who << ": " << failure << "\n";
    }
  }
  if (auto it = a.options.find("junit"); it != a.options.end()) {
    // JUnit XML (the schema CI systems read): one testsuite, one testcase
    // per item, a <failure> with the reasons when it failed.
    const std::string suite = results.sweep().name().empty() ? sweep.id() : results.sweep().name();
    int failures = 0;
    for (const auto& verdict : verdicts) failures += verdict.second.empty() ? 0 : 1;
    std::ostringstream xml;
    xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        << "<testsuites tests=\"" << verdicts.size() << "\" failures=\"" << failures << "\">\n"
        << "  <testsuite name=\"" << XmlEscape(suite) << "\" id=\"" << XmlEscape(sweep.id())
        << "\" tests=\"" << verdicts.size() << "\" failures=\"" << failures
        << "\" errors=\"0\">\n";
    for (size_t k = 0; k < verdicts.size(); ++k) {
      const auto& [name, reasons] = verdicts[k];
      const v1::SweepItem& item = results.items(static_cast<int>(k));
      xml << "    <testcase classname=\"" << XmlEscape(absl::StrCat("cablesim.sweep.", suite))
          << "\" name=\"" << XmlEscape(name) << "\" time=\""
          << absl::StrFormat("%.6f", item.summary().wall_seconds()) << "\"";
      if (reasons.empty()) {
        xml << "/>\n";
        continue;
      }
      xml << ">\n      <failure message=\"" << XmlEscape(reasons.front()) << "\" type=\""
          << (item.state() != v1::SUCCEEDED ? v1::JobState_Name(item.state()) : "threshold")
          << "\">" << XmlEscape(absl::StrJoin(reasons, "\n")) << "</failure>\n    </testcase>\n";
    }
    xml << "  </testsuite>\n</testsuites>\n";
    std::ofstream file(it->second);
    file << xml.str();
    file.close();
    if (!file) {
      err << "cablesim: " << it->second << ": cannot write\n";
      return kExitIoError;
    }
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
