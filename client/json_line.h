#ifndef CABLESIM_CLIENT_JSON_LINE_H_
#define CABLESIM_CLIENT_JSON_LINE_H_

// Builds one JSON object on one line, key by key, in insertion order. Used
// for the machine-readable output of the command line.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace cablesim {

class JsonLine {
 public:
  JsonLine() = default;

  // Adds `"key":value`. Keys are not checked for duplicates.
  JsonLine& Add(std::string_view key, std::string_view value);
  JsonLine& Add(std::string_view key, const char* value);
  JsonLine& Add(std::string_view key, int64_t value);
  JsonLine& Add(std::string_view key, int value);
  // Written in the shortest form that reads back to the same double; a
  // non-finite value is written as null.
  JsonLine& Add(std::string_view key, double value);
  JsonLine& Add(std::string_view key, bool value);
  // A JSON array of numbers, each written as by Add(key, double).
  JsonLine& Add(std::string_view key, const std::vector<double>& values);
  JsonLine& Add(std::string_view key, const std::vector<std::string>& values);

  // Adds `"key":json` with `json` already JSON (an object or array built
  // with JsonLine), written as is.
  JsonLine& AddJson(std::string_view key, std::string_view json) {
    AddRaw(key, json);
    return *this;
  }

  // The object, e.g. `{"status":"ok","steps":10}`, without a newline.
  std::string ToString() const { return body_ + "}"; }

  // `value` as a JSON string literal, quotes included. Control characters
  // are escaped; invalid UTF-8 becomes U+FFFD.
  static std::string Quote(std::string_view value);
  // `value` as a JSON number, or `null` when it is not finite.
  static std::string Number(double value);

 private:
  void AddRaw(std::string_view key, std::string_view json_value);
  // `key`: [format(v0),format(v1),...].
  template <typename T, typename Format>
  void AddArray(std::string_view key, const std::vector<T>& values, Format format) {
    std::string array = "[";
    for (size_t i = 0; i < values.size(); ++i) {
      if (i > 0) array += ",";
      array += format(values[i]);
    }
    array += "]";
    AddRaw(key, array);
  }

  std::string body_ = "{";
};

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_JSON_LINE_H_
