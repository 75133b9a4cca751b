#include "client/json_line.h"

#include <charconv>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {

JsonLine& JsonLine::Add(std::string_view key, std::string_view value) {
  AddRaw(key, Quote(value));
  return *this;
}

JsonLine& JsonLine::Add(std::string_view key, const char* value) {
  return Add(key, std::string_view(value));
}

JsonLine& JsonLine::Add(std::string_view key, int64_t value) {
  AddRaw(key, absl::StrCat(value));
  return *this;
}

JsonLine& JsonLine::Add(std::string_view key, int value) {
  return Add(key, static_cast<int64_t>(value));
}

JsonLine& JsonLine::Add(std::string_view key, double value) {
  AddRaw(key, Number(value));
  return *this;
}

JsonLine& JsonLine::Add(std::string_view key, bool value) {
  AddRaw(key, value ? "true" : "false");
  return *this;
}

JsonLine& JsonLine::Add(std::string_view key, const std::vector<double>& values) {
  AddArray(key, values, [](double v) { return Number(v); });
  return *this;
}

JsonLine& JsonLine::Add(std::string_view key, const std::vector<std::string>& values) {
  AddArray(key, values, [](const std::string& v) { return Quote(v); });
  return *this;
}

void JsonLine::AddRaw(std::string_view key, std::string_view json_value) {
  if (body_.size() > 1) body_ += ',';
  body_ += Quote(key);
  body_ += ':';
  body_.append(json_value.data(), json_value.size());
}

std::string JsonLine::Quote(std::string_view value) {
  std::string out = "\"";
  out.reserve(value.size() + 2);
  for (const char c : value) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
          absl::StrAppendFormat(&out, "\\u%04x", static_cast<unsigned char>(c));
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

std::string JsonLine::Number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

}  // namespace cablesim
