#include "convert/json_merge.h"

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

using google::protobuf::Struct;
using google::protobuf::Value;

void MergeValue(const Value& patch, Value* into);

void MergeStruct(const Struct& patch, Struct* into) {
  for (const auto& [key, value] : patch.fields()) MergeValue(value, &(*into->mutable_fields())[key]);
}

void MergeValue(const Value& patch, Value* into) {
  if (patch.has_struct_value() && into->has_struct_value()) {
    MergeStruct(patch.struct_value(), into->mutable_struct_value());
  } else if (patch.has_list_value() && into->has_list_value()) {
    auto* list = into->mutable_list_value();
    const auto& items = patch.list_value().values();
    for (int k = 0; k < items.size(); ++k) {
      if (k < list->values_size()) {
        MergeValue(items[k], list->mutable_values(k));
      } else {
        *list->add_values() = items[k];
      }
    }
  } else {
    *into = patch;
  }
}

absl::StatusOr<Struct> Parse(std::string_view json, const char* what) {
  Struct out;
  const auto status = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(json.data(), json.size()), &out);
  if (!status.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " is not a JSON object: ", std::string(status.message())));
  }
  return out;
}

}  // namespace

absl::StatusOr<std::string> MergeJson(std::string_view document, std::string_view patch) {
  absl::StatusOr<Struct> doc = Parse(document, "the document");
  if (!doc.ok()) return doc.status();
  absl::StatusOr<Struct> p = Parse(patch, "the patch");
  if (!p.ok()) return p.status();
  MergeStruct(*p, &*doc);
  std::string out;
  const auto status = google::protobuf::util::MessageToJsonString(*doc, &out);
  if (!status.ok()) return absl::InternalError(std::string(status.message()));
  return out;
}

}  // namespace cablesim
