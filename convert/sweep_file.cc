#include "convert/sweep_file.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"

namespace cablesim {
namespace {

namespace fs = std::filesystem;

// True when `inner` (both canonical) is `dir` or lies below it.
bool IsUnder(const fs::path& inner, const fs::path& dir) {
  const auto [dir_end, inner_end] = std::mismatch(dir.begin(), dir.end(), inner.begin(), inner.end());
  // A trailing empty component ("dir/") matches anything below.
  return dir_end == dir.end() || (std::next(dir_end) == dir.end() && dir_end->empty());
}

}  // namespace

absl::StatusOr<v1::SubmitSweepRequest> ParseSweepFile(absl::string_view json,
                                                      const std::string& path,
                                                      bool allow_outside) {
  v1::SweepFile file;
  if (absl::Status s = ParseStrictJson(json, "invalid sweep file", &file); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", s.message()));
  }
  v1::SubmitSweepRequest request;
  request.set_name(file.name());
  *request.mutable_axes() = file.axes();
  if (!file.base_file().empty()) {
    if (file.has_base()) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": give base or base_file, not both"));
    }
    const fs::path dir = fs::path(path).parent_path().empty() ? fs::path(".")
                                                              : fs::path(path).parent_path();
    fs::path base = file.base_file();
    if (base.is_relative()) base = dir / base;
    if (!allow_outside) {
      std::error_code error;
      const fs::path canonical_dir = fs::weakly_canonical(dir, error);
      const fs::path canonical_base = error ? fs::path() : fs::weakly_canonical(base, error);
      if (error || !IsUnder(canonical_base, canonical_dir) || canonical_base == canonical_dir) {
        return absl::InvalidArgumentError(absl::StrCat(
            path, ": base_file: must be under the sweep file's directory (",
            canonical_dir.string(), "); give --allow-outside to read a scene from elsewhere"));
      }
    }
    absl::StatusOr<v1::Scene> scene = ReadSceneFile(base.string());
    if (!scene.ok()) {
      return absl::Status(scene.status().code(),
                          absl::StrCat(path, ": base_file: ", scene.status().message()));
    }
    *request.mutable_base() = std::move(*scene);
  } else {
    *request.mutable_base() = file.base();
  }
  if (request.name().empty()) request.set_name(fs::path(path).stem().string());
  return request;
}

absl::StatusOr<v1::SubmitSweepRequest> ReadSweepFile(const std::string& path,
                                                     bool allow_outside) {
  const absl::StatusOr<std::string> text = ReadBoundedFile(path, "sweep file");
  if (!text.ok()) return text.status();
  return ParseSweepFile(*text, path, allow_outside);
}

}  // namespace cablesim
