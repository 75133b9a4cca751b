// The server costs a request before any work (CheckScene): the numbers a
// run will keep must be counted exactly as the frames will hold them, for
// every kind of column (probes, energy per part, support forces, a
// seabed's energy.contact), so that max_trajectory_values refuses exactly
// the runs above it.

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "convert/scene_file.h"
#include "engine/output/frame_columns.h"
#include "engine/model/multibody_model.h"
#include "engine/output/results.h"
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

// A Run request costs its scene on the built model and runs that same
// model: one build, not one to cost and one to run (a scene of many
// elements takes seconds to build). A second run of the same checked scene
// must build again (a model runs once).
TEST(RequestCostingTest, ARunBuildsItsModelOnce) {
  class Discard : public FrameSink {
   public:
    absl::Status OnFrame(const Frame&) override { return absl::OkStatus(); }
  } sink;
  const int64_t before = MultibodyModel::BuildsStarted();
  absl::StatusOr<CheckedScene> checked = CheckScene(SampleScene("falling-pendulum.json"), {});
  ASSERT_TRUE(checked.ok()) << checked.status();
  absl::StatusOr<RunSummary> ran = RunSceneWithinMemory(&*checked, &sink, {});
  ASSERT_TRUE(ran.ok()) << ran.status();
  EXPECT_EQ(ran->status, "ok");
  EXPECT_EQ(MultibodyModel::BuildsStarted() - before, 1);
  // The same answer as a run that builds its own model.
  absl::StatusOr<RunSummary> again = RunSceneWithinMemory(checked->scene, &sink, {});
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(MultibodyModel::BuildsStarted() - before, 2);
  EXPECT_EQ(again->energy_final, ran->energy_final);
  EXPECT_EQ(again->steps, ran->steps);
  absl::StatusOr<RunSummary> rerun = RunSceneWithinMemory(&*checked, &sink, {});
  ASSERT_TRUE(rerun.ok()) << rerun.status();
  EXPECT_EQ(MultibodyModel::BuildsStarted() - before, 3);
  EXPECT_EQ(rerun->energy_final, ran->energy_final);
}

// The thread a run computes on: kComputeNice levels below the caller in
// the daemon (so that calls and health checks answer under load), at the
// caller's own level when asked for 0 (`cablesim run` in-process, which a
// busy machine slowed tenfold when it yielded to everything else).
TEST(RequestCostingTest, ComputeThreadNiceIsTheCallersPlusComputeNice) {
  class NiceOfFirstFrame : public FrameSink {
   public:
    absl::Status OnFrame(const Frame&) override {
      if (!seen) {
        seen = true;
        errno = 0;
        nice = ::getpriority(PRIO_PROCESS, static_cast<int>(::syscall(SYS_gettid)));
      }
      return absl::OkStatus();
    }
    bool seen = false;
    int nice = 100;
  };
  errno = 0;
  const int caller = ::getpriority(PRIO_PROCESS, static_cast<int>(::syscall(SYS_gettid)));
  ASSERT_EQ(errno, 0);
  if (caller + kComputeNice > 19) GTEST_SKIP() << "the test runs at nice " << caller;
  const Scene scene = [] {
    absl::StatusOr<CheckedScene> checked = CheckScene(SampleScene("falling-pendulum.json"), {});
    EXPECT_TRUE(checked.ok()) << checked.status();
    return checked.ok() ? checked->scene : Scene{};
  }();
  NiceOfFirstFrame daemon, in_process;
  ASSERT_TRUE(RunSceneWithinMemory(scene, &daemon, {}).ok());
  ASSERT_TRUE(RunSceneWithinMemory(scene, &in_process, {}, 0).ok());
  EXPECT_EQ(daemon.nice, caller + kComputeNice);
  EXPECT_EQ(in_process.nice, caller);
  EXPECT_EQ(ServerLimits{}.compute_nice, kComputeNice);
}

}  // namespace
}  // namespace cablesim
