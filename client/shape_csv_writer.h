#ifndef CABLESIM_CLIENT_SHAPE_CSV_WRITER_H_
#define CABLESIM_CLIENT_SHAPE_CSV_WRITER_H_

// Writes the cable's shape (Scene.output.shape: every node's position per
// frame) as a long-format CSV, one row per node and frame:
//
//   t,cable,node,s,x,y,z
//
// t as in the run CSV [s, or the load factor], cable the cable's index in
// the scene, node the node's index along it (a node split where a cable
// kinks counts once), s its arc length in the undeformed cable [m], x y z
// its position [m] (numbers in the shortest form that reads back exactly:
// AppendCsvNumber, client/csv_writer.h). Long rather than wide: cables
// have different node counts, the header is the same for every scene, and
// it loads directly as a table (numpy.loadtxt, pandas groupby t or cable).
// With the scene's output.tension (ModelInfo::node_tension) each row ends
// with one more column, `tension`: the cable's axial force at the node [N].

#include <cstdint>
#include <fstream>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/run/simulation.h"

namespace cablesim {

class ShapeCsvWriter : public FrameSink {
 public:
  static constexpr const char* kHeader = "t,cable,node,s,x,y,z";

  // Creates (or truncates) the file at `path`; an error names it.
  static absl::StatusOr<std::unique_ptr<ShapeCsvWriter>> Create(const std::string& path);

  // Writes the header. FailedPrecondition when the run has no shape
  // (ModelInfo::shape false: the scene did not ask for it).
  absl::Status OnStart(const ModelInfo& info) override;
  // Writes the frame's nodes.
  absl::Status OnFrame(const Frame& frame) override;
  // Flushes and closes; the first error of the writer.
  absl::Status Finish();

 private:
  ShapeCsvWriter(std::unique_ptr<std::ofstream> file, std::string path)
      : file_(std::move(file)), path_(std::move(path)) {}
  absl::Status Check(const char* what);

  std::unique_ptr<std::ofstream> file_;
  std::string path_;
  absl::Status status_;
  ModelInfo info_;
  std::string row_;
  std::string t_;  // the frame's t, formatted once per frame (reused)
};

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_SHAPE_CSV_WRITER_H_
