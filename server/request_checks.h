#ifndef CABLESIM_SERVER_REQUEST_CHECKS_H_
#define CABLESIM_SERVER_REQUEST_CHECKS_H_

// What the server checks before it accepts work: the scene is valid
// (InvalidArgument naming the field), the engine can build it, and it stays
// within the server's limits (ResourceExhausted naming the limit); a sweep
// expands to valid items (errors naming `axes[i]`).

#include <cstdint>
#include <functional>
#include <memory>
#include <limits>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "absl/time/time.h"
#include "cablesim/v1/service.pb.h"
#include "engine/run/simulation.h"

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
  // Nice levels a computation's thread goes below the caller's (see
  // kComputeNice, the same 10): 10 in cablesim-server, 0 in-process (`cablesim run`
  // and `sweep` have no calls to keep answering, and a foreground run
  // should not yield to everything else on the machine).
  int compute_nice = 10;
  // Limits added later default to "none" here, so that in-process users
  // (`cablesim run`) keep the engine's own bounds; cablesim-server sets
  // them from its flags (README, service section).
  // MODAL: modes computed per run, and the memory the eigensolver's basis
  // and the mode shapes take (8 bytes x dofs x (3 modes + 1) estimated).
  int max_modes = std::numeric_limits<int>::max();
  int64_t max_modal_bytes = std::numeric_limits<int64_t>::max();
  // Bytes of any one string in a request (names, references, sweep paths).
  int64_t max_name_bytes = std::numeric_limits<int64_t>::max();
  // Counted streams (Run, GetEnergy of a scene) of one client address.
  int max_streams_per_peer = std::numeric_limits<int>::max();
  // Jobs queued or running that one client address submitted (sweep
  // items included).
  int64_t max_queued_jobs_per_peer = std::numeric_limits<int64_t>::max();
  // Coordinates of the model built (nodal and body coordinates).
  int64_t max_coordinates = std::numeric_limits<int64_t>::max();
  // Retention of finished jobs and sweeps: deleted once finished longer
  // ago than this, or, oldest first, while the stored results take more
  // than max_bytes. Infinite / max: kept.
  absl::Duration retention_max_age = absl::InfiniteDuration();
  int64_t retention_max_bytes = std::numeric_limits<int64_t>::max();
  // Unary calls that carry a scene (Validate, SubmitJob, SubmitSweep) in
  // progress at once, in all and per client (ClientKey), and the memory
  // they may hold together: each is estimated at kRequestMemoryFactor
  // times its request's size (the parsed scene, the model built from it).
  int max_unary_calls = std::numeric_limits<int>::max();
  int max_unary_calls_per_peer = std::numeric_limits<int>::max();
  int64_t max_inflight_bytes = std::numeric_limits<int64_t>::max();
  // Work of a run (EstimateWork): steps x the force evaluation's units.
  int64_t max_work_units = std::numeric_limits<int64_t>::max();
};

// The work of one force evaluation, in units of one Gauss point of one
// element: every element's Gauss points (at most GaussRule::kMaxPoints),
// each summing every wave component once more, plus each body contact
// point and each element a sheave may wrap (and the seabed's elements).
int64_t WorkPerStep(const Scene& scene, int64_t elements);

// The memory a scene-carrying request holds while it is checked, per byte
// of the request: measured at about 18 (a 7.8 MB scene held 140 MB while
// its model was built), rounded up.
inline constexpr int64_t kRequestMemoryFactor = 20;

// The limits cablesim-server applies by default (its flags' defaults) and
// `cablesim` applies to its in-process runs unless --no-limits.
ServerLimits DefaultServerLimits();

struct CheckedScene {
  Scene scene;
  // The model CheckScene built to cost the scene; a Run or GetEnergy call
  // runs this one (RunSceneWithinMemory) instead of building it again.
  // Shared so that CheckedScene stays copyable; it runs once.
  std::shared_ptr<PreparedRun> prepared;
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
// The same, or `moordyn`, a MoorDyn v2 input file's text (the request
// field scene_moordyn), read by SceneFromMoorDyn (convert/moordyn_deck.h):
// its errors start with `scene_moordyn:` and the deck's line. At most one
// of the three.
absl::StatusOr<v1::Scene> SceneOrDeckOfRequest(bool has_scene, const v1::Scene& scene,
                                               const std::string& json,
                                               const std::string& moordyn);

// Validates `proto`, builds its model and checks it against `limits`:
// every string's length, the steps, frames and numbers kept, the elements
// summed over all cables before anything is built, then the model's
// elements and coordinates and, for MODAL, the modes and their memory.
// The one costing of a scene: Validate, Run, SubmitJob, sweeps and
// GetEnergy all call it. `should_stop` (empty: never) is asked while the
// model is built (a scene of many elements takes seconds): Cancelled when
// it said stop.
absl::StatusOr<CheckedScene> CheckScene(const v1::Scene& proto, const ServerLimits& limits,
                                        const std::function<bool()>& should_stop = {});

// RunScene, with an allocation that fails (std::bad_alloc: the run needs
// more memory than the server can get) answered as ResourceExhausted
// naming the scene's size, instead of an exception that the RPC would
// report as UNKNOWN (or that would end a job's worker thread). The run
// computes on a thread of its own, kComputeNice below the server's
// priority, the caller waiting: under overload the threads that answer
// calls (refusals, health checks, job status) still get the processor at
// once rather than a share among every running computation
// (bench/server_load_bench.cc).
inline constexpr int kComputeNice = 10;
absl::StatusOr<RunSummary> RunSceneWithinMemory(const Scene& scene, FrameSink* sink,
                                                const RunControl& control,
                                                int compute_nice = kComputeNice);
// The same for a checked scene: runs the model CheckScene built (built
// once per request), or builds it again when that one has run.
absl::StatusOr<RunSummary> RunSceneWithinMemory(CheckedScene* checked, FrameSink* sink,
                                                const RunControl& control,
                                                int compute_nice = kComputeNice);

// ResourceExhausted naming the first string field of `message` (its path,
// after `prefix`) longer than limits.max_name_bytes.
absl::Status CheckStringLengths(const google::protobuf::Message& message,
                                const ServerLimits& limits, const std::string& prefix = "");

// The broken thresholds of a finished sweep item with `summary`, one line
// each (SweepItem.threshold_failures), in the order of `thresholds`.
std::vector<std::string> ThresholdFailures(
    const google::protobuf::RepeatedPtrField<v1::SweepThreshold>& thresholds,
    const v1::RunSummary& summary);

// `error` from a refusal whose message reads `path: rule`
// (convert/scene_from_proto.h; a message without such a path: all of it
// the rule), its code's name ("INVALID_ARGUMENT", "RESOURCE_EXHAUSTED").
void SetFieldError(const absl::Status& status, v1::FieldError* error);

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
