#include "client/csv_writer.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {
namespace {

constexpr const char* kProbeColumns[] = {"x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"};
constexpr const char* kTrailingColumns[] = {"energy.kinetic", "energy.potential",
                                            "energy.axial",   "energy.bending",
                                            "energy.total",   "constraint.violation",
                                            "energy.damped"};

void AppendNumber(std::string* row, double value) { absl::StrAppendFormat(row, ",%.17g", value); }

void AppendVector(std::string* row, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) AppendNumber(row, v[k]);
}

}  // namespace

absl::StatusOr<std::unique_ptr<CsvWriter>> CsvWriter::Create(const std::string& path) {
  errno = 0;
  auto file = std::make_unique<std::ofstream>(path, std::ios::out | std::ios::trunc);
  if (!file->is_open()) {
    const int error = errno;
    return absl::UnavailableError(absl::StrCat(
        path, ": cannot open for writing: ", error != 0 ? std::strerror(error) : "unknown"));
  }
  return std::unique_ptr<CsvWriter>(new CsvWriter(std::move(file), path));
}

CsvWriter::CsvWriter(std::ostream* out, std::string name) : out_(out), name_(std::move(name)) {}

CsvWriter::CsvWriter(std::unique_ptr<std::ofstream> file, std::string name)
    : file_(std::move(file)), out_(file_.get()), name_(std::move(name)) {}

CsvWriter::~CsvWriter() {
  if (!finished_) Finish().IgnoreError();
}

std::string CsvWriter::Header(const std::vector<std::string>& probe_names) {
  std::string header = "t";
  for (const std::string& name : probe_names) {
    for (const char* column : kProbeColumns) absl::StrAppend(&header, ",", name, ".", column);
  }
  for (const char* column : kTrailingColumns) absl::StrAppend(&header, ",", column);
  return header;
}

absl::Status CsvWriter::CheckStream(const char* what) {
  if (status_.ok() && !*out_) {
    const int error = errno;
    status_ = absl::DataLossError(absl::StrCat(
        name_, ": ", what, " failed", error != 0 ? absl::StrCat(": ", std::strerror(error)) : ""));
  }
  return status_;
}

absl::Status CsvWriter::OnStart(const ModelInfo& info) {
  if (!status_.ok()) return status_;
  if (started_ || finished_) {
    status_ = absl::FailedPreconditionError(absl::StrCat(name_, ": OnStart called twice"));
    return status_;
  }
  started_ = true;
  probe_count_ = info.probe_names.size();
  errno = 0;
  *out_ << Header(info.probe_names) << '\n';
  out_->flush();
  return CheckStream("writing the header");
}

absl::Status CsvWriter::OnFrame(const Frame& frame) {
  if (!status_.ok()) return status_;
  if (!started_ || finished_) {
    status_ =
        absl::FailedPreconditionError(absl::StrCat(name_, ": frame outside OnStart ... Finish"));
    return status_;
  }
  if (frame.probes.size() != probe_count_) {
    status_ = absl::InternalError(absl::StrCat(name_, ": frame has ", frame.probes.size(),
                                               " probe samples, the header ", probe_count_));
    return status_;
  }
  std::string row = absl::StrFormat("%.17g", frame.t);
  row.reserve(row.size() + (probe_count_ * 9 + 6) * 25);
  for (const ProbeSample& probe : frame.probes) {
    AppendVector(&row, probe.position_m);
    AppendVector(&row, probe.velocity_m_s);
    AppendVector(&row, probe.acceleration_m_s2);
  }
  const EnergySample& e = frame.energy;
  for (const double value :
       {e.kinetic, e.potential, e.axial, e.bending, e.total, frame.constraint_violation,
        e.damped}) {
    AppendNumber(&row, value);
  }
  row += '\n';
  errno = 0;
  out_->write(row.data(), static_cast<std::streamsize>(row.size()));
  ++rows_;
  if (rows_ % kRowsPerFlush == 0) out_->flush();
  return CheckStream("writing a row");
}

absl::Status CsvWriter::Finish() {
  if (finished_) return status_;
  finished_ = true;
  errno = 0;
  out_->flush();
  CheckStream("flushing").IgnoreError();
  if (file_ != nullptr) {
    file_->close();
    CheckStream("closing").IgnoreError();
  }
  return status_;
}

}  // namespace cablesim
