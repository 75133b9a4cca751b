#ifndef CABLESIM_CONVERT_SCENE_FILE_H_
#define CABLESIM_CONVERT_SCENE_FILE_H_

// Reading cablesim.v1.Scene messages from scene files. Parsing checks only
// the syntax and the field names; SceneFromProto (convert/scene_from_proto.h)
// checks the values.

#include <cstdint>
#include <string>
#include <string_view>

#include <google/protobuf/message.h>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim {

// Limits on scene text, the same for a file read by `cablesim` and for a
// scene given to the server as JSON text (README "Limits").
// Largest scene (or sweep) file or JSON text [bytes]; a scene is a few
// kilobytes, a 100,000-point polyline about 6 MB. Below the server's
// default gRPC message limit, so a file that reads also sends.
inline constexpr int64_t kMaxSceneBytes = 8 << 20;
// Deepest nesting of JSON arrays and objects (or text-format messages); a
// scene needs 5 (`cables[0].points[0]`).
inline constexpr int kMaxSceneNesting = 32;
// Longest parse-error excerpt quoted from the input [characters].
inline constexpr int kMaxQuotedChars = 60;

// Parses protobuf JSON `json` into `message` strictly, as every scene and
// sweep file is read: at most kMaxSceneBytes and kMaxSceneNesting levels
// (checked before parsing), every value of the kind its field takes (an
// object for a message, a list for a repeated field, `"cables": {...}` is
// an error naming `cables`), no unknown fields or enum names. Errors are
// InvalidArgument, name the field where the parser knows it, and quote the
// input only as a short escaped excerpt. `what` starts the message
// (`invalid JSON scene`).
absl::Status ParseStrictJson(absl::string_view json, absl::string_view what,
                             google::protobuf::Message* message);

// Reads the file at `path`, at most kMaxSceneBytes: the size is checked
// (stat) before reading, and the read is bounded, so /dev/zero or a pipe
// fails fast. NotFound when it does not exist, FailedPrecondition for a
// directory or an unreadable file, InvalidArgument when too large. Every
// message starts with `path: `; `what` names the file's kind.
absl::StatusOr<std::string> ReadBoundedFile(const std::string& path, absl::string_view what);

// Parses a scene written in protobuf JSON (proto field names such as
// `youngs_modulus`, or their lowerCamelCase forms) with ParseStrictJson. Returns InvalidArgument with the parser's message,
// which names the offending field.
absl::StatusOr<v1::Scene> ParseSceneJson(std::string_view json);

// Parses a scene written in protobuf text format. Unknown fields are
// rejected; at most kMaxSceneBytes and kMaxSceneNesting. Returns InvalidArgument with the parser's message (line:column
// and field name).
absl::StatusOr<v1::Scene> ParseSceneTextFormat(std::string_view text);

// True when `path` names a text-format scene: it ends in `.txtpb`,
// `.textproto` or `.pbtxt`. Every other file is read as JSON.
bool IsTextFormatScenePath(std::string_view path);

// Reads and parses the scene file at `path` (see IsTextFormatScenePath for
// the format; a MoorDyn deck, IsMoorDynDeck, is read by SceneFromMoorDyn:
// convert/moordyn_deck.h), with ReadBoundedFile. Returns NotFound when the file does not
// exist, another non-OK status when it cannot be read, and InvalidArgument
// when it is too large or does not parse.
// Every error message starts with `path: `.
absl::StatusOr<v1::Scene> ReadSceneFile(const std::string& path);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_SCENE_FILE_H_
