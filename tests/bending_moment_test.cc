// Bending moment along a line (Scene.output.bending_moment): NAME.bending_moment
// at cable probes, against the statics of a cantilever in large deflection.
//
// A 1 m steel rod (1 cm diameter) clamped at s = 0, a tip force P, no
// gravity. The cable beyond s carries the force P at the tip and nothing
// else, so its moment about the point r(s) is exactly
//   M(s) = (r_tip - r(s)) x P
// for the deflected shape the run computes (read back from its probes'
// positions): a statement of equilibrium, whatever the mesh. Under the
// planar scene's load the tip drops by half the length (0.49 m), so the
// lever arm is far from the straight rod's L - s. Tolerance 1e-6 of P L: the static
// solver's residual tolerance (1e-8 of the load scale) times a lever arm of
// at most L, with margin; a moment read at the wrong end of an element, or
// not averaged between the two elements at a node, is off by up to P l (6 %
// of P L with 16 elements), a sign error by twice the moment.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/output/frame_columns.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

const std::vector<double> kS = {0, 0.25, 0.5, 0.625, 0.9, 1.0};

std::string Cantilever(const std::string& model, const std::string& force, bool moments = true) {
  std::string probes;
  for (double s : kS) probes += absl::StrFormat(R"({"name": "s%g", "cable": "rod", "s": %g},)", s, s);
  probes.pop_back();
  return absl::StrFormat(R"({"model": "%s",
    "cables": [{"name": "rod", "length": 1.0, "elements": 16, "direction": {"x": 1},
                "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}}],
    "loads": [{"at": {"cable": "rod", "s": 1.0}, "force": %s}],
    "probes": [%s],
    "output": {"bending_moment": %s},
    "solver": {"analysis": "STATIC", "load_steps": 20}})",
                         model, force, probes, moments ? "true" : "false");
}

// The moment of P about each probe from the run's own deflected shape.
std::vector<Eigen::Vector3d> Expected(const Frame& f, const Eigen::Vector3d& p) {
  std::vector<Eigen::Vector3d> m;
  const Eigen::Vector3d tip = f.probes.back().position_m;
  for (const ProbeSample& probe : f.probes) m.push_back((tip - probe.position_m).cross(p));
  return m;
}

TEST(BendingMomentTest, PlanarCantileverCarriesTheTipForcesMoment) {
  const double py = -196.3495;
  CollectingSink sink;
  RunOk(SceneFromJson(Cantilever("PLANAR", R"({"y": -196.3495})")), &sink);
  ASSERT_EQ(sink.info().bending_moment_probe_names.size(), kS.size());
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.probe_bending_moments.size(), kS.size());
  const std::vector<Eigen::Vector3d> m = Expected(f, Eigen::Vector3d(0, py, 0));
  const double tol = 1e-6 * std::abs(py) * 1.0;
  std::printf("tip at (%.6f, %.6f) m\n", f.probes.back().position_m.x(),
              f.probes.back().position_m.y());
  for (size_t k = 0; k < kS.size(); ++k) {
    std::printf("s %.3f m: moment %.9g N m, equilibrium %.9g N m\n", kS[k],
                f.probe_bending_moments[k], m[k].z());
    EXPECT_NEAR(f.probe_bending_moments[k], m[k].z(), tol) << "s = " << kS[k];
  }
  // The deflection is large: the lever arm at the clamp is well short of L.
  EXPECT_LT(std::abs(m[0].z()), 0.9 * std::abs(py));
  EXPECT_THAT(FrameColumns(sink.info()), ::testing::Contains("s0.5.bending_moment"));
}

TEST(BendingMomentTest, SpatialCantileverCarriesTheTipForcesMoment) {
  // The tip force out of every coordinate plane: the rod bends and twists
  // nothing (no torsion in the model), the moment has two components.
  const Eigen::Vector3d p(0, -120, 150);
  CollectingSink sink;
  RunOk(SceneFromJson(Cantilever("SPATIAL", R"({"y": -120, "z": 150})")), &sink);
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.probe_bending_moments.size(), kS.size());
  const std::vector<Eigen::Vector3d> m = Expected(f, p);
  const double tol = 1e-6 * p.norm() * 1.0;
  for (size_t k = 0; k < kS.size(); ++k) {
    EXPECT_NEAR(f.probe_bending_moments[k], m[k].norm(), tol) << "s = " << kS[k];
  }
}

// Without output.bending_moment: no columns, nothing computed.
TEST(BendingMomentTest, NoneUnlessAskedFor) {
  CollectingSink sink;
  RunOk(SceneFromJson(Cantilever("PLANAR", R"({"y": -10})", false)), &sink);
  EXPECT_TRUE(sink.info().bending_moment_probe_names.empty());
  EXPECT_TRUE(sink.frames().back().probe_bending_moments.empty());
  for (const std::string& c : FrameColumns(sink.info())) {
    EXPECT_THAT(c, ::testing::Not(::testing::HasSubstr("bending_moment")));
  }
}

}  // namespace
}  // namespace cablesim
