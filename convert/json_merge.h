#ifndef CABLESIM_CONVERT_JSON_MERGE_H_
#define CABLESIM_CONVERT_JSON_MERGE_H_

// Merges a JSON "patch" into a JSON document, for variants of one scene
// (bench/work_precision: the same scene with other solver settings or
// another mesh). Works on generic JSON (google.protobuf.Struct), so a patch
// may name fields and enum values this build's scene.proto does not know
// yet; parsing the result as a Scene (ParseSceneJson) then rejects them with
// the field named.
//
// Rules: an object in the patch merges key by key into the document's object
// (recursively); an array in the patch merges element by element into the
// document's array of objects at the same key (patch element k into element
// k; extra patch elements are appended); any other patch value replaces the
// document's value.

#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace cablesim {

// Both must be JSON objects. Returns the merged object as JSON text, or
// InvalidArgument naming which input does not parse.
absl::StatusOr<std::string> MergeJson(std::string_view document, std::string_view patch);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_JSON_MERGE_H_
