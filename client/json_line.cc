#include "client/json_line.h"

#include <charconv>
#include <cmath>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"

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

// Strings are written by nlohmann::json (Debian's nlohmann-json3-dev): its
// escaping of control characters and its replacement of invalid UTF-8 by
// U+FFFD, so that a line is always valid JSON. Numbers by std::to_chars,
// the shortest form that reads back to the same double (nlohmann's form
// differs only in spelling, 1.0 for 1 and 0.0001 for 1e-04, and the
// summaries' spelling is kept for the scripts that read them as text).
std::string JsonLine::Quote(std::string_view value) {
  return nlohmann::json(value).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string JsonLine::Number(double value) {
  if (!std::isfinite(value)) return "null";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

}  // namespace cablesim
