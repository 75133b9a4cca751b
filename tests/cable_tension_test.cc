// Tension along a line (Scene.output.tension): NAME.tension of a probe on
// a cable and the shape's per-node tension, the element's own axial force
// EA eps |r_s| (eps Green-Lagrange), against a hanging rod's linear profile.

#include <algorithm>
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/output/frame_columns.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// A 10 m steel rod (1 cm diameter) hanging from a pin at its top, statics:
// at arc length s from the top it carries the weight below it,
// T(s) = rho A g (L - s) (exact for any stretch: the weight of the
// undeformed length below). The strain is 4e-6 at most, the profile linear,
// so the cubic elements hold it closely; the tolerance, 1e-6 of the top
// tension (6 N), is far below what a wrong sign or a tension read one
// node off (0.6 N) would give.
std::string HangingRod(const std::string& shape) {
  return absl::StrFormat(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rod", "length": 10, "elements": 10, "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.01, "direction": {"y": -1}}],
    "joints": [{"type": "PIN", "a": {"cable": "rod", "s": 0}}],
    "probes": [{"name": "top", "cable": "rod", "s": 0}, {"name": "mid", "cable": "rod", "s": 5},
               {"name": "quarter", "cable": "rod", "s": 7.5}, {"name": "end", "cable": "rod", "s": 10}],
    "output": {"tension": true, "shape": %s},
    "solver": {"analysis": "STATIC"}})",
                         shape);
}

TEST(CableTensionTest, HangingRodCarriesTheWeightBelow) {
  CollectingSink sink;
  RunOk(SceneFromJson(HangingRod("true")), &sink);
  const double w = 7850 * (M_PI / 4 * 1e-4) * 9.81;  // N/m
  ASSERT_EQ(sink.info().tension_probe_names,
            (std::vector<std::string>{"top", "mid", "quarter", "end"}));
  ASSERT_TRUE(sink.info().node_tension);
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.t, 1.0);
  const double tol = 1e-6 * w * 10;
  const double s_probe[] = {0, 5, 7.5, 10};
  ASSERT_EQ(f.probe_tensions.size(), 4u);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(f.probe_tensions[k], w * (10 - s_probe[k]), tol) << s_probe[k];
  ASSERT_EQ(f.node_tensions.size(), sink.info().node_s.size());
  for (size_t k = 0; k < f.node_tensions.size(); ++k)
    EXPECT_NEAR(f.node_tensions[k], w * (10 - sink.info().node_s[k]), tol) << sink.info().node_s[k];
  const std::vector<std::string> columns = FrameColumns(sink.info());
  EXPECT_THAT(columns, ::testing::Contains("mid.tension"));
  EXPECT_THAT(columns, ::testing::Contains("cables[0].nodes[3].tension"));
  // The last column: the last node's tension (a node is inserted at the
  // probe at s = 7.5, so 12 nodes).
  EXPECT_EQ(columns.back(), absl::StrFormat("cables[0].nodes[%d].tension",
                                            sink.info().node_s.size() - 1));
}

// The same rod standing on its pin (gravity reversed, pushed from below
// by its own weight towards the pin): compression is negative, T(s) =
// -rho A g (L - s). Statics of a compressed straight rod is the same
// linear system (the rod stays straight: no lateral load).
TEST(CableTensionTest, CompressionIsNegative) {
  std::string json = HangingRod("false");
  json.replace(json.find(R"({"y": -9.81})"), 12, R"({"y": 9.81})");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  const double w = 7850 * (M_PI / 4 * 1e-4) * 9.81;
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.probe_tensions.size(), 4u);
  EXPECT_NEAR(f.probe_tensions[1], -w * 5, 1e-6 * w * 10);
  EXPECT_FALSE(sink.info().node_tension);  // no shape: no node tensions
  EXPECT_TRUE(f.node_tensions.empty());
}

