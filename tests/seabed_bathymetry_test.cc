// The bathymetry grid of the seabed (engine/forces/bathymetry_grid.h,
// engine/forces/seabed.h):
//  - the grid bed's force is the gradient of its energy and its tangent
//    the gradient of the force (central differences), on elements crossing
//    grid lines in both directions and the bed, planar and spatial;
//  - a chain on a uniformly sloped grid rests exactly where it rests on
//    the tilted plane of stiffness k / cos^2(theta) (the grid's stiffness
//    acts on the vertical penetration, the plane's on the normal one);
//  - a chain pinned over a zigzag bed rests at the bilinear heights;
//  - bad grids are refused with the field named.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/forces/seabed.h"
#include "engine/model/multibody_model.h"
#include "engine/analysis/static_solver.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::SceneFromJson;

constexpr double kArea = 0.01, kDensity = 7850, kG = 9.81, kEa = 5e7;
constexpr double kW = kDensity * kArea * kG;  // 770 N/m

// Central differences of the energy against the gradient and of the
// gradient against the tangent. Errors: (d^2/6) U''' plus rounding
// eps U / d; 1e-6 of the largest entry leaves a margin of 100 over both.
template <int D>
void CheckDerivatives(const Seabed& bed, const Eigen::Matrix<double, 4 * D, 1>& e, double l) {
  constexpr int kN = 4 * D;
  using Vec = Eigen::Matrix<double, kN, 1>;
  Vec g = Vec::Zero();
  Eigen::Matrix<double, kN, kN> hm = Eigen::Matrix<double, kN, kN>::Zero();
  const double u = bed.AddPotential<D>(e, l, &g, &hm);
  ASSERT_GT(u, 0);
  const double d = 1e-6;
  for (int i = 0; i < kN; ++i) {
    Vec ep = e, em = e;
    ep(i) += d;
    em(i) -= d;
    EXPECT_NEAR((bed.Energy<D>(ep, l) - bed.Energy<D>(em, l)) / (2 * d), g(i),
                1e-6 * g.cwiseAbs().maxCoeff())
        << i;
    Vec gp = Vec::Zero(), gm = Vec::Zero();
    bed.AddPotential<D>(ep, l, &gp, nullptr);
    bed.AddPotential<D>(em, l, &gm, nullptr);
    for (int j = 0; j < kN; ++j)
      EXPECT_NEAR((gp(j) - gm(j)) / (2 * d), hm(j, i), 1e-6 * hm.cwiseAbs().maxCoeff())
          << i << "," << j;
  }
}

// A 3 x 3 grid whose cells are truly bilinear (d_uv != 0).
SeabedSpec GridBed(const Eigen::Vector3d& up) {
  SeabedSpec spec;
  spec.enabled = true;
  spec.normal = up;
  spec.stiffness_n_m2 = 1e5;
  spec.bathymetry.enabled = true;
  spec.bathymetry.origin_x_m = 0;
  spec.bathymetry.origin_y_m = -0.5;
  spec.bathymetry.dx_m = 0.8;
  spec.bathymetry.dy_m = 0.6;
  spec.bathymetry.nx = 3;
  spec.bathymetry.ny = 3;
  spec.bathymetry.depths_m = {0.1, 0.3, 0.0, 0.25, -0.1, 0.2, 0.05, 0.15, 0.4};
  return spec;
}

TEST(SeabedBathymetryTest, SpatialForceAndTangentAreDerivativesOfTheEnergy) {
  const Seabed bed(GridBed(Eigen::Vector3d::UnitZ()));
  ASSERT_NE(bed.grid(), nullptr);
  Eigen::Matrix<double, 12, 1> e;
  // Across the grid in x and y (several grid lines), dipping into the bed;
  // no node on a grid line (the tangent jumps where a crossing passes an
  // element's end).
  e << 0.1, -0.4, 0.05, 1, 0.5, -0.6, 1.9, 0.65, -0.02, 1, 0.3, 0.4;
  CheckDerivatives<3>(bed, e, 2.2);
  // Wholly in the bed.
  e << 0.1, -0.4, -0.5, 1, 0.5, -0.1, 1.9, 0.65, -0.6, 1, 0.3, 0.2;
  CheckDerivatives<3>(bed, e, 2.2);
}

TEST(SeabedBathymetryTest, PlanarForceAndTangentAreDerivativesOfTheEnergy) {
  // Up = y: the planar cable sees the grid's row at z = 0 (interpolated
  // between the rows at -0.5 and 0.1).
  const Seabed bed(GridBed(Eigen::Vector3d::UnitY()));
  Eigen::Matrix<double, 8, 1> e;
  e << -0.3, 0.05, 1, -0.5, 1.9, -0.02, 1, 0.4;
  CheckDerivatives<2>(bed, e, 2.3);
}

