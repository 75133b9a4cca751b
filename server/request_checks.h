#ifndef CABLESIM_SERVER_REQUEST_CHECKS_H_
#define CABLESIM_SERVER_REQUEST_CHECKS_H_

// What the server checks before it accepts work: the scene is valid
// (InvalidArgument naming the field), the engine can build it, and it stays
// within the server's limits (ResourceExhausted naming the limit); a sweep
// expands to valid items (errors naming `axes[i]`).

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "cablesim/v1/service.pb.h"
#include "engine/simulation.h"

namespace cablesim {

struct ServerLimits {
  int max_elements = 5000;        // cable elements (inserted nodes included)
  int64_t max_steps = 5'000'000;  // nominal steps (duration / step) or load steps
  int64_t max_frames = 200'000;   // output frames per run
  // Numbers in a run's trajectory (frames x columns): a job keeps them in
  // memory and in SQLite. 32 Mi doubles = 256 MiB.
  int64_t max_trajectory_values = 32 << 20;
  int max_sweep_items = 1000;        // items of one sweep
  int max_streams = 64;              // concurrent Run / GetEnergy(scene) calls
  int max_message_bytes = 16 << 20;  // gRPC receive limit
  // A Run stream whose client reads nothing for this long is cancelled.
  absl::Duration stall_timeout = absl::Seconds(30);
};

struct CheckedScene {
  Scene scene;
  ModelInfo info;
  double end_time_s = 0;      // duration (DYNAMIC) or 1 (STATIC)
  int64_t nominal_steps = 0;  // duration / step, or load steps
  int64_t frames = 0;         // output frames the run will write
};

// The scene a request carries: `scene`, or `json` (its JSON text, the
// request field `json_field`) parsed with the strict scene-file parser
// (convert/scene_file.h). InvalidArgument, starting with `json_field: `,
// when both are given or the text does not parse.
absl::StatusOr<v1::Scene> SceneOfRequest(bool has_scene, const v1::Scene& scene,
                                         const std::string& json,
                                         absl::string_view json_field = "scene_json");

// Validates `proto`, builds its model and checks it against `limits`.
absl::StatusOr<CheckedScene> CheckScene(const v1::Scene& proto, const ServerLimits& limits);

// The items of a sweep (cartesian product, last axis fastest), each
// checked with CheckScene; `end_times_s` receives each item's end time.
absl::StatusOr<std::vector<v1::Scene>> ExpandSweep(const v1::SubmitSweepRequest& request,
                                                   const ServerLimits& limits,
                                                   std::vector<double>* end_times_s);

// The axis values of item `index`.
std::vector<double> SweepAxisValues(const google::protobuf::RepeatedPtrField<v1::SweepAxis>& axes,
                                    int64_t index);

}  // namespace cablesim

#endif  // CABLESIM_SERVER_REQUEST_CHECKS_H_
