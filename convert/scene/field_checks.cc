#include "convert/scene/field_checks.h"

#include <cmath>
#include <string>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim::scene_convert {

absl::Status Invalid(absl::string_view path, absl::string_view rule) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", rule));
}

std::string Sub(absl::string_view parent, absl::string_view field) {
  return absl::StrCat(parent, ".", field);
}

std::string Indexed(absl::string_view parent, absl::string_view field, int index) {
  return absl::StrCat(parent, parent.empty() ? "" : ".", field, "[", index, "]");
}

std::string Num(double value) {
  std::string text = absl::StrFormat("%.10g", value);
  if (text.find_first_of("e.") == std::string::npos && text.size() >= 5 &&
      absl::EndsWith(text, "0000")) {
    text = absl::StrFormat("%.9e", value);
    const size_t e = text.find('e');
    size_t mantissa_end = e;
    while (text[mantissa_end - 1] == '0') --mantissa_end;
    if (text[mantissa_end - 1] == '.') --mantissa_end;
    text = text.substr(0, mantissa_end) + text.substr(e);
  }
  const size_t e = text.find('e');
  if (e == std::string::npos) return text;
  size_t digits = e + 1;
  std::string exponent;
  if (text[digits] == '-') exponent = "-";
  if (text[digits] == '-' || text[digits] == '+') ++digits;
  while (digits + 1 < text.size() && text[digits] == '0') ++digits;
  return absl::StrCat(text.substr(0, e + 1), exponent, text.substr(digits));
}

absl::Status CheckFinite(absl::string_view path, double value) {
  if (!std::isfinite(value))
    return Invalid(path, absl::StrCat("must be finite (got ", Num(value), ")"));
  return absl::OkStatus();
}

absl::Status CheckPositive(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value > 0)) return Invalid(path, absl::StrCat("must be > 0 (got ", Num(value), ")"));
  return absl::OkStatus();
}

absl::Status CheckNonNegative(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value >= 0)) return Invalid(path, absl::StrCat("must be >= 0 (got ", Num(value), ")"));
  return absl::OkStatus();
}

absl::Status CheckNameLength(absl::string_view path, absl::string_view name) {
  if (name.size() > static_cast<size_t>(plausible::kMaxNameBytes)) {
    return Invalid(
        path, absl::StrCat("at most ", plausible::kMaxNameBytes, " bytes (got ", name.size(), ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckIntRange(absl::string_view path, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    return Invalid(path, absl::StrCat("must be in [", lo, ", ", hi, "] (got ", value, ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckRange(absl::string_view path, double value, const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value >= range.lo && value <= range.hi)) {
    return Invalid(path, absl::StrCat("must be in [", Num(range.lo), ", ", Num(range.hi), "] ",
                                      range.unit, " (got ", Num(value), ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckPositiveInRange(absl::string_view path, double value,
                                  const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckPositive(path, value));
  return CheckRange(path, value, range);
}

absl::Status UnknownEnumValue(absl::string_view path, int value, absl::string_view allowed) {
  return Invalid(path, absl::StrCat("unknown value ", value, " (must be ", allowed, ")"));
}

absl::Status RegisterName(absl::string_view path, absl::string_view kind, const std::string& name,
                          int index, NameIndex* names) {
  if (name.empty()) return Invalid(path, "required");
  CABLESIM_RETURN_IF_ERROR(CheckNameLength(path, name));
  const auto [it, inserted] = names->emplace(name, index);
  if (!inserted) {
    return Invalid(
        path, absl::StrCat("duplicate name \"", name, "\" (also ", kind, "[", it->second, "])"));
  }
  return absl::OkStatus();
}

absl::StatusOr<Eigen::Vector3d> FiniteVector(absl::string_view path, const v1::Vec3& v) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "x"), v.x()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "y"), v.y()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "z"), v.z()));
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

absl::StatusOr<Eigen::Vector3d> VectorInRange(absl::string_view path, const v1::Vec3& v,
                                              const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "x"), v.x(), range));
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "y"), v.y(), range));
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "z"), v.z(), range));
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

// Smallest norm of a direction that is normalised without losing digits.
constexpr double kMinDirectionNorm = 1e-100;

absl::StatusOr<Eigen::Vector3d> Direction(absl::string_view path, const v1::Vec3& v) {
  CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d result, FiniteVector(path, v));
  const double norm = result.norm();
  if (!std::isfinite(norm)) {
    return Invalid(
        path, absl::StrCat("norm overflows (largest component ", Num(result.cwiseAbs().maxCoeff()),
                           "); give a direction of moderate size"));
  }
  if (!(norm >= kMinDirectionNorm)) {
    return Invalid(path, absl::StrCat("must be non-zero (got norm ", Num(norm), ")"));
  }
  return Eigen::Vector3d(result / norm);
}

}  // namespace cablesim::scene_convert
