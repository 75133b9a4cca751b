// STATIC analysis against closed-form and tabulated elastica solutions.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

std::string Cantilever(int elements, double tip_force_n) {
  return absl::StrFormat(R"({
    "cables": [{"name": "rod", "length": 1.0, "elements": %d, "direction": {"x": 1},
                "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}}],
    "loads": [{"at": {"cable": "rod", "s": 1.0}, "force": {"y": %.17g}}],
    "probes": [{"name": "tip", "cable": "rod", "s": 1.0}],
    "solver": {"analysis": "STATIC", "load_steps": 20}})",
                         elements, tip_force_n);
}

TEST(StaticsTest, SmallLoadCantileverMatchesBeamTheory) {
  // P L^2 / (E I) = 1e-3: geometric nonlinearity changes the deflection by
  // O(1e-6) relative, so linear theory P L^3 / (3 E I) is the reference.
  const double ei = 2e11 * std::numbers::pi * std::pow(0.01, 4) / 64;
  const double p = 1e-3 * ei;
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(Cantilever(4, -p)), &sink);
  ASSERT_EQ(sink.frames().size(), 20u);
  const double deflection = -sink.frames().back().probes[0].position_m.y();
  const double ref = p / (3 * ei);
  EXPECT_NEAR(deflection, ref, 0.005 * ref);
  EXPECT_EQ(s.info.multipliers, 0);  // the clamp removed coordinates
}

TEST(StaticsTest, LargeDeflectionCantileverMatchesMattiassonElastica) {
  // The issue's scene: P L^2 / (E I) = 2. Mattiasson (1981), elastica
  // table: tip deflection 0.49346 L, horizontal shortening 0.16064 L.
  CollectingSink sink;
  RunOk(SceneFromJson(Cantilever(16, -196.3495)), &sink);
  const Eigen::Vector3d tip = sink.frames().back().probes[0].position_m;
  std::printf("tip deflection %.6f L, shortening %.6f L\n", -tip.y(), 1 - tip.x());
  EXPECT_NEAR(-tip.y(), 0.49346, 0.005 * 0.49346);
  EXPECT_NEAR(1 - tip.x(), 0.16064, 0.005 * 0.16064);
  EXPECT_DOUBLE_EQ(sink.frames().back().t, 1.0);
}

TEST(StaticsTest, CantileverCarryingABodyAtItsTip) {
  // A nearly weightless rod clamped at one end carries a body FIXED at its
  // tip; the body's weight m g = 1e-3 E I / L^2 gives P L^3 / (3 E I).
  // Bodies have no stiffness, so this exercises the augmented Lagrangian.
  const double ei = 2e11 * std::numbers::pi * std::pow(0.01, 4) / 64;
  const double p = 1e-3 * ei, g = 9.81;
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "rod", "length": 1.0, "elements": 4, "direction": {"x": 1},
                "density": 1e-6, "youngs_modulus": 2e11, "diameter": 0.01}],
    "bodies": [{"name": "tip", "mass": %.17g, "inertia": {"x": 1e-6, "y": 1e-6, "z": 1e-6},
                "position": {"x": 1.0}}],
    "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}},
               {"type": "FIXED", "a": {"cable": "rod", "s": 1.0}, "b": {"body": "tip"}}],
    "probes": [{"name": "tip", "body": "tip"}],
    "solver": {"analysis": "STATIC", "load_steps": 2}})",
                                           p / g);
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  // FIXED: 2 position rows and 1 direction row; the body's unit axis: 1.
  EXPECT_EQ(s.info.multipliers, 4);
  ASSERT_FALSE(sink.frames().empty());
  const double deflection = -sink.frames().back().probes[0].position_m.y();
  const double ref = p / (3 * ei);
  EXPECT_NEAR(deflection, ref, 0.005 * ref);
}

}  // namespace
}  // namespace cablesim
