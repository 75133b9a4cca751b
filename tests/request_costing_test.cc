// The server costs a request before any work (CheckScene): the numbers a
// run will keep must be counted exactly as the frames will hold them, for
// every kind of column (probes, energy per part, support forces, a
// seabed's energy.contact), so that max_trajectory_values refuses exactly
// the runs above it.

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "convert/scene_file.h"
#include "engine/output/frame_columns.h"
#include "server/request_checks.h"

namespace cablesim {
namespace {

v1::Scene SampleScene(const std::string& name) {
  std::ifstream in(std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + name);
  std::stringstream json;
  json << in.rdbuf();
  absl::StatusOr<v1::Scene> scene = ParseSceneJson(json.str());
  EXPECT_TRUE(scene.ok()) << name << ": " << scene.status();
  return scene.ok() ? *scene : v1::Scene();
}

// With the limit at exactly frames x (the columns a frame has), the scene
// passes; one number fewer and it is refused, naming the limit. A count
// that left out a column (as the seabed's was, before this test) passes
// both.
TEST(RequestCostingTest, TrajectoryLimitCountsEveryColumnOfEveryFrame) {
  for (const char* name : {"falling-pendulum.json", "crane-trolley-hoist.json",
                           "cable-with-end-cylinder.json", "mooring-chain-landing.json"}) {
    const v1::Scene scene = SampleScene(name);
    ServerLimits limits;
    absl::StatusOr<CheckedScene> checked = CheckScene(scene, limits);
    ASSERT_TRUE(checked.ok()) << name << ": " << checked.status();
    const int64_t row = static_cast<int64_t>(FrameColumns(checked->info, false).size());
    const int64_t exact = checked->frames * row;
    limits.max_trajectory_values = exact;
    EXPECT_TRUE(CheckScene(scene, limits).ok()) << name << ": " << exact << " numbers";
    limits.max_trajectory_values = exact - 1;
    const absl::Status refused = CheckScene(scene, limits).status();
    EXPECT_EQ(refused.code(), absl::StatusCode::kResourceExhausted) << name;
    EXPECT_NE(refused.message().find("max_trajectory_values"), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace cablesim
