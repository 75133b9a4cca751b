#ifndef CABLESIM_CONVERT_SWEEP_FILE_H_
#define CABLESIM_CONVERT_SWEEP_FILE_H_

// Reading sweep files (cablesim.v1.SweepFile in protobuf JSON) into a
// SubmitSweepRequest: the same strict parsing and limits as scene files
// (convert/scene_file.h), and a `base_file` that may only name a file under
// the sweep file's own directory unless the caller allows more.

#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/service.pb.h"

namespace cablesim {

// Parses the sweep file text `json`, read from `path` (which starts every
// message and locates a relative `base_file`). `base_file` must resolve
// (symbolic links followed) to a file under the directory of `path`, unless
// `allow_outside`: a sweep file from elsewhere cannot make `cablesim sweep`
// read, or quote, an arbitrary file. The request's name defaults to the
// file's stem.
absl::StatusOr<v1::SubmitSweepRequest> ParseSweepFile(absl::string_view json,
                                                      const std::string& path,
                                                      bool allow_outside);

// Reads the sweep file at `path` (bounded like a scene file) and parses it.
absl::StatusOr<v1::SubmitSweepRequest> ReadSweepFile(const std::string& path, bool allow_outside);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SWEEP_FILE_H_