// A soft rod (E = 4e7 Pa: about 1.9 % strain at its top) under either
// axial law carries the same weight below each point, T(s) = rho A g
// (L - s), and the output must be the law's own tension: EA e under
// ENGINEERING, EA eps |r_s| under GREEN_LAGRANGE. Read with the other law's
// formula, the top tension would be off by about 1.5 times the strain
// (2.8 %), far above the tolerance, 1e-4 of the top tension (the cubic
// elements hold the nearly linear profile of the stretched rod closely).
TEST(CableTensionTest, EachAxialLawReportsItsOwnTension) {
  const double w = 7850 * (M_PI / 4 * 1e-4) * 9.81;
  for (const char* law : {"ENGINEERING", "GREEN_LAGRANGE"}) {
    std::string json = HangingRod("false");
    json.replace(json.find(R"("youngs_modulus": 2e11)"), 22,
                 absl::StrFormat(R"("youngs_modulus": 4e7, "axial_law": "%s")", law));
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    const Frame& f = sink.frames().back();
    ASSERT_EQ(f.probe_tensions.size(), 4u);
    EXPECT_NEAR(f.probe_tensions[0], w * 10, 1e-4 * w * 10) << law;
    EXPECT_NEAR(f.probe_tensions[1], w * 5, 1e-4 * w * 10) << law;
  }
}

// A straight bar (ENGINEERING law, EA = 1e8 Pa * A) with Kelvin-Voigt
// axial damping (axial_time tau = 0.05 s), pinned at s = 0 and pulled at
// s = L = 10 m from rest by x(t) = V t - V sin(w t) / w (V = 0.01 m/s,
// w = pi rad/s: the speed V (1 - cos w t) starts at 0, so no impulse
// launches a transient). The bar's axial modes are overdamped
// (tau omega_1 / 2 = 78 at a density of 1 kg/m^3), so it stretches
// uniformly and carries T = EA (x / L + tau x' / L) at every section; its
// inertia (7.9e-4 kg at accelerations below 0.04 m/s^2) adds under 3e-5 N.
// The damping's share, EA tau x' / L, is up to 0.79 N of 8 to 17 N; the
// tolerance, 1e-4 of T (under 2 mN), is far smaller, so a tension without
// the damping (the outputs before 29 November 2026) fails. The moving
// support's force, read from the multipliers, is the same tension by
// another route.
TEST(CableTensionTest, DynamicTensionCarriesTheMaterialDamping) {
  const double v = 0.01, w = M_PI;
  const std::string json = absl::StrFormat(R"({
    "cables": [{"name": "bar", "points": [{"x": 0}, {"x": 10}], "elements": 4, "density": 1,
                "youngs_modulus": 1e8, "diameter": 0.01, "axial_law": "ENGINEERING",
                "damping": {"axial_time": 0.05}}],
    "joints": [{"type": "PIN", "a": {"cable": "bar", "s": 0}},
               {"type": "PIN", "a": {"cable": "bar", "s": 10},
                "motion": {"x": {"ramp": {"slope": %.17g},
                                 "harmonic": {"amplitude": %.17g, "frequency": 0.5}}}}],
    "probes": [{"name": "root", "cable": "bar", "s": 0}, {"name": "mid", "cable": "bar", "s": 5},
               {"name": "end", "cable": "bar", "s": 10}],
    "output": {"tension": true, "shape": true},
    "solver": {"duration": 2, "step": 0.005, "output_interval": 0.25}})",
                                           v, -v / w);
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  const double ea = 1e8 * M_PI / 4 * 1e-4, tau = 0.05, length = 10;
  int checked = 0;
  double largest_damping = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t < 1) continue;
    const double x = v * f.t - v * std::sin(w * f.t) / w, speed = v * (1 - std::cos(w * f.t));
    const double damping = ea * tau * speed / length;
    const double tension = ea * x / length + damping;
    const double tol = 1e-4 * tension;
    largest_damping = std::max(largest_damping, damping / tol);
    ASSERT_EQ(f.probe_tensions.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f.probe_tensions[k], tension, tol) << f.t << " " << k;
    for (double node : f.node_tensions) EXPECT_NEAR(node, tension, tol) << f.t;
    ASSERT_EQ(f.support_forces.size(), 1u);
    EXPECT_NEAR(f.support_forces[0].x(), tension, tol) << f.t;
    ++checked;
  }
  EXPECT_EQ(checked, 5);  // t = 1, 1.25, ..., 2
  EXPECT_GT(largest_damping, 100);  // the damping's share, in tolerances
}

// Without output.tension: no tension columns.
TEST(CableTensionTest, NoneUnlessAskedFor) {
  std::string json = HangingRod("true");
  json.replace(json.find(R"("tension": true)"), 15, R"("tension": false)");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  EXPECT_TRUE(sink.info().tension_probe_names.empty());
  EXPECT_TRUE(sink.frames().back().probe_tensions.empty());
  EXPECT_TRUE(sink.frames().back().node_tensions.empty());
}

}  // namespace
}  // namespace cablesim
