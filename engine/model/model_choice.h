#ifndef CABLESIM_ENGINE_MODEL_MODEL_CHOICE_H_
#define CABLESIM_ENGINE_MODEL_MODEL_CHOICE_H_

// Which model a scene needs: planar (2 coordinates per point) when every
// cable, body, body point, joint, load, probe, gravity and initial velocity
// lies in the x-y plane and every rotation is about z; spatial otherwise.
// `Scene::model` may force either; PLANAR on a scene that leaves the plane
// is an error naming the first field that does.

#include <string>

#include "absl/status/statusor.h"
#include "engine/scene/scene.h"

namespace cablesim {

// The first field of `scene` (a path such as "bodies[0].position.z") that
// leaves the x-y plane, or an empty string when the scene is planar.
std::string OutOfPlaneField(const Scene& scene);

// 2 or 3. InvalidArgument (field "model") when PLANAR is forced on a
// scene that is not planar.
absl::StatusOr<int> ChooseDimension(const Scene& scene);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_MODEL_MODEL_CHOICE_H_