// The damping's position tangent on a grid bed (Seabed::AddDissipation's
// `position`: the moving ends where g changes sign) against central
// differences of the damping force in e at a fixed rate, on a uniformly
// sloped 3 x 3 grid (d = 0.2 + 0.15 u - 0.1 v: the normal is the same
// everywhere, so the ends' term is the whole derivative), with an element
// that dips into the bed across grid lines u = 0.8 and v = 0.1 and stays
// inside the grid (beyond it the depth continues flat, and the normal would
// jump at the last line) (the pieces split at the lines must add no term:
// a wrong one errs by the tangent's scale). Bound 1e-6
// of the largest entry, as in seabed_test's plane-bed check (smooth in e
// at this state; truncation and rounding of the difference below 1e-9).
TEST(SeabedBathymetryTest, DampingPositionTangentIsTheDerivativeOfTheDampingForce) {
  SeabedSpec spec = GridBed(Eigen::Vector3d::UnitZ());
  spec.damping_n_s_m2 = 2e4;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const double u = 0.8 * i, v = -0.5 + 0.6 * j;
      spec.bathymetry.depths_m[j * 3 + i] = 0.2 + 0.15 * u - 0.1 * v;
    }
  const Seabed bed(spec);
  using Coords = Eigen::Matrix<double, 12, 1>;
  using Matrix = Eigen::Matrix<double, 12, 12>;
  Coords e, edot;
  e << 0.1, -0.4, -0.2, 0.8, 0.5, -0.8, 1.5, 0.65, -0.3, 0.8, 0.3, 0.6;
  edot << 0.3, 0.5, -0.1, 0.05, -0.2, 0.1, -0.2, 0.8, 0.3, 0.1, 0.4, -0.3;
  constexpr double kL = 2.0;
  Coords f = Coords::Zero();
  Matrix c = Matrix::Zero(), k = Matrix::Zero();
  bed.AddDissipation<3>(e, edot, kL, &f, &c, &k);
  const double scale = k.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  const double d = 1e-6;
  for (int i = 0; i < 12; ++i) {
    Coords ep = e, em = e, fp = Coords::Zero(), fm = Coords::Zero();
    ep(i) += d;
    em(i) -= d;
    bed.AddDissipation<3>(ep, edot, kL, &fp, nullptr);
    bed.AddDissipation<3>(em, edot, kL, &fm, nullptr);
    for (int j = 0; j < 12; ++j)
      EXPECT_NEAR(-(fp(j) - fm(j)) / (2 * d), k(j, i), 1e-6 * scale) << i << "," << j;
  }
}

TEST(SeabedBathymetryTest, HeightIsBilinearAndContinuesAtTheEdges) {
  const Seabed bed(GridBed(Eigen::Vector3d::UnitZ()));
  // Node (1, 1): depth -0.1 at (0.8, 0.1).
  EXPECT_DOUBLE_EQ(bed.Height(Eigen::Vector3d(0.8, 0.1, 0)), -0.1);
  // Cell (0, 0) centre: the mean of its four nodes.
  EXPECT_NEAR(bed.Height(Eigen::Vector3d(0.4, -0.2, 1)), 1 + (0.1 + 0.3 + 0.25 - 0.1) / 4,
              1e-15);
  // Beyond the last column and below the first row: the corner node.
  EXPECT_NEAR(bed.Height(Eigen::Vector3d(5, -3, 0)), 0.0, 1e-15);
}

// A 20 m chain pinned at its upper end at x = 0, lying down a slope s
// along +x, frictionless, in statics.
constexpr double kSlope = 0.2, kChain = 20, kTop = 5;

std::string SlopeScene(const std::string& seabed, int elements) {
  const double c = 1 / std::sqrt(1 + kSlope * kSlope);
  // Along the bed y = -kTop - s x (grid) from x = 0.
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": %.17g, "elements": %d, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "second_moment": 1e-14,
                "bending": "NONE",
                "points": [{"x": 0, "y": %.17g}, {"x": %.17g, "y": %.17g}]}],
    "joints": [{"type": "PIN", "a": {"cable": "chain", "s": 0}}],
    %s,
    "solver": {"analysis": "STATIC", "newton_tolerance": 1e-10}})",
                         kChain, elements, kDensity, kEa / kArea, kArea, -kTop, kChain * c,
                         -kTop - kSlope * kChain * c, seabed);
}

