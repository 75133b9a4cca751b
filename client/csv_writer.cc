#include "client/csv_writer.h"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "engine/output/frame_columns.h"

namespace cablesim {
namespace {

// ",%.17g" (17 significant digits: every double reads back exactly), by
// std::to_chars, which the standard defines as printf's conversion in the C
// locale (the same characters) but which runs several times faster than a
// format string; frames every millisecond made formatting a visible part
// of a run's wall time.
void AppendNumber(std::string* row, double value) {
  row->push_back(',');
  AppendCsvNumber(row, value);
}

}  // namespace

void AppendCsvNumber(std::string* row, double value) {
  char buf[32];  // the longest shortest form, -2.2250738585072014e-308, has 24
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), value);
  row->append(buf, r.ptr);
}

absl::StatusOr<std::unique_ptr<std::ofstream>> OpenForWriting(const std::string& path) {
  errno = 0;
  auto file = std::make_unique<std::ofstream>(path, std::ios::out | std::ios::trunc);
  if (!file->is_open()) {
    const int error = errno;
    return absl::UnavailableError(absl::StrCat(
        path, ": cannot open for writing: ", error != 0 ? std::strerror(error) : "unknown"));
  }
  return file;
}

absl::StatusOr<std::unique_ptr<CsvWriter>> CsvWriter::Create(const std::string& path) {
  absl::StatusOr<std::unique_ptr<std::ofstream>> file = OpenForWriting(path);
  if (!file.ok()) return file.status();
  return std::unique_ptr<CsvWriter>(new CsvWriter(std::move(*file), path));
}

CsvWriter::CsvWriter(std::ostream* out, std::string name) : out_(out), name_(std::move(name)) {}

CsvWriter::CsvWriter(std::unique_ptr<std::ofstream> file, std::string name)
    : file_(std::move(file)), out_(file_.get()), name_(std::move(name)) {}

CsvWriter::~CsvWriter() {
  if (!finished_) Finish().IgnoreError();
}

std::string CsvWriter::Header(const ModelInfo& info) {
  return absl::StrJoin(FrameColumns(info, /*with_nodes=*/false), ",");
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
  cable_count_ = info.cable_names.size();
  force_count_ = info.force_probe_names.size();
  body_count_ = info.body_names.size();
  errno = 0;
  *out_ << Header(info) << '\n';
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
  if (frame.probes.size() != probe_count_ ||
      frame.energy_parts.cables.size() != cable_count_ ||
      frame.support_forces.size() != force_count_ ||
      frame.energy_parts.bodies.size() != body_count_) {
    status_ = absl::InternalError(absl::StrCat(
        name_, ": frame has ", frame.probes.size(), " probe samples and the energy of ",
        frame.energy_parts.cables.size(), " cables and ", frame.energy_parts.bodies.size(),
        " bodies and ", frame.support_forces.size(), " support forces, the header ", probe_count_,
        ", ", cable_count_, ", ", body_count_, " and ", force_count_));
    return status_;
  }
  const size_t start = pending_.size();
  ForEachFrameValue(frame, [this](double value) { AppendNumber(&pending_, value); });
  // The row starts with t, without the separator.
  pending_.erase(start, 1);
  pending_ += '\n';
  ++rows_;
  if (rows_ % kRowsPerFlush != 0) return status_;
  WritePending();
  out_->flush();
  return CheckStream("writing a row");
}

void CsvWriter::WritePending() {
  errno = 0;
  out_->write(pending_.data(), static_cast<std::streamsize>(pending_.size()));
  pending_.clear();
}

absl::Status CsvWriter::Finish() {
  if (finished_) return status_;
  finished_ = true;
  if (status_.ok()) {
    WritePending();
    CheckStream("writing a row").IgnoreError();
  }
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
