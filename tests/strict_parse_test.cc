// Strict reading of scene files: values of the wrong kind, deep nesting,
// oversized or endless files and binary input are refused early with a
// message that names the field and quotes at most a short escaped excerpt.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr char kCable[] =
    R"({"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01})";

std::string ParseError(const std::string& json) {
  const absl::StatusOr<v1::Scene> scene = ParseSceneJson(json);
  EXPECT_FALSE(scene.ok()) << json;
  if (scene.ok()) return "";
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(scene.status().message());
}

TEST(StrictParseTest, ObjectWhereAListBelongsNamesTheField) {
  EXPECT_EQ(ParseError(absl::StrCat(R"({"cables": )", kCable, "}")),
            "invalid JSON scene: cables: must be a list [...] (got an object)");
}

TEST(StrictParseTest, ValuesOfTheWrongKindNameTheirField) {
  EXPECT_THAT(ParseError(R"({"cables": [{"name": "c", "length": [1]}]})"),
              HasSubstr("cables[0].length: must be a number (got a list)"));
  EXPECT_THAT(ParseError(R"({"cables": [{"name": "c", "points": [{"x": 0}, 3]}]})"),
              HasSubstr("cables[0].points[1]: must be an object {...} (got a number)"));
  EXPECT_THAT(ParseError(R"({"solver": {"adaptive": "yes"}})"),
              HasSubstr("solver.adaptive: must be true or false (got a string)"));
  EXPECT_THAT(ParseError(R"({"gravity": [0, -9.81, 0]})"),
              HasSubstr("gravity: must be an object {...} (got a list)"));
  EXPECT_THAT(ParseError(R"({"name": 5})"), HasSubstr("name: must be a string (got a number)"));
  EXPECT_THAT(ParseError("[]"), HasSubstr("must be a JSON object {...} (got a list)"));
}

TEST(StrictParseTest, TheRightKindsStillParseIncludingLowerCamelCaseAndNamedNumbers) {
  const absl::StatusOr<v1::Scene> scene = ParseSceneJson(
      R"({"cables": [{"name": "c", "youngsModulus": "1e7", "length": "NaN"}], "solver": null})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->cables(0).youngs_modulus(), 1e7);
}

TEST(StrictParseTest, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_THAT(ParseError(deep), HasSubstr("nested deeper than 32 levels"));
  // Brackets inside strings do not count.
  const absl::StatusOr<v1::Scene> named =
      ParseSceneJson(absl::StrCat(R"({"name": ")", std::string(100, '['), R"("})"));
  EXPECT_TRUE(named.ok()) << named.status();
}

// The nesting check and the UTF-8 error's field path share one reading of
// JSON strings (convert/scene_file.cc, JsonStringTracker): an escaped
// quote does not end a string, so brackets, commas and colons after it
// are text, not structure.
TEST(StrictParseTest, EscapedQuotesDoNotEndStrings) {
  const absl::StatusOr<v1::Scene> named = ParseSceneJson(
      absl::StrCat(R"({"name": "say \"hi\" )", std::string(40, '['), R"("})"));
  EXPECT_TRUE(named.ok()) << named.status();
  EXPECT_EQ(named->name(), absl::StrCat("say \"hi\" ", std::string(40, '[')));
  EXPECT_EQ(ParseError("{\"name\": \"a\\\"],[{,:\", \"cables\": [{\"name\": \"b\xff\"}]}"),
            "invalid JSON scene: cables[0].name: not valid UTF-8 (byte 44 is 0xff)");
  // A key's escaped characters are left out of the path.
  EXPECT_THAT(ParseError("{\"cables\": [{\"n\\\"a\xffme\": \"c\"}]}"),
              HasSubstr("cables[0].na: not valid UTF-8"));
}

TEST(StrictParseTest, TextFormatNestingIsBounded) {
  std::string deep;
  for (int i = 0; i < 1000; ++i) deep += "solver {";
  const absl::StatusOr<v1::Scene> scene = ParseSceneTextFormat(deep);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(StrictParseTest, OversizedTextIsRefusedWithTheLimit) {
  const std::string big = absl::StrCat(R"({"name": ")", std::string(kMaxSceneBytes, 'a'), R"("})");
  EXPECT_THAT(ParseError(big), HasSubstr("more than the limit of 8388608"));
}

TEST(StrictParseTest, BinaryInputIsQuotedShortAndEscaped) {
  std::string binary = "\x7f" "ELF\x02\x01";
  for (int i = 0; i < 5000; ++i) binary += static_cast<char>(i * 7919 % 256);
  const std::string message = ParseError(binary);
  EXPECT_LT(message.size(), 300u);
  for (const char c : message) {
    EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "unescaped byte " << static_cast<int>(c);
  }
}

TEST(StrictParseTest, DevZeroFailsAfterABoundedRead) {
  const absl::StatusOr<v1::Scene> scene = ReadSceneFile("/dev/zero");
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(scene.status().message()),
              StartsWith("/dev/zero: scene file is more than the limit of"));
}

TEST(StrictParseTest, AnOversizedFileIsRefusedByItsSizeBeforeReading) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "cablesim_strict_parse_big.json";
  { std::ofstream(path) << "{}"; }
  std::filesystem::resize_file(path, 1ull << 30);  // sparse: 1 GiB, never read
  const absl::StatusOr<v1::Scene> scene = ReadSceneFile(path.string());
  std::filesystem::remove(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(std::string(scene.status().message()),
              HasSubstr("scene file is 1073741824 bytes, more than the limit"));
}

TEST(StrictParseTest, LongNamesAreRefusedWithoutEchoingThem) {
  const std::string name(50 << 20, 'n');
  v1::Scene proto;
  v1::Cable* cable = proto.add_cables();
  cable->set_name(name);
  const absl::StatusOr<Scene> scene = SceneFromProto(proto);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().message(), "cables[0].name: at most 256 bytes (got 52428800)");

  v1::Scene joint = *ParseSceneJson(absl::StrCat(R"({"cables": [)", kCable, "]}"));
  joint.add_joints()->mutable_a()->set_cable(name);
  joint.mutable_joints(0)->set_type(v1::PIN);
  const absl::StatusOr<Scene> joined = SceneFromProto(joint);
  ASSERT_FALSE(joined.ok());
  EXPECT_THAT(std::string(joined.status().message()),
              StartsWith("joints[0].a.cable: at most 256 bytes"));
}

