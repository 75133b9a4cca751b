// The seabed's sample scene scenes/mooring-chain-landing.json (README,
// "Moorings: the seabed"): a 40 m chain pinned at its top swings down
// through water onto a bed 20 m below and comes to rest on it, its free
// end on the bed sunk by about w / k (within 1 cm: it may still creep on
// the bed after 30 s), with the balance energy.total + energy.damped (drag,
// bed damping and friction) closed to 1 % of the damped work. The slam of
// the chain on the bed halves a few steps (14 of 3029, measured).

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

TEST(SeabedSceneTest, ChainLandsOnTheBedAndComesToRest) {
  auto proto =
      ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/mooring-chain-landing.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  testing::CollectingSink sink;
  const RunSummary s = testing::RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  std::printf("%lld steps, %lld rejected, %.3f s wall for %.1f s simulated; energy initial %.4g "
              "final %.4g damped %.4g\n",
              static_cast<long long>(s.steps), static_cast<long long>(s.rejected_steps),
              s.wall_seconds, s.end_time_s, s.energy_initial, s.energy_final, s.energy_damped);
  const double w = (7850 * 0.016 - 1025 * std::numbers::pi * 0.137 * 0.137 / 4) * 9.81;
  EXPECT_NEAR(sink.frames().back().probes[1].position_m.y(), -20 - w / 4e5, 0.01);
  EXPECT_GT(sink.frames().back().energy.contact, 0);
  EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 0.01 * s.energy_damped);
}

}  // namespace
}  // namespace cablesim
