#include "client/shape_csv_writer.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "client/csv_writer.h"

namespace cablesim {

absl::StatusOr<std::unique_ptr<ShapeCsvWriter>> ShapeCsvWriter::Create(const std::string& path) {
  absl::StatusOr<std::unique_ptr<std::ofstream>> file = OpenForWriting(path);
  if (!file.ok()) return file.status();
  return std::unique_ptr<ShapeCsvWriter>(new ShapeCsvWriter(std::move(*file), path));
}

absl::Status ShapeCsvWriter::Check(const char* what) {
  if (status_.ok() && !*file_) {
    status_ = absl::DataLossError(absl::StrCat(path_, ": ", what, " failed"));
  }
  return status_;
}

absl::Status ShapeCsvWriter::OnStart(const ModelInfo& info) {
  if (!info.shape) {
    status_ = absl::FailedPreconditionError(
        absl::StrCat(path_, ": the run has no shape (the scene's output.shape is false)"));
    return status_;
  }
  info_ = info;
  *file_ << kHeader << (info.node_tension ? ",tension" : "") << '\n';
  return Check("writing the header");
}

absl::Status ShapeCsvWriter::OnFrame(const Frame& frame) {
  if (!status_.ok()) return status_;
  if (frame.nodes.size() != info_.node_s.size()) {
    status_ = absl::InternalError(absl::StrCat(path_, ": frame has ", frame.nodes.size(),
                                               " nodes, the model ", info_.node_s.size()));
    return status_;
  }
  row_.clear();
  // t once per frame (the same for each of its rows).
  t_.clear();
  AppendCsvNumber(&t_, frame.t);
  size_t n = 0;
  for (size_t c = 0; c < info_.cable_nodes.size(); ++c) {
    for (int k = 0; k < info_.cable_nodes[c]; ++k, ++n) {
      const Eigen::Vector3d& r = frame.nodes[n];
      absl::StrAppend(&row_, t_, ",", c, ",", k, ",");
      AppendCsvNumber(&row_, info_.node_s[n]);
      for (int i = 0; i < 3; ++i) {
        row_ += ',';
        AppendCsvNumber(&row_, r(i));
      }
      if (info_.node_tension && n < frame.node_tensions.size()) {
        row_ += ',';
        AppendCsvNumber(&row_, frame.node_tensions[n]);
      }
      row_ += '\n';
    }
  }
  file_->write(row_.data(), static_cast<std::streamsize>(row_.size()));
  return Check("writing a frame");
}

absl::Status ShapeCsvWriter::Finish() {
  if (file_->is_open()) {
    file_->close();
    Check("closing").IgnoreError();
  }
  return status_;
}

}  // namespace cablesim
