#include "convert/scene_file.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/struct.pb.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "convert/moordyn_deck.h"

namespace cablesim {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;

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

// Longest parser message passed on [characters]: the parser's messages
// quote the input, which may be anything.
constexpr size_t kMaxMessageChars = 160 + kMaxQuotedChars;

// A parser's message made safe to print: on one line, every byte outside
// printable ASCII escaped as \xNN, cut after kMaxMessageChars.
std::string Printable(absl::string_view message) {
  std::string out;
  for (const char ch : message) {
    if (out.size() >= kMaxMessageChars) {
      out += "...";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '\n' || c == '\r' || c == '\t') {
      out += ' ';
    } else if (c >= 0x20 && c < 0x7f) {
      out += ch;
    } else {
      out += absl::StrFormat("\\x%02x", c);
    }
  }
  return std::string(absl::StripAsciiWhitespace(out));
}

// Length of the valid UTF-8 sequence starting at text[i] (1 to 4), or 0
// when the byte there does not start one (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF).
size_t Utf8SequenceLength(absl::string_view text, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  size_t n = 0;
  unsigned char low = 0x80, high = 0xbf;  // the second byte's range
  if (c >= 0xc2 && c <= 0xdf) {
    n = 2;
  } else if (c >= 0xe0 && c <= 0xef) {
    n = 3;
    if (c == 0xe0) low = 0xa0;
    if (c == 0xed) high = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    n = 4;
    if (c == 0xf0) low = 0x90;
    if (c == 0xf4) high = 0x8f;
  } else {
    return 0;
  }
  if (i + n > text.size()) return 0;
  if (byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (size_t k = 2; k < n; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xbf) return 0;
  }
  return n;
}

// Offset of the first byte of `text` that is not valid UTF-8; npos when
// all of it is.
size_t FirstInvalidUtf8(absl::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t n = Utf8SequenceLength(text, i);
    if (n == 0) return i;
    i += n;
  }
  return absl::string_view::npos;
}

// One byte at a time through JSON text, telling which bytes are inside
// strings: the scans below look at the nesting outside strings (and at
// keys), which the full parser only reaches after recursing into it.
class JsonStringTracker {
 public:
  enum class Byte {
    kOutside,   // outside any string, not a quote
    kOpen,      // the quote that opens a string
    kContent,   // an unescaped byte inside a string
    kEscape,    // a backslash inside a string, or the byte it escapes
    kClose,     // the quote that closes a string
  };

  Byte Next(char c) {
    if (!in_string_) {
      if (c != '"') return Byte::kOutside;
      in_string_ = true;
      return Byte::kOpen;
    }
    if (escaped_) {
      escaped_ = false;
      return Byte::kEscape;
    }
    if (c == '\\') {
      escaped_ = true;
      return Byte::kEscape;
    }
    if (c == '"') {
      in_string_ = false;
      return Byte::kClose;
    }
    return Byte::kContent;
  }

  bool in_string() const { return in_string_; }

 private:
  bool in_string_ = false;
  bool escaped_ = false;
};

// The field path (`cables[0].name`) of the JSON value, or key, that
// contains byte `offset` of `json`: a small scan of the nesting up to it.
// A key's escaped characters are left out of it.
std::string JsonPathAt(absl::string_view json, size_t offset) {
  struct Frame {
    bool array;
    int index = 0;
    std::string key;
    bool expecting_key = true;
  };
  std::vector<Frame> stack;
  JsonStringTracker strings;
  bool string_is_key = false;
  std::string current;
  for (size_t i = 0; i < offset && i < json.size(); ++i) {
    const char c = json[i];
    switch (strings.Next(c)) {
      case JsonStringTracker::Byte::kOpen:
        string_is_key = !stack.empty() && !stack.back().array && stack.back().expecting_key;
        current.clear();
        continue;
      case JsonStringTracker::Byte::kContent:
        if (string_is_key) current += c;
        continue;
      case JsonStringTracker::Byte::kEscape:
        continue;
      case JsonStringTracker::Byte::kClose:
        if (string_is_key && !stack.empty()) stack.back().key = current;
        continue;
      case JsonStringTracker::Byte::kOutside:
        break;
    }
    if (c == '{' || c == '[') {
      Frame frame;
      frame.array = c == '[';
      stack.push_back(std::move(frame));
    } else if ((c == '}' || c == ']') && !stack.empty()) {
      stack.pop_back();
    } else if (c == ':' && !stack.empty()) {
      stack.back().expecting_key = false;
    } else if (c == ',' && !stack.empty()) {
      if (stack.back().array) {
        ++stack.back().index;
      } else {
        stack.back().expecting_key = true;
        stack.back().key.clear();
      }
    }
  }
  if (strings.in_string() && string_is_key && !stack.empty()) stack.back().key = current;
  std::string path;
  for (const Frame& f : stack) {
    if (f.array) {
      absl::StrAppend(&path, "[", f.index, "]");
    } else if (!f.key.empty()) {
      absl::StrAppend(&path, path.empty() ? "" : ".", f.key);
    }
  }
  return Printable(path);
}

