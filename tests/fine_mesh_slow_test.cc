// Fine stiff meshes run (issue 9): the 10 m steel cable (E = 2e11 Pa,
// d = 1 cm, density 7850) pinned at one end and released horizontal, with
// 100 to 10,000 elements and every stepper at h = 1e-4 for 5 ms. Before the
// per-entry rounding floor of Newton's acceptance test, 2,000 elements or
// more did not take their first step. Every run must complete without a
// rejected step; the free tip, still falling freely at 5 ms, must match
// the stepper's discrete free fall, and near the pin, where the cable
// bends, successive meshes must agree ever more closely.

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

TEST(FineMeshTest, SteelCableRunsWithEveryMeshAndStepperAndConverges) {
  const std::vector<int> meshes = {100, 1000, 2000, 5000, 10000};
  for (const char* integrator : {"IMPLICIT_EULER", "HHT", "GENERALIZED_ALPHA"}) {
    std::vector<double> tip_y, near_y;
    for (int n : meshes) {
      CollectingSink sink;
      const RunSummary s = RunOk(SceneFromJson(absl::StrFormat(R"({
        "gravity": {"y": -9.81},
        "cables": [{"name": "steel", "length": 10, "elements": %d, "density": 7850,
                    "youngs_modulus": 2e11, "diameter": 0.01}],
        "joints": [{"type": "PIN", "a": {"cable": "steel", "s": 0}}],
        "probes": [{"name": "tip", "cable": "steel", "s": 10},
                   {"name": "near", "cable": "steel", "s": 0.05}],
        "solver": {"duration": 0.005, "step": 1e-4, "output_interval": 0.001,
                   "integrator": "%s"}})",
                                                               n, integrator)),
                                 &sink);
      ASSERT_EQ(s.status, "ok") << integrator << " " << n << ": " << s.error;
      EXPECT_EQ(s.steps, 50) << integrator << " " << n;
      EXPECT_EQ(s.rejected_steps, 0) << integrator << " " << n;
      tip_y.push_back(sink.frames().back().probes[0].position_m.y());
      near_y.push_back(sink.frames().back().probes[1].position_m.y());
      std::printf("%s %5d elements: near y %.12g m, tip y %.12g m, %lld Newton iterations, floor %.3g, %.3f s\n",
                  integrator, n, near_y.back(), tip_y.back(), static_cast<long long>(s.newton_iterations),
                  s.max_residual_floor, s.wall_seconds);
    }
    // The free end is still in free fall at 5 ms (it feels nothing of the
    // pin yet), so it must match the stepper's own discrete free fall:
    // g h^2 N (N + 1) / 2 for backward Euler, g t^2 / 2 for the
    // second-order steppers (exact for constant acceleration).
    const double n_steps = 50, h = 1e-4;
    const double fall = std::string(integrator) == "IMPLICIT_EULER"
                            ? 9.81 * h * h * n_steps * (n_steps + 1) / 2
                            : 9.81 * 0.005 * 0.005 / 2;
    for (double y : tip_y) EXPECT_NEAR(y, -fall, 1e-9 * fall) << integrator;
    // Near the pin (s = 5 cm) the cable bends: mesh convergence there.
    // Successive differences shrink until they reach rounding (1e-12 m is
    // a thousand ulps of the 10 m coordinates).
    const double d1 = std::abs(near_y[1] - near_y[0]), d2 = std::abs(near_y[2] - near_y[1]),
                 d3 = std::abs(near_y[3] - near_y[2]), d4 = std::abs(near_y[4] - near_y[3]);
    EXPECT_LT(d2, d1) << integrator;
    EXPECT_LT(d3, d2) << integrator;
    EXPECT_LT(d4, 1e-12) << integrator;
  }
}

}  // namespace
}  // namespace cablesim