Eigen::VectorXd SolveStatics(const Scene& scene, MultibodyModel* model) {
  StaticSolver solver(model, scene.solver);
  for (int k = 1; k <= 10; ++k) {
    const auto stats = solver.Solve(k / 10.0);
    EXPECT_TRUE(stats.converged) << k << ": " << stats.reason;
    if (!stats.converged) return {};
  }
  Eigen::VectorXd q(model->coordinates());
  model->ToFull(solver.z(), &q);
  return q;
}

// The grid: depths kTop + s x at x = -10 and 40 (one cell, ny = 1). The
// tilted plane: n = (s, 1) / sqrt(1 + s^2), depth kTop / sqrt(1 + s^2),
// stiffness k (1 + s^2). Both integrals are exact (4- and 7-point Gauss of
// polynomials), so the two statics differ only by rounding and Newton's
// tolerance: 1e-9 m (measured below 1e-12 m); the chain sinks by
// w cos^2 / k = 7.4e-6 m, so 1e-9 m is a test of the stiffness scaling.
TEST(SeabedBathymetryTest, UniformSlopeEqualsTheTiltedPlane) {
  const double k = 1e8;
  const std::string grid = absl::StrFormat(
      R"("seabed": {"stiffness": %.17g, "bathymetry": {"origin_x": -10, "dx": 50, "nx": 2,
         "ny": 1, "depths": [%.17g, %.17g]}})",
      k, kTop - 10 * kSlope, kTop + 40 * kSlope);
  const double root = std::sqrt(1 + kSlope * kSlope);
  const std::string plane = absl::StrFormat(
      R"("seabed": {"stiffness": %.17g, "depth": %.17g, "normal": {"x": %.17g, "y": 1}})",
      k * (1 + kSlope * kSlope), kTop / root, kSlope);
  const Scene sg = SceneFromJson(SlopeScene(grid, 20));
  const Scene sp = SceneFromJson(SlopeScene(plane, 20));
  auto mg = MultibodyModel::Build(sg);
  auto mp = MultibodyModel::Build(sp);
  ASSERT_TRUE(mg.ok() && mp.ok());
  ASSERT_NE(mg->seabed()->grid(), nullptr);
  ASSERT_EQ(mp->seabed()->grid(), nullptr);
  const Eigen::VectorXd qg = SolveStatics(sg, &*mg), qp = SolveStatics(sp, &*mp);
  ASSERT_EQ(qg.size(), qp.size());
  ASSERT_GT(qg.size(), 0);
  double worst = 0;
  for (int i = 0; i <= 40; ++i) {
    const double s = kChain * i / 40;
    const Eigen::Vector3d a = mg->CablePosition(qg, 0, s), b = mp->CablePosition(qp, 0, s);
    worst = std::max(worst, (a - b).norm());
  }
  const double sink = -mg->seabed()->Height(mg->CablePosition(qg, 0, kChain / 2));
  std::printf("grid vs tilted plane: largest distance %.3e m, vertical sink %.3e m\n", worst,
              sink);
  EXPECT_LT(worst, 1e-9);
  // And the chain is on the bed: mid-way it sinks by w cos^2(theta) / k
  // vertically (to 1e-3: Newton's tolerance and the stretch, 1e-6, leave
  // far less).
  const double cos2 = 1 / (1 + kSlope * kSlope);
  EXPECT_NEAR(sink, kW * cos2 / k, 1e-3 * kW / k);
}

