// The ENERGY_MOMENTUM stepper over a long run (label slow): the falling
// pendulum of the reference paper (12 elements, E = 0.7 MPa, so it
// stretches by up to 18 %) for 100 s at h = 1e-3 without any damping keeps
// its total energy (which is 0 at the start: it falls from rest at the
// pivot's height) to 1e-6 of the largest energy term at every frame.
//
// Why 1e-6: each step conserves the energy up to what Newton leaves in the
// residual (tolerance 1e-8 relative to the largest force term), and over
// 1e5 steps these errors add up partly at random; measured 4.8e-7 (3.9e-5 J
// of 81 J). The dissipative steppers remove energy by design, and
// generalized-alpha with rho_infinity = 1 blows up near t = 6 s on this run
// (hard_cases_slow_test).
// Frames every 0.1 s are step ends (the steps return to the nominal grid
// after any halving), so their energies are the stepper's own.

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "tests/energy_momentum_scenes.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

TEST(EnergyMomentumLongRunTest, FallingPendulumKeepsItsEnergyForAHundredSeconds) {
  // Frames every 0.1 s: 1001 of them.
  const std::string json = testing::EnergyMomentumFallingPendulum(
      100, 1e-3, R"(, "linear_solver": "DIRECT")", /*output_interval_s=*/0.1);
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(s.status, "ok") << s.error;
  ASSERT_EQ(sink.frames().size(), 1001u);
  double scale = 0, drift = 0;
  for (const Frame& f : sink.frames()) {
    scale = std::max({scale, std::abs(f.energy.kinetic), std::abs(f.energy.potential),
                      f.energy.axial + f.energy.bending});
    drift = std::max(drift, std::abs(f.energy.total - sink.frames()[0].energy.total));
  }
  std::printf("falling pendulum 100 s, ENERGY_MOMENTUM h = 1e-3: %lld steps, %lld rejected, "
              "%lld Newton iterations, largest energy drift %.3g J of %.3g J (%.3g relative)\n",
              static_cast<long long>(s.steps), static_cast<long long>(s.rejected_steps),
              static_cast<long long>(s.newton_iterations), drift, scale, drift / scale);
  EXPECT_GT(scale, 50);  // it fell: the potential reached tens of joules
  EXPECT_LT(drift, 1e-6 * scale);
}

}  // namespace
}  // namespace cablesim
