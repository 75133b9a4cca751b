// Merging JSON patches into scene documents (convert/json_merge.h), as the
// work-precision report builds its scene variants.

#include "convert/json_merge.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "convert/scene_file.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

TEST(JsonMergeTest, ObjectsMergeKeyByKeyAndScalarsReplace) {
  auto merged = MergeJson(R"({"a": 1, "solver": {"step": 0.001, "duration": 1}})",
                          R"({"solver": {"step": 0.0001, "linear_solver": "GMRES"}, "b": true})");
  ASSERT_TRUE(merged.ok()) << merged.status();
  auto scene_like = MergeJson(*merged, "{}");
  ASSERT_TRUE(scene_like.ok());
  EXPECT_THAT(*merged, HasSubstr(R"("step":0.0001)"));
  EXPECT_THAT(*merged, HasSubstr(R"("duration":1)"));
  EXPECT_THAT(*merged, HasSubstr(R"("linear_solver":"GMRES")"));
  EXPECT_THAT(*merged, HasSubstr(R"("a":1)"));
  EXPECT_THAT(*merged, HasSubstr(R"("b":true)"));
}

TEST(JsonMergeTest, ArraysMergeElementByElement) {
  auto merged = MergeJson(R"({"cables": [{"name": "a", "elements": 4}, {"name": "b"}]})",
                          R"({"cables": [{"elements": 1000}]})");
  ASSERT_TRUE(merged.ok()) << merged.status();
  // The first cable keeps its name and gets the new mesh; the second stays.
  auto scene = ParseSceneJson(*merged);
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_EQ(scene->cables_size(), 2);
  EXPECT_EQ(scene->cables(0).name(), "a");
  EXPECT_EQ(scene->cables(0).elements(), 1000);
  EXPECT_EQ(scene->cables(1).name(), "b");
}

TEST(JsonMergeTest, UnknownFieldsPassTheMergeAndAreRejectedByTheSceneParser) {
  auto merged = MergeJson(R"({"solver": {}})", R"({"solver": {"no_such_field": 1}})");
  ASSERT_TRUE(merged.ok()) << merged.status();
  auto scene = ParseSceneJson(*merged);
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("no_such_field"));
}

TEST(JsonMergeTest, NonObjectsAreInvalid) {
  EXPECT_THAT(MergeJson("[1]", "{}").status().message(), HasSubstr("the document"));
  EXPECT_THAT(MergeJson("{}", "nope").status().message(), HasSubstr("the patch"));
}

}  // namespace
}  // namespace cablesim
