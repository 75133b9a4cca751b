// Sliding joints (Joint type SLIDE, SlidingJoint): a bead on a stiff
// inclined cable against g (sin a - mu cos a), no jolt where the bead
// crosses a node, the scene validation; planar and spatial.

#include <cmath>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/forces/sliding_joint.h"
#include "test_util.h"

namespace cablesim {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = std::numbers::pi;

using testing::CollectingSink;
using testing::ProbeIndex;
using testing::RunOk;
using testing::SceneFromJson;
using ::testing::HasSubstr;

// A straight steel bar (E = 2e11 Pa, d = 0.05 m: EI = 6.1e4 N m^2) of
// length 2 m clamped at both ends, inclined at `angle` below +x, nearly
// massless (1 kg/m^3), and a 1 kg bead slid on it from s = 0.2 m.
std::string Incline(double angle, double friction, const std::string& model) {
  return absl::StrCat(R"({"gravity": {"y": -9.81}, "model": ")", model, R"(",
    "cables": [{"name": "bar", "length": 2, "elements": 20,
                "direction": {"x": )", std::cos(angle), R"(, "y": )", -std::sin(angle), R"(},
                "density": 1, "youngs_modulus": 2e11, "diameter": 0.05}],
    "bodies": [{"name": "bead", "mass": 1, "inertia": {"x": 1e-3, "y": 1e-3, "z": 1e-3},
                "position": {"x": )", 0.2 * std::cos(angle), R"(, "y": )", -0.2 * std::sin(angle),
                      R"(}}],
    "joints": [{"type": "FIXED", "a": {"cable": "bar", "s": 0}},
               {"type": "FIXED", "a": {"cable": "bar", "s": 2}},
               {"type": "SLIDE", "a": {"body": "bead"}, "b": {"cable": "bar", "s": 0.2},
                "slide": {"friction": )", friction, R"(}}],
    "probes": [{"name": "bead", "body": "bead"}],
    "solver": {"duration": 0.6, "step": 0.001, "output_interval": 0.3}})");
}

struct InclineCase {
  double friction;
  const char* model;
};

class InclineTest : public ::testing::TestWithParam<InclineCase> {};

// The bead's acceleration along the bar, from its velocity at 0.3 s and
// 0.6 s (after the friction's stick regularization, v < v_s = 1e-3 m/s in
// the first 1e-3 s, has passed), against g (sin a - mu cos a). Errors
// expected: the bar bends under the bead by P L^3 / (192 EI) ~ 6e-6 m,
// which tilts it by ~1e-5 rad (1e-5 relative on the acceleration); the
// penalty gap m g cos a / k ~ 2e-9 m; HHT is exact for a constant
// acceleration. Tolerance 1e-4 relative: ten times the bar's tilt. The bead
// crosses 5 element boundaries on the way (0.2 m to 1.5 m at mu = 0).
TEST_P(InclineTest, AcceleratesAtGSinAMinusMuCosA) {
  const double angle = kPi / 6;
  const InclineCase c = GetParam();
  CollectingSink sink;
  RunOk(SceneFromJson(Incline(angle, c.friction, c.model)), &sink);
  ASSERT_EQ(sink.frames().size(), 3u);
  const int p = ProbeIndex(sink.info(), "bead");
  ASSERT_GE(p, 0);
  const Eigen::Vector3d dir(std::cos(angle), -std::sin(angle), 0);
  const double v1 = sink.frames()[1].probes[p].velocity_m_s.dot(dir);
  const double v2 = sink.frames()[2].probes[p].velocity_m_s.dot(dir);
  const double measured = (v2 - v1) / 0.3;
  const double expected = kG * (std::sin(angle) - c.friction * std::cos(angle));
  EXPECT_NEAR(measured, expected, 1e-4 * expected) << c.model << " mu " << c.friction;
  // The bead stays on the bar: its distance from the line well below 1e-5 m.
  const Eigen::Vector3d x = sink.frames()[2].probes[p].position_m;
  EXPECT_LT((x - x.dot(dir) * dir).norm(), 1e-5);
}

INSTANTIATE_TEST_SUITE_P(PlanarAndSpatial, InclineTest,
                         ::testing::Values(InclineCase{0, "PLANAR"}, InclineCase{0.2, "PLANAR"},
                                           InclineCase{0, "SPATIAL"},
                                           InclineCase{0.2, "SPATIAL"}));

// No jolt where the bead crosses a node: the frictionless bead's
// acceleration along the bar, every step from 0.05 s (the start's normal
// transient damped) to 0.6 s, while it crosses the nodes at 0.3, ..., 1.4 m,
// stays within 1e-4 relative of g sin a (the bar's tilt under the bead,
// see above); a force that jumped at a node would show there.
TEST(SlidingJointTest, NoJoltAtNodes) {
  const double angle = kPi / 6;
  std::string json = Incline(angle, 0, "PLANAR");
  json.replace(json.find(R"("output_interval": 0.3)"), 22, R"("output_interval": 0.001)");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  const int p = ProbeIndex(sink.info(), "bead");
  ASSERT_GE(p, 0);
  const Eigen::Vector3d dir(std::cos(angle), -std::sin(angle), 0);
  const double expected = kG * std::sin(angle);
  double worst = 0;
  int frames = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t < 0.05) continue;
    ++frames;
    worst = std::max(worst, std::abs(f.probes[p].acceleration_m_s2.dot(dir) - expected));
  }
  EXPECT_GT(frames, 500);
  EXPECT_LT(worst, 1e-4 * expected);
  // It did cross nodes: from s = 0.2 m to past 1 m.
  EXPECT_GT(sink.frames().back().probes[p].position_m.dot(dir), 1.0);
}