// The review: a string that is not UTF-8 was refused without naming its
// field in JSON ("Encountered non UTF-8 code points"), and in text format
// passed parsing to fail later with raw libprotobuf log lines. Now both
// name the field.
TEST(StrictParseTest, NonUtf8StringsNameTheirField) {
  EXPECT_EQ(ParseError("{\"cables\": [{\"name\": \"c\"}, {\"name\": \"be\xff" "am\"}]}"),
            "invalid JSON scene: cables[1].name: not valid UTF-8 (byte 39 is 0xff)");
  EXPECT_THAT(ParseError("{\"name\": \"\xc3\x28\"}"), HasSubstr("scene: name: not valid UTF-8"));
  // An overlong form and a surrogate are not UTF-8 either.
  EXPECT_THAT(ParseError("{\"name\": \"\xc0\xaf\"}"), HasSubstr(": name: not valid UTF-8"));
  EXPECT_THAT(ParseError("{\"name\": \"\xed\xa0\x80\"}"), HasSubstr(": name: not valid UTF-8"));
  // In a key: the path up to the byte.
  EXPECT_THAT(ParseError("{\"cables\": [{\"na\xffme\": \"c\"}]}"),
              HasSubstr("cables[0].na: not valid UTF-8 (byte 16 is 0xff)"));
  // Valid multi-byte UTF-8 passes.
  EXPECT_TRUE(ParseSceneJson("{\"name\": \"Gr\xc3\xbc\xc3\x9f" "e \xe2\x82\xac \xf0\x9f\x8c\x8a\"}").ok());
  for (const std::string text :
       {std::string("cables { name: \"ok\" }\ncables { name: \"be\xff" "am\" }\n"),
        std::string("cables { name: \"ok\" }\ncables { name: \"be\\377am\" }\n")}) {
    const absl::StatusOr<v1::Scene> scene = ParseSceneTextFormat(text);
    ASSERT_FALSE(scene.ok()) << text;
    EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(scene.status().message(),
              "invalid text-format scene: cables[1].name: not valid UTF-8 (byte 2 of the "
              "string is 0xff)");
  }
}

}  // namespace
}  // namespace cablesim
