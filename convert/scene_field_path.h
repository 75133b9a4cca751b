#ifndef CABLESIM_CONVERT_SCENE_FIELD_PATH_H_
#define CABLESIM_CONVERT_SCENE_FIELD_PATH_H_

// Setting one field of a cablesim.v1.Scene named by its path, for parameter
// sweeps: proto field names separated by '.', a repeated message field
// indexed with [i], for example `cables[0].elements`, `solver.step`,
// `gravity.y`, `bodies[1].cylinder.diameter`. Works through protobuf
// reflection, so every field added to scene.proto can be swept at once.

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim {

// Sets the numeric, boolean (0 or 1) or enum (by number) field at `path` of
// `scene` to `value`; unset intermediate messages are created, but indexed
// elements must exist. An integer (or enum or boolean) field takes only
// whole values in its range. Returns InvalidArgument saying what is wrong
// with the path or the value (the caller adds where the path came from).
absl::Status SetSceneField(v1::Scene* scene, absl::string_view path, double value);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SCENE_FIELD_PATH_H_
