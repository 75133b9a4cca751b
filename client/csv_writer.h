#ifndef CABLESIM_CLIENT_CSV_WRITER_H_
#define CABLESIM_CLIENT_CSV_WRITER_H_

// Writes a run's trajectory as CSV, one row per frame, in the columns of
// FrameColumns (engine/output/frame_columns.h):
//
//   t, then for each probe NAME.x NAME.y NAME.z NAME.vx NAME.vy NAME.vz
//   NAME.ax NAME.ay NAME.az, then energy.kinetic energy.potential
//   energy.axial energy.bending energy.total constraint.violation, then the
//   energy per part: cables[i].energy.{kinetic,gravity,axial,bending},
//   bodies[j].energy.{kinetic,gravity}, loads.energy.potential
//
// t is the time [s] (DYNAMIC) or the load factor (STATIC); positions [m],
// velocities [m/s], accelerations [m/s^2], energies [J]. Numbers are written
// in the shortest form that reads back to the same double (AppendCsvNumber).

#include <cstdint>
#include <fstream>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/run/simulation.h"

namespace cablesim {

// Appends `value` to `row` in the shortest decimal form that reads back to
// the same double (std::to_chars without a precision: 0.1, not
// 0.10000000000000001). Until 29 November 2026 the CSVs were written with 17
// significant digits: the same doubles, in longer text that took about 60 %
// longer to format (72 against 44 ns a number, measured on this machine).
void AppendCsvNumber(std::string* row, double value);

// Creates (or truncates) the file at `path` for writing; Unavailable,
// naming the file and the reason, when it cannot be opened.
absl::StatusOr<std::unique_ptr<std::ofstream>> OpenForWriting(const std::string& path);

class CsvWriter : public FrameSink {
 public:
  // Rows written between flushes of the output. They are kept in one
  // buffer and written together: libstdc++'s filebuf hands every write of
  // 1 KB or more (a row of a few probes) to the kernel at once, and a
  // system call per row was 4 % of a fast mooring run's CPU with a frame
  // every 0.1 s (bench/scenes/oc4-three-lines.json, 8 elements per line).
  static constexpr int64_t kRowsPerFlush = 100;

  // Creates (or truncates) the file at `path`. Returns a non-OK status
  // naming the file when it cannot be opened.
  static absl::StatusOr<std::unique_ptr<CsvWriter>> Create(const std::string& path);

  // Writes to `out`, which must outlive the writer. `name` is used in error
  // messages.
  CsvWriter(std::ostream* out, std::string name);

  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  // Flushes what is still buffered.
  ~CsvWriter() override;

  // Writes the header line. Returns the write error, if any.
  absl::Status OnStart(const ModelInfo& info) override;
  // Writes one row (every frame must have one sample per probe of OnStart,
  // and one energy part per cable and body).
  // Rows are kept and written (and flushed) together every kRowsPerFlush
  // rows and at Finish. Returns the write error, if any (a write that
  // fails is seen at the end of its batch).
  absl::Status OnFrame(const Frame& frame) override;

  // Flushes and, for a file made by Create, closes it. Returns the first
  // error of the whole writer, so a run's CSV is known complete when this
  // returns OK. Later frames are refused.
  absl::Status Finish();

  // The first error so far (OK if none).
  const absl::Status& status() const { return status_; }
  int64_t rows() const { return rows_; }

  // The header line for a model with `info`'s probes, cables and bodies,
  // without the newline.
  static std::string Header(const ModelInfo& info);

 private:
  CsvWriter(std::unique_ptr<std::ofstream> file, std::string name);

  // Records a failure of `out_` (with `what` it was doing) in status_.
  absl::Status CheckStream(const char* what);
  // Writes the rows kept in pending_ to `out_` (not flushed).
  void WritePending();

  std::unique_ptr<std::ofstream> file_;  // set when the writer owns the file
  std::ostream* out_;
  std::string name_;
  absl::Status status_;
  size_t probe_count_ = 0, cable_count_ = 0, body_count_ = 0, force_count_ = 0;
  bool started_ = false;
  bool finished_ = false;
  int64_t rows_ = 0;
  std::string pending_;  // rows not yet written (fewer than kRowsPerFlush)
};

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_CSV_WRITER_H_
