#include "convert/scene_file.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace cablesim {
namespace {

// Largest scene file read [bytes]; a scene is a few kilobytes.
constexpr std::streamoff kMaxSceneFileBytes = 64 << 20;

// Collects the text-format parser's errors instead of logging them.
class CollectingErrorCollector : public google::protobuf::io::ErrorCollector {
 public:
  void AddError(int line, google::protobuf::io::ColumnNumber column,
                const std::string& message) override {
    // The parser counts lines and columns from 0.
    messages_.push_back(absl::StrCat(line + 1, ":", column + 1, ": ", message));
  }
  void AddWarning(int line, google::protobuf::io::ColumnNumber column,
                  const std::string& message) override {}

  std::string Joined() const { return absl::StrJoin(messages_, "; "); }

 private:
  std::vector<std::string> messages_;
};

// The parser's message on one line.
std::string OneLine(std::string message) {
  std::replace(message.begin(), message.end(), '\n', ' ');
  return std::string(absl::StripAsciiWhitespace(message));
}

absl::Status WithPath(const std::string& path, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat(path, ": ", status.message()));
}

}  // namespace

absl::StatusOr<v1::Scene> ParseSceneJson(std::string_view json) {
  v1::Scene scene;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  options.case_insensitive_enum_parsing = false;
  const auto status = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(json.data(), json.size()), &scene, options);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("invalid JSON scene: ", OneLine(std::string(status.message()))));
  }
  return scene;
}

absl::StatusOr<v1::Scene> ParseSceneTextFormat(std::string_view text) {
  v1::Scene scene;
  CollectingErrorCollector errors;
  google::protobuf::TextFormat::Parser parser;
  parser.RecordErrorsTo(&errors);
  if (!parser.ParseFromString(std::string(text), &scene)) {
    return absl::InvalidArgumentError(absl::StrCat("invalid text-format scene: ", errors.Joined()));
  }
  return scene;
}

bool IsTextFormatScenePath(std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  return absl::EndsWith(path, ".txtpb") || absl::EndsWith(path, ".textproto") ||
         absl::EndsWith(path, ".pbtxt");
}

absl::StatusOr<v1::Scene> ReadSceneFile(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) {
    return absl::FailedPreconditionError(absl::StrCat(path, ": is a directory, not a scene file"));
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    const std::string reason = error != 0 ? std::strerror(error) : "cannot open";
    if (error == ENOENT) {
      return absl::NotFoundError(absl::StrCat(path, ": cannot open scene file: ", reason));
    }
    return absl::FailedPreconditionError(absl::StrCat(path, ": cannot open scene file: ", reason));
  }
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) {
    return absl::DataLossError(absl::StrCat(path, ": cannot read scene file"));
  }
  const std::string text = std::move(contents).str();
  if (static_cast<std::streamoff>(text.size()) > kMaxSceneFileBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": scene file is larger than ", kMaxSceneFileBytes, " bytes"));
  }
  absl::StatusOr<v1::Scene> scene =
      IsTextFormatScenePath(path) ? ParseSceneTextFormat(text) : ParseSceneJson(text);
  if (!scene.ok()) return WithPath(path, scene.status());
  return scene;
}

}  // namespace cablesim