absl::Status Convert(const std::string& json) {
  auto proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  return SceneFromProto(*proto).status();
}

TEST(SlidingJointTest, ValidationNamesTheField) {
  const std::string base = Incline(kPi / 6, 0, "PLANAR");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string json = base;
    json.replace(json.find(from), from.size(), to);
    return Convert(json);
  };
  EXPECT_THAT(with(R"("friction": 0})", R"("friction": -0.1})").message(),
              HasSubstr("joints[2].slide.friction: must be >= 0"));
  EXPECT_THAT(with(R"("friction": 0})", R"("stiffness": -1})").message(),
              HasSubstr("joints[2].slide.stiffness: must be >= 0"));
  EXPECT_THAT(with(R"("friction": 0})", R"("stick_velocity": -1})").message(),
              HasSubstr("joints[2].slide.stick_velocity: must be > 0"));
  EXPECT_THAT(with(R"("b": {"cable": "bar", "s": 0.2})", R"("b": {"body": "bead"})").message(),
              HasSubstr("joints[2].b"));
  EXPECT_THAT(with(R"({"type": "FIXED", "a": {"cable": "bar", "s": 2}})",
                   R"({"type": "FIXED", "a": {"cable": "bar", "s": 2}, "slide": {"friction": 1}})")
                  .message(),
              HasSubstr("joints[1].slide: only with type SLIDE"));
  // The body point must start on the cable (the engine checks it).
  std::string off = Incline(kPi / 6, 0, "SPATIAL");
  const std::string pos = R"("position": {"x": )";
  off.replace(off.find(pos), pos.size(), R"("position": {"z": 0.01, "x": )");
  CollectingSink sink;
  auto summary = RunScene(SceneFromJson(off), &sink);
  ASSERT_FALSE(summary.ok());
  EXPECT_THAT(summary.status().message(), HasSubstr("joints[2]: the body point is"));
}

// The sample zip line runs; its trolley descends along the line past the
// middle, and friction's work (energy.damped) is what the run lost beyond
// HHT's own numerical dissipation: total + damped never exceeds the
// initial energy (1e-9 relative: rounding).
TEST(SlidingJointTest, ZipLineSceneRuns) {
  auto proto = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/zip-line.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  const int p = ProbeIndex(sink.info(), "trolley");
  ASSERT_GE(p, 0);
  EXPECT_GT(sink.frames().back().probes[p].position_m.x(), 20);
  const double initial = sink.frames().front().energy.total;
  for (const Frame& f : sink.frames())
    EXPECT_LE(f.energy.total + f.energy.damped, initial + 1e-9 * std::abs(initial)) << f.t;
  EXPECT_GT(sink.frames().back().energy.damped, 0);
}

// The penalty's force is minus the gradient of its energy and its
// stiffness the derivative of minus the force (the Schur complement of the
// minimization over s), by central differences (step 1e-6: truncation
// ~1e-12 relative, rounding ~1e-10 relative of k |d|; tolerance 1e-6
// relative to the largest entry). Two curved planar elements (nodes at
// x = 0, 1, 2 with bent slopes), a body point 1e-3 m off the cable near
// s = 0.9 (inside the first element; its nearest point is found from a
// start at s = 1.6, in the second).
TEST(SlidingJointTest, ForceAndStiffnessAreDerivativesOfTheEnergy) {
  // Full q: 3 nodes x [r(2), r_x(2)], then the body [r_c(2), u(2)].
  Eigen::VectorXd q(16);
  q << 0, 0, 1, 0.2, 1, 0.1, 1, -0.1, 2, -0.1, 0.9, 0.3,
       0.9, 0.101, 1, 0;
  std::vector<SlidingJoint::Segment> segments = {{0, 0, 1}, {4, 1, 1}};
  const SlidingJoint slider(2, segments, 12, 4, Eigen::Vector3d(0.01, 0.002, 0), 1e4, 0, 1e-3,
                            1.6);
  SlidingJoint::Local local;
  slider.Penalty(q, &local, true);
  EXPECT_LT(slider.s(), 1.0);
  EXPECT_GT(slider.s(), 0.5);
  const int n = local.n;
  ASSERT_EQ(n, 12);
  const double h = 1e-6;
  const double fmax = local.force.cwiseAbs().maxCoeff();
  const double kmax = local.matrix.cwiseAbs().maxCoeff();
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd qp = q, qm = q;
    qp(local.coord[i]) += h;
    qm(local.coord[i]) -= h;
    const double dv = (slider.Penalty(qp, nullptr, false) - slider.Penalty(qm, nullptr, false)) /
                      (2 * h);
    EXPECT_NEAR(local.force(i), -dv, 1e-6 * fmax) << i;
    SlidingJoint::Local lp, lm;
    slider.Penalty(qp, &lp, false);
    slider.Penalty(qm, &lm, false);
    ASSERT_EQ(lp.coord[0], local.coord[0]);  // still on the same element
    for (int k = 0; k < n; ++k)
      EXPECT_NEAR(local.matrix(k, i), -(lp.force(k) - lm.force(k)) / (2 * h), 1e-6 * kmax)
          << k << " " << i;
  }
}

}  // namespace
}  // namespace cablesim
