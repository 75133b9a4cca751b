// The paper's spatial pendulum (MODEL.md section 7, table 2; scenes/
// spatial-pendulum.json): pinned at the origin, straight along +x, gravity
// -y, spun at 4 rad/s about +y. Gravity and the pin exert no moment about
// the vertical axis through the pin, so the exact solution keeps L_y; the
// drift under backward Euler is its numerical dissipation and must shrink
// with the step at first order. Energy must never rise.

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;

Scene SpatialPendulum(double step) {
  auto proto = ReadSceneFile(CABLESIM_SOURCE_DIR "/scenes/spatial-pendulum.json");
  EXPECT_TRUE(proto.ok()) << proto.status();
  proto->mutable_solver()->set_step(step);
  proto->mutable_solver()->set_output_interval(0.01);
  auto scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return *scene;
}

TEST(SpatialPendulumTest, AngularMomentumAboutTheVerticalDriftsAtFirstOrderAndEnergyNeverRises) {
  double previous_drift = 0;
  for (double step : {4e-4, 2e-4, 1e-4}) {
    CollectingSink sink;
    const RunSummary s = RunOk(SpatialPendulum(step), &sink);
    ASSERT_EQ(s.info.model, "spatial");
    const double l0 = sink.frames().front().angular_momentum.y();
    // A straight rod spun about an axis through its end: I = rho A L^3 / 3.
    // Exact for the cubic elements only if the slopes got w x r_x too.
    EXPECT_NEAR(l0, 320 * 2.5e-5 / 3 * 4.0, 1e-12);
    EXPECT_NEAR(sink.frames().front().energy.kinetic, 0.5 * 320 * 2.5e-5 / 3 * 16.0, 1e-12);
    double drift = 0;
    for (size_t k = 0; k < sink.frames().size(); ++k) {
      drift = std::max(drift, std::abs(sink.frames()[k].angular_momentum.y() - l0) / l0);
      if (k > 0) {
        EXPECT_LE(sink.frames()[k].energy.total,
                  sink.frames()[k - 1].energy.total + 1e-10 * sink.frames()[0].energy.kinetic)
            << "h = " << step << ", t = " << sink.frames()[k].t;
      }
    }
    std::printf("spatial pendulum h = %g: max |L_y drift| / L_y = %.4g, energy removed %.4g J "
                "of %.4g J, %lld steps in %.3f s\n",
                step, drift, s.energy_dissipated, s.energy_initial,
                static_cast<long long>(s.steps), s.wall_seconds);
    EXPECT_LT(drift, 0.05);
    if (previous_drift > 0) {
      // First order: halving the step halves the drift (within 0.4 to 0.65).
      EXPECT_GT(drift / previous_drift, 0.4);
      EXPECT_LT(drift / previous_drift, 0.65);
    }
    previous_drift = drift;
  }
}

}  // namespace
}  // namespace cablesim
