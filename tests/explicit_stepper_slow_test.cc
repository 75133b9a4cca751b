// The explicit steppers on the hard case of a long run: the 30 s falling
// pendulum, whose whips nearly fold elements (the stiffest mode then spikes
// far above its 1076 rad/s at rest). At a fixed step both stop on the
// energy guard within 8 s (explicit_stepper_test: a step beyond the limit
// is reported); adaptive steps must get through without the energy rising.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "tests/energy_momentum_scenes.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

TEST(ExplicitStepperSlowTest, AdaptiveStepsCarryTheLongFallingPendulumWithoutEnergyRise) {
  // Tolerance 1e-5 m. Pass: the run completes and the total energy never
  // rises by more than 1e-3 of its largest term (the guard stops a run at
  // 5 %; a stable explicit run of a conservative scene only loses energy,
  // through the variable step).
  for (const char* integrator : {"CENTRAL_DIFFERENCE", "DORMAND_PRINCE"}) {
    SCOPED_TRACE(integrator);
    CollectingSink sink;
    const RunSummary s = RunOk(
        SceneFromJson(testing::FallingPendulumWithSolver(
            30, 0.1,
            absl::StrFormat(R"("integrator": "%s", "adaptive": true, "tolerance": 1e-5)",
                            integrator))),
        &sink);
    double scale = 0;
    for (const Frame& f : sink.frames())
      scale = std::max({scale, std::abs(f.energy.kinetic), std::abs(f.energy.potential)});
    std::printf("%s adaptive 1e-5, 30 s falling pendulum: %lld steps (%lld rejected), steps "
                "%.3g to %.3g s, wall %.3g s, largest energy rise %.3g J, energy lost %.3g J of "
                "%.3g J\n",
                integrator, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.min_step_s, s.max_step_s,
                s.wall_seconds, s.energy_max_increase, s.energy_dissipated, scale);
    EXPECT_DOUBLE_EQ(s.end_time_s, 30);
    EXPECT_LT(s.energy_max_increase, 1e-3 * scale);
  }
}

}  // namespace
}  // namespace cablesim
