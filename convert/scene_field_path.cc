#include "convert/scene_field_path.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"

namespace cablesim {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

absl::Status Bad(absl::string_view path, absl::string_view why) {
  return absl::InvalidArgumentError(absl::StrCat("path \"", path, "\": ", why));
}

// `value` as an integer in [lo, hi], or an error.
absl::Status WholeIn(double value, double lo, double hi, absl::string_view path, int64_t* out) {
  if (!std::isfinite(value) || value != std::floor(value) || value < lo || value > hi) {
    return Bad(path, absl::StrFormat("value %.17g is not a whole number in [%.17g, %.17g]", value,
                                     lo, hi));
  }
  *out = static_cast<int64_t>(value);
  return absl::OkStatus();
}

}  // namespace

absl::Status SetSceneField(v1::Scene* scene, absl::string_view path, double value) {
  if (path.empty()) return Bad(path, "empty");
  Message* message = scene;
  const std::vector<absl::string_view> parts = absl::StrSplit(path, '.');
  for (size_t p = 0; p < parts.size(); ++p) {
    absl::string_view part = parts[p];
    const bool last = p + 1 == parts.size();
    int64_t index = -1;
    if (const size_t open = part.find('['); open != absl::string_view::npos) {
      if (part.back() != ']' ||
          !absl::SimpleAtoi(part.substr(open + 1, part.size() - open - 2), &index) || index < 0) {
        return Bad(path, absl::StrCat("bad index in \"", part, "\""));
      }
      part = part.substr(0, open);
    }
    const Descriptor* descriptor = message->GetDescriptor();
    const Reflection* reflection = message->GetReflection();
    const FieldDescriptor* field = descriptor->FindFieldByName(std::string(part));
    if (field == nullptr) {
      return Bad(path, absl::StrCat("no field \"", part, "\" in ", descriptor->name()));
    }
    if (field->is_repeated() != (index >= 0)) {
      return Bad(path, field->is_repeated()
                           ? absl::StrCat("\"", part, "\" is repeated: give an index")
                           : absl::StrCat("\"", part, "\" is not repeated"));
    }
    if (!last) {
      if (field->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE) {
        return Bad(path, absl::StrCat("\"", part, "\" is not a message"));
      }
      if (index >= 0) {
        const int size = reflection->FieldSize(*message, field);
        if (index >= size) {
          return Bad(path, absl::StrCat(part, "[", index, "] does not exist (", size,
                                        " in the base scene)"));
        }
        message = reflection->MutableRepeatedMessage(message, field, static_cast<int>(index));
      } else {
        message = reflection->MutableMessage(message, field);
      }
      continue;
    }
    if (index >= 0) return Bad(path, "a sweep sets a single value, not a repeated element");
    int64_t whole = 0;
    switch (field->cpp_type()) {
      case FieldDescriptor::CPPTYPE_DOUBLE:
        reflection->SetDouble(message, field, value);
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_FLOAT:
        reflection->SetFloat(message, field, static_cast<float>(value));
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_INT32:
        if (auto s = WholeIn(value, std::numeric_limits<int32_t>::min(),
                             std::numeric_limits<int32_t>::max(), path, &whole);
            !s.ok()) {
          return s;
        }
        reflection->SetInt32(message, field, static_cast<int32_t>(whole));
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_INT64:
        if (auto s = WholeIn(value, -9.0e15, 9.0e15, path, &whole); !s.ok()) return s;
        reflection->SetInt64(message, field, whole);
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_UINT32:
        if (auto s = WholeIn(value, 0, std::numeric_limits<uint32_t>::max(), path, &whole);
            !s.ok()) {
          return s;
        }
        reflection->SetUInt32(message, field, static_cast<uint32_t>(whole));
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_UINT64:
        if (auto s = WholeIn(value, 0, 9.0e15, path, &whole); !s.ok()) return s;
        reflection->SetUInt64(message, field, static_cast<uint64_t>(whole));
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_BOOL:
        if (auto s = WholeIn(value, 0, 1, path, &whole); !s.ok()) return s;
        reflection->SetBool(message, field, whole != 0);
        return absl::OkStatus();
      case FieldDescriptor::CPPTYPE_ENUM: {
        if (auto s = WholeIn(value, std::numeric_limits<int32_t>::min(),
                             std::numeric_limits<int32_t>::max(), path, &whole);
            !s.ok()) {
          return s;
        }
        if (field->enum_type()->FindValueByNumber(static_cast<int>(whole)) == nullptr) {
          return Bad(path, absl::StrCat(whole, " is not a value of ", field->enum_type()->name()));
        }
        reflection->SetEnumValue(message, field, static_cast<int>(whole));
        return absl::OkStatus();
      }
      default:
        return Bad(path, absl::StrCat("\"", part, "\" is not a number, boolean or enum"));
    }
  }
  return Bad(path, "empty");
}

}  // namespace cablesim