// A chain over a zigzag bed: depths 20, 19, 20, 19, 20 every 10 m along x
// (ny = 1), every segment sqrt(101) m long, the chain as long as the bed's
// profile and pinned at its corners at its resting depth below them (the
// vertical sink of a chain on a slope theta = atan(0.1), w cos^2(theta) / k
// = 7.6e-6 m), 2 elements per segment; frictionless statics. Between the
// corners it rests at the bilinear heights: at 81 points the height above
// the bed is that sink to 1e-3 of it (Newton's tolerance and the stretch,
// 1e-6, leave far less). (Pinned on the bed itself the elements next to
// the pins overshoot by 17%: a cubic cannot follow the boundary layer of
// width sqrt(T / k) where the chain sinks in.)
TEST(SeabedBathymetryTest, ChainOverAZigzagRestsAtTheBilinearHeights) {
  const double k = 1e8;
  const double seg = std::sqrt(101.0);
  const double sink = kW / (1 + 0.01) / k;  // w cos^2(theta) / k
  const double depth[5] = {20, 19, 20, 19, 20};
  std::vector<std::string> pts, pins;
  for (int i = 0; i < 5; ++i) {
    pts.push_back(absl::StrFormat(R"({"x": %d, "y": %.17g})", 10 * i, -depth[i] - sink));
    pins.push_back(
        absl::StrFormat(R"({"type": "PIN", "a": {"cable": "chain", "s": %.17g}})", i * seg));
  }
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": %.17g, "elements": 8, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "second_moment": 1e-14,
                "bending": "NONE", "points": [%s]}],
    "joints": [%s],
    "seabed": {"stiffness": %.17g, "bathymetry": {"dx": 10, "nx": 5, "ny": 1,
               "depths": [20, 19, 20, 19, 20]}},
    "solver": {"analysis": "STATIC", "newton_tolerance": 1e-10}})",
                                           4 * seg, kDensity, kEa / kArea, kArea,
                                           absl::StrJoin(pts, ","), absl::StrJoin(pins, ","), k);
  const Scene scene = SceneFromJson(json);
  auto model = MultibodyModel::Build(scene);
  ASSERT_TRUE(model.ok()) << model.status();
  const Eigen::VectorXd q = SolveStatics(scene, &*model);
  ASSERT_GT(q.size(), 0);
  double lowest = 0, highest = -1;
  for (int i = 0; i <= 80; ++i) {
    const double s = 4 * seg * i / 80;
    const Eigen::Vector3d r = model->CablePosition(q, 0, s);
    // The bilinear height along x, written out.
    const int cell = std::min(3, static_cast<int>(r.x() / 10));
    const double a = r.x() / 10 - cell;
    const double bed = -((1 - a) * depth[cell] + a * depth[cell + 1]);
    const double h = r.y() - bed;
    EXPECT_NEAR(h, model->seabed()->Height(r), 1e-12);
    lowest = std::min(lowest, h);
    highest = std::max(highest, h);
  }
  std::printf("zigzag: height above the bed in [%.3e, %.3e] m (w/k = %.3e)\n", lowest, highest,
              kW / k);
  EXPECT_NEAR(lowest, -sink, 1e-3 * sink);
  EXPECT_NEAR(highest, -sink, 1e-3 * sink);
}

std::string Invalid(const std::string& bathymetry, const std::string& extra = "") {
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "elements": 1, "density": 1, "youngs_modulus": 1e9,
                "area": 1e-4, "bending": "NONE", "points": [{"x": 0}, {"x": 1}]}],
    "seabed": {"stiffness": 1e5 %s, "bathymetry": %s}, "solver": {"analysis": "STATIC"}})",
                                           extra, bathymetry);
  return testing::SceneError(json);
}

TEST(SeabedBathymetryTest, BadGridsNameTheField) {
  EXPECT_EQ(Invalid(R"({"nx": 4, "ny": 3, "dx": 1, "dy": 1, "depths": [1,1,1,1,1,1,1,1,1,1,1]})"),
            "seabed.bathymetry.depths: expected nx*ny = 12 values, got 11");
  EXPECT_EQ(Invalid(R"({"nx": 2, "ny": 1, "dx": 1, "depths": [1, 2]})"), "ok");
  EXPECT_EQ(Invalid(R"({"nx": 2, "ny": 1, "dx": 0, "depths": [1, 2]})"),
            "seabed.bathymetry.dx: must be > 0 (got 0)");
  EXPECT_EQ(Invalid(R"({"nx": 2, "ny": 2, "dx": 1, "dy": -1, "depths": [1, 2, 3, 4]})"),
            "seabed.bathymetry.dy: must be > 0 (got -1)");
  EXPECT_EQ(Invalid(R"({"ny": 1, "depths": [1]})"),
            "seabed.bathymetry.nx: must be in [1, 10000000] (got 0)");
  EXPECT_EQ(Invalid(R"({"nx": 2, "ny": 1, "dx": 1, "depths": [1, "NaN"]})"),
            "seabed.bathymetry.depths[1]: must be finite (got nan)");
  EXPECT_EQ(Invalid(R"({"nx": 1, "ny": 1, "depths": [1]})", R"(, "depth": 2)"),
            "seabed.depth: must be 0 with a bathymetry grid (the grid gives the depths)");
  EXPECT_EQ(Invalid(R"({"nx": 1, "ny": 1, "depths": [1]})", R"(, "normal": {"x": 1, "y": 1})"),
            "seabed.normal: must be along a coordinate axis with a bathymetry grid (the grid's "
            "up)");
}

}  // namespace
}  // namespace cablesim
