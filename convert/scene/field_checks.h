#ifndef CABLESIM_CONVERT_SCENE_FIELD_CHECKS_H_
#define CABLESIM_CONVERT_SCENE_FIELD_CHECKS_H_

// The field paths and checks that every section of the scene conversion
// (convert/scene/*.cc, SceneFromProto) words its errors with: a message is
// the field's path in proto field names, `: `, and the rule broken
// (`cables[1].length: must be > 0 (got -2)`). Numbers in messages are
// written by Num, so that every section prints them alike.

#include <map>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/scene.pb.h"
#include "convert/plausible_ranges.h"

// Early return on error, for the conversion's files only.
#define CABLESIM_RETURN_IF_ERROR(expr)   \
  do {                                   \
    const absl::Status _status = (expr); \
    if (!_status.ok()) return _status;   \
  } while (false)
#define CABLESIM_CONCAT_INNER(a, b) a##b
#define CABLESIM_CONCAT(a, b) CABLESIM_CONCAT_INNER(a, b)
#define CABLESIM_ASSIGN_OR_RETURN(lhs, expr) \
  CABLESIM_ASSIGN_OR_RETURN_IMPL(CABLESIM_CONCAT(_status_or_, __LINE__), lhs, expr)
#define CABLESIM_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                   \
  if (!tmp.ok()) return tmp.status();                  \
  lhs = std::move(*tmp)

namespace cablesim::scene_convert {

// InvalidArgument `path: rule`.
absl::Status Invalid(absl::string_view path, absl::string_view rule);
// InvalidArgument `path: unknown value 7 (must be A, B or C)`.
absl::Status UnknownEnumValue(absl::string_view path, int value, absl::string_view allowed);

// `parent.field`.
std::string Sub(absl::string_view parent, absl::string_view field);
// `parent.field[index]`, or `field[index]` at the top (`parent` empty).
std::string Indexed(absl::string_view parent, absl::string_view field, int index);

// A number as written in messages: 10 significant digits; exponents without
// '+' or leading zeros, and round numbers of 10,000 and more as exponents
// (1e-3, 1e6, 2.5e7, 1e308), as users write them.
std::string Num(double value);

absl::Status CheckFinite(absl::string_view path, double value);
absl::Status CheckPositive(absl::string_view path, double value);
absl::Status CheckNonNegative(absl::string_view path, double value);
// Whole value in [lo, hi].
absl::Status CheckIntRange(absl::string_view path, int value, int lo, int hi);
// A finite value in `range` (inclusive); the message gives the range.
absl::Status CheckRange(absl::string_view path, double value, const PlausibleRange& range);
// A value > 0 (the message most users meet first) and in `range`.
absl::Status CheckPositiveInRange(absl::string_view path, double value,
                                  const PlausibleRange& range);

// Names are echoed in messages: a long one is refused before that.
absl::Status CheckNameLength(absl::string_view path, absl::string_view name);

// Scene items' names to their indices (cables, bodies, probes).
using NameIndex = std::map<std::string, int, std::less<>>;
// Registers `name` of item `index` in `names`; `path` is the name field,
// `kind` the list (`cables`) a duplicate is reported in.
absl::Status RegisterName(absl::string_view path, absl::string_view kind, const std::string& name,
                          int index, NameIndex* names);

// A vector with finite components.
absl::StatusOr<Eigen::Vector3d> FiniteVector(absl::string_view path, const v1::Vec3& v);
// A vector whose every component lies in `range`.
absl::StatusOr<Eigen::Vector3d> VectorInRange(absl::string_view path, const v1::Vec3& v,
                                              const PlausibleRange& range);
// A non-zero direction, normalised. Its size does not matter, but its norm
// must be a double: components of 1e308 are rejected as overflowing, not
// called zero.
absl::StatusOr<Eigen::Vector3d> Direction(absl::string_view path, const v1::Vec3& v);

}  // namespace cablesim::scene_convert

#endif  // CABLESIM_CONVERT_SCENE_FIELD_CHECKS_H_
