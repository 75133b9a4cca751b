#ifndef CABLESIM_CONVERT_SCENE_FILE_H_
#define CABLESIM_CONVERT_SCENE_FILE_H_

// Reading cablesim.v1.Scene messages from scene files. Parsing checks only
// the syntax and the field names; SceneFromProto (convert/scene_from_proto.h)
// checks the values.

#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim {

// Parses a scene written in protobuf JSON (proto field names such as
// `youngs_modulus`, or their lowerCamelCase forms). Unknown fields and unknown
// enum names are rejected. Returns InvalidArgument with the parser's message,
// which names the offending field.
absl::StatusOr<v1::Scene> ParseSceneJson(std::string_view json);

// Parses a scene written in protobuf text format. Unknown fields are
// rejected. Returns InvalidArgument with the parser's message (line:column
// and field name).
absl::StatusOr<v1::Scene> ParseSceneTextFormat(std::string_view text);

// True when `path` names a text-format scene: it ends in `.txtpb`,
// `.textproto` or `.pbtxt`. Every other file is read as JSON.
bool IsTextFormatScenePath(std::string_view path);

// Reads and parses the scene file at `path` (see IsTextFormatScenePath for
// the format). Returns NotFound when the file does not exist, another non-OK
// status when it cannot be read, and InvalidArgument when it does not parse.
// Every error message starts with `path: `.
absl::StatusOr<v1::Scene> ReadSceneFile(const std::string& path);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SCENE_FILE_H_