// The first string field (at any depth) of `message` that is not valid
// UTF-8, as InvalidArgument naming its path (`cables[0].name`).
absl::Status CheckStringsAreUtf8(const google::protobuf::Message& message,
                                 const std::string& path) {
  const google::protobuf::Reflection* reflection = message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  for (const FieldDescriptor* field : fields) {
    const std::string name = path.empty() ? field->name() : absl::StrCat(path, ".", field->name());
    const int count = field->is_repeated() ? reflection->FieldSize(message, field) : 1;
    for (int i = 0; i < count; ++i) {
      const std::string item = field->is_repeated() ? absl::StrCat(name, "[", i, "]") : name;
      if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
        const google::protobuf::Message& sub =
            field->is_repeated() ? reflection->GetRepeatedMessage(message, field, i)
                                 : reflection->GetMessage(message, field);
        if (absl::Status s = CheckStringsAreUtf8(sub, item); !s.ok()) return s;
      } else if (field->type() == FieldDescriptor::TYPE_STRING) {
        std::string scratch;
        const std::string& value =
            field->is_repeated()
                ? reflection->GetRepeatedStringReference(message, field, i, &scratch)
                : reflection->GetStringReference(message, field, &scratch);
        if (const size_t bad = FirstInvalidUtf8(value); bad != absl::string_view::npos) {
          return absl::InvalidArgumentError(
              absl::StrCat(item, ": not valid UTF-8 (byte ", bad, " of the string is ",
                           absl::StrFormat("0x%02x", static_cast<unsigned char>(value[bad])),
                           ")"));
        }
      }
    }
  }
  return absl::OkStatus();
}

absl::Status WithPath(const std::string& path, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat(path, ": ", status.message()));
}

absl::Status CheckSize(absl::string_view text, absl::string_view what) {
  if (text.size() > static_cast<size_t>(kMaxSceneBytes)) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", text.size(),
                                                   " bytes, more than the limit of ",
                                                   kMaxSceneBytes));
  }
  return absl::OkStatus();
}

