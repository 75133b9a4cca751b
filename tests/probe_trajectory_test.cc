// The probe-position error between two runs (engine/output/probe_trajectory.h).

#include "engine/output/probe_trajectory.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace cablesim {
namespace {

using ::testing::HasSubstr;

// A trajectory of one probe at (x(t), 0, 0) for the given times.
ProbeTrajectory Line(const std::vector<double>& times, double speed, int probes = 1) {
  ProbeTrajectory trajectory;
  ModelInfo info;
  info.probe_names.assign(probes, "p");
  EXPECT_TRUE(trajectory.OnStart(info).ok());
  for (double t : times) {
    Frame f;
    f.t = t;
    f.probes.resize(probes);
    for (auto& p : f.probes) p.position_m = Eigen::Vector3d(speed * t, 0, 0);
    EXPECT_TRUE(trajectory.OnFrame(f).ok());
  }
  return trajectory;
}

TEST(ProbeTrajectoryTest, LargestDistanceOverCommonFrames) {
  const ProbeTrajectory reference = Line({0, 0.1, 0.2, 0.3}, 1.0);
  // The run writes every other frame: only those are compared.
  const ProbeTrajectory run = Line({0, 0.2}, 1.5);
  auto error = MaxProbePositionError(run, reference);
  ASSERT_TRUE(error.ok()) << error.status();
  EXPECT_NEAR(*error, 0.5 * 0.2, 1e-15);
}

TEST(ProbeTrajectoryTest, TimesMatchWithinTolerance) {
  const ProbeTrajectory reference = Line({0, 0.1 + 1e-12}, 1.0);
  const ProbeTrajectory run = Line({0, 0.1}, 1.0);
  auto error = MaxProbePositionError(run, reference);
  ASSERT_TRUE(error.ok()) << error.status();
  EXPECT_LT(*error, 1e-11);
}

TEST(ProbeTrajectoryTest, MissingReferenceFrameOrProbeMismatchIsAnError) {
  const ProbeTrajectory reference = Line({0, 0.1}, 1.0);
  EXPECT_THAT(MaxProbePositionError(Line({0, 0.15}, 1.0), reference).status().message(),
              HasSubstr("no frame at t = 0.15"));
  EXPECT_THAT(MaxProbePositionError(Line({0}, 1.0, 2), reference).status().message(),
              HasSubstr("probes"));
  EXPECT_FALSE(MaxProbePositionError(Line({}, 1.0), reference).ok());
}

}  // namespace
}  // namespace cablesim
