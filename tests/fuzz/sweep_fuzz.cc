// Fuzz target: a sweep file's bytes through `cablesim sweep`'s reading of
// them: strict JSON parsing, base_file confinement (to a directory that
// does not exist, so nothing is read from disk), and every axis value set
// at its field path in the base scene (SetSceneField) and validated.
//
// Built as a libFuzzer binary with clang (-DCABLESIM_FUZZ=ON), and in every
// build as a replay driver (replay_main.cc) that CTest runs over the corpus.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "convert/scene_field_path.h"
#include "convert/scene_from_proto.h"
#include "convert/sweep_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  const absl::StatusOr<cablesim::v1::SubmitSweepRequest> request =
      cablesim::ParseSweepFile(text, "/nonexistent-cablesim-fuzz/sweep.json", false);
  if (!request.ok()) return 0;
  for (const cablesim::v1::SweepAxis& axis : request->axes()) {
    for (int i = 0; i < std::min(axis.values_size(), 4); ++i) {
      cablesim::v1::Scene scene = request->base();
      if (!cablesim::SetSceneField(&scene, axis.path(), axis.values(i)).ok()) continue;
      (void)cablesim::SceneFromProto(scene);
    }
  }
  return 0;
}