// The nesting of arrays and objects outside strings, checked before any
// parser recurses into it.
absl::Status CheckJsonNesting(absl::string_view json, absl::string_view what) {
  int depth = 0;
  JsonStringTracker strings;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (strings.Next(c) != JsonStringTracker::Byte::kOutside) continue;
    if (c == '[' || c == '{') {
      if (++depth > kMaxSceneNesting) {
        return absl::InvalidArgumentError(absl::StrCat(what, ": nested deeper than ",
                                                       kMaxSceneNesting, " levels (at byte ", i,
                                                       ")"));
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return absl::OkStatus();
}

const char* KindName(const google::protobuf::Value& value) {
  switch (value.kind_case()) {
    case google::protobuf::Value::kNullValue:
      return "null";
    case google::protobuf::Value::kNumberValue:
      return "a number";
    case google::protobuf::Value::kStringValue:
      return "a string";
    case google::protobuf::Value::kBoolValue:
      return "true or false";
    case google::protobuf::Value::kStructValue:
      return "an object";
    case google::protobuf::Value::kListValue:
      return "a list";
    default:
      return "nothing";
  }
}

absl::Status CheckObjectKinds(const google::protobuf::Struct& object, const Descriptor& type,
                              const std::string& path);

// One value (an element, for a repeated field) of `field`.
absl::Status CheckValueKind(const google::protobuf::Value& value, const FieldDescriptor& field,
                            const std::string& path) {
  using V = google::protobuf::Value;
  const V::KindCase kind = value.kind_case();
  if (kind == V::kNullValue) return absl::OkStatus();  // the parser's rules apply
  const char* expected = nullptr;
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_MESSAGE:
      if (kind == V::kStructValue) {
        return CheckObjectKinds(value.struct_value(), *field.message_type(), path);
      }
      expected = "an object {...}";
      break;
    case FieldDescriptor::CPPTYPE_STRING:
      if (kind == V::kStringValue) return absl::OkStatus();
      expected = "a string";
      break;
    case FieldDescriptor::CPPTYPE_BOOL:
      if (kind == V::kBoolValue) return absl::OkStatus();
      expected = "true or false";
      break;
    case FieldDescriptor::CPPTYPE_ENUM:
      if (kind == V::kStringValue || kind == V::kNumberValue) return absl::OkStatus();
      expected = "a name (string)";
      break;
    default:  // numbers: "NaN", "Infinity" and quoted numbers are strings
      if (kind == V::kNumberValue || kind == V::kStringValue) return absl::OkStatus();
      expected = "a number";
      break;
  }
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": must be ", expected, " (got ", KindName(value), ")"));
}

absl::Status CheckObjectKinds(const google::protobuf::Struct& object, const Descriptor& type,
                              const std::string& path) {
  std::vector<std::string> keys;
  for (const auto& [key, value] : object.fields()) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  for (const std::string& key : keys) {
    const FieldDescriptor* field = type.FindFieldByName(key);
    if (field == nullptr) field = type.FindFieldByCamelcaseName(key);
    if (field == nullptr) continue;  // the parser names unknown fields
    const std::string field_path = path.empty() ? key : absl::StrCat(path, ".", key);
    const google::protobuf::Value& value = object.fields().at(key);
    if (!field->is_repeated()) {
      if (absl::Status s = CheckValueKind(value, *field, field_path); !s.ok()) return s;
      continue;
    }
    if (value.kind_case() == google::protobuf::Value::kNullValue) continue;
    if (value.kind_case() != google::protobuf::Value::kListValue) {
      return absl::InvalidArgumentError(absl::StrCat(field_path, ": must be a list [...] (got ",
                                                     KindName(value), ")"));
    }
    const auto& items = value.list_value().values();
    for (int i = 0; i < items.size(); ++i) {
      const absl::Status s = CheckValueKind(items[i], *field, absl::StrCat(field_path, "[", i, "]"));
      if (!s.ok()) return s;
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ParseStrictJson(absl::string_view json, absl::string_view what,
                             google::protobuf::Message* message) {
  if (absl::Status s = CheckSize(json, what); !s.ok()) return s;
  if (absl::Status s = CheckJsonNesting(json, what); !s.ok()) return s;
  // Text that is not UTF-8, named by the field it is in (the parser would
  // only say that some code point is not UTF-8).
  if (const size_t bad = FirstInvalidUtf8(json); bad != absl::string_view::npos) {
    const std::string path = JsonPathAt(json, bad);
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": ", path.empty() ? "" : absl::StrCat(path, ": "), "not valid UTF-8 (byte ", bad,
        " is ", absl::StrFormat("0x%02x", static_cast<unsigned char>(json[bad])), ")"));
  }
  const google::protobuf::StringPiece text(json.data(), json.size());
  // First the syntax and the kind of every value, on a generic JSON tree.
  google::protobuf::Value tree;
  if (const auto s = google::protobuf::util::JsonStringToMessage(text, &tree); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", Printable(s.message().as_string())));
  }
  if (tree.kind_case() != google::protobuf::Value::kStructValue) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": must be a JSON object {...} (got ", KindName(tree), ")"));
  }
  if (absl::Status s = CheckObjectKinds(tree.struct_value(), *message->GetDescriptor(), "");
      !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", Printable(s.message())));
  }
  // Then the message itself: field names and enum names.
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  options.case_insensitive_enum_parsing = false;
  if (const auto s = google::protobuf::util::JsonStringToMessage(text, message, options);
      !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", Printable(s.message().as_string())));
  }
  // JSON escapes (\\u...) cannot make invalid UTF-8 past the parser, but
  // the check is cheap and names the field.
  if (absl::Status s = CheckStringsAreUtf8(*message, ""); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", s.message()));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> ReadBoundedFile(const std::string& path, absl::string_view what) {
  struct stat info;
  if (::stat(path.c_str(), &info) != 0) {
    const int error = errno;
    const std::string message = absl::StrCat(path, ": cannot open ", what, ": ", std::strerror(error));
    if (error == ENOENT) return absl::NotFoundError(message);
    return absl::FailedPreconditionError(message);
  }
  if (S_ISDIR(info.st_mode)) {
    return absl::FailedPreconditionError(absl::StrCat(path, ": is a directory, not a ", what));
  }
  if (S_ISREG(info.st_mode) && info.st_size > kMaxSceneBytes) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", what, " is ", info.st_size,
                                                   " bytes, more than the limit of ",
                                                   kMaxSceneBytes));
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int error = errno;
    return absl::FailedPreconditionError(absl::StrCat(path, ": cannot open ", what, ": ",
                                                      error != 0 ? std::strerror(error) : "?"));
  }
  // Bounded: a device or a pipe has no size to check first.
  std::string text;
  char chunk[1 << 16];
  while (in && text.size() <= static_cast<size_t>(kMaxSceneBytes)) {
    in.read(chunk, sizeof chunk);
    text.append(chunk, static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) return absl::DataLossError(absl::StrCat(path, ": cannot read ", what));
  if (text.size() > static_cast<size_t>(kMaxSceneBytes)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", what, " is more than the limit of ",
                                                   kMaxSceneBytes, " bytes"));
  }
  return text;
}

