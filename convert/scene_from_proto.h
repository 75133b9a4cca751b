#ifndef CABLESIM_CONVERT_SCENE_FROM_PROTO_H_
#define CABLESIM_CONVERT_SCENE_FROM_PROTO_H_

// Validation of a cablesim.v1.Scene and its conversion to the engine's plain
// cablesim::Scene, with the defaults documented in scene.proto applied.

#include <string_view>

#include "absl/status/statusor.h"
#include "cablesim/v1/scene.pb.h"
#include "engine/scene/scene.h"

namespace cablesim {

// Checks every field of `proto` and converts it. On the first invalid field
// returns InvalidArgument whose message starts with the field's path in proto
// field names, then `: ` and the rule broken, for example
//   cables[1].length: must be > 0
//   joints[0].a.cable: no cable named "bem"
// The result keeps the scene's indices; derived values are filled in (area
// and second moment from a diameter, a cylinder's mass and inertia, a
// straight cable's two points, normalised body axes, solver defaults).
// Whether the scene is planar is the engine's decision (model_choice.h).
absl::StatusOr<Scene> SceneFromProto(const v1::Scene& proto);

// Proto enum to engine enum. An UNSPECIFIED value maps to the documented
// default; a value outside the enum returns InvalidArgument naming `path`.
absl::StatusOr<BendingModel> BendingFromProto(v1::Bending bending, std::string_view path);
absl::StatusOr<JointType> JointTypeFromProto(v1::JointType type, std::string_view path);
absl::StatusOr<Analysis> AnalysisFromProto(v1::Analysis analysis, std::string_view path);
absl::StatusOr<Integrator> IntegratorFromProto(v1::Integrator integrator, std::string_view path);
absl::StatusOr<LinearSolverKind> LinearSolverFromProto(v1::LinearSolver solver,
                                                       std::string_view path);

// The scene-file spelling of an engine enum value (AnalysisName, ...) is
// declared with the enums in engine/scene/scene.h.

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SCENE_FROM_PROTO_H_