absl::StatusOr<v1::Scene> ParseSceneJson(std::string_view json) {
  v1::Scene scene;
  if (absl::Status s = ParseStrictJson(absl::string_view(json.data(), json.size()),
                                       "invalid JSON scene", &scene);
      !s.ok()) {
    return s;
  }
  return scene;
}

absl::StatusOr<v1::Scene> ParseSceneTextFormat(std::string_view text) {
  if (absl::Status s = CheckSize(absl::string_view(text.data(), text.size()),
                                 "invalid text-format scene");
      !s.ok()) {
    return s;
  }
  v1::Scene scene;
  CollectingErrorCollector errors;
  google::protobuf::TextFormat::Parser parser;
  parser.RecordErrorsTo(&errors);
  parser.SetRecursionLimit(kMaxSceneNesting);
  if (!parser.ParseFromString(std::string(text), &scene)) {
    return absl::InvalidArgumentError(
        absl::StrCat("invalid text-format scene: ", Printable(errors.Joined())));
  }
  // Strings that are not UTF-8 (raw bytes, or escapes such as "\\377"):
  // refused here naming the field, before anything serializes the scene.
  if (absl::Status s = CheckStringsAreUtf8(scene, ""); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("invalid text-format scene: ", s.message()));
  }
  return scene;
}

bool IsTextFormatScenePath(std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  return absl::EndsWith(path, ".txtpb") || absl::EndsWith(path, ".textproto") ||
         absl::EndsWith(path, ".pbtxt");
}

absl::StatusOr<v1::Scene> ReadSceneFile(const std::string& path) {
  absl::StatusOr<std::string> text = ReadBoundedFile(path, "scene file");
  if (!text.ok()) return text.status();
  // A MoorDyn deck's messages already start with the path and its line.
  if (IsMoorDynDeck(path, *text)) {
    // Files the deck names are relative to its directory (MoorDyn's base
    // path).
    const std::string dir = std::filesystem::path(path).parent_path().string();
    return SceneFromMoorDyn(*text, path, [&dir](std::string_view name) {
      return ReadBoundedFile((std::filesystem::path(dir) / std::string(name)).string(),
                             "file the deck names");
    });
  }
  absl::StatusOr<v1::Scene> scene =
      IsTextFormatScenePath(path) ? ParseSceneTextFormat(*text) : ParseSceneJson(*text);
  if (!scene.ok()) return WithPath(path, scene.status());
  return scene;
}

}  // namespace cablesim
