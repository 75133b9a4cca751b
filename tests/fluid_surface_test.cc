// The cables' added mass along and across the line (hydrodynamics.
// axial_added_mass, engine/forces/cable_added_mass.h) and the free surface
// (fluid.free_surface: buoyancy, drag and added mass only under the
// water, engine/forces/free_surface.h, cable_buoyancy.h), against closed
// forms:
//  - a straight submerged line accelerated along and across its axis: the
//    inertia force is (mu L + rho A L C) a with C = axial_added_mass along
//    and added_mass across (the line is straight, so the quadrature is
//    exact: rounding only), and the Newton matrix's share is the force's
//    exact derivative;
//  - a vertical line hanging half out of the water: its top reaction is the
//    air weight of the dry part plus the submerged weight of the wet part,
//    with the surface at a node and inside an element (STATIC integrates
//    each section's dry fraction);
//  - a level buoyant line floating free at its section's draft, and
//    STATIC's buoyancy above the level the gradient of its energy, its
//    matrix the force's derivative (central differences);
//  - the same line partly immersed in a regular wave: the buoyancy lost is
//    rho A g times the dry length up to the wave's elevation at that time;
//  - a current's drag on the wet part only; a current profile (velocity by
//    depth, piecewise linear): uniform reproduced, and the closed-form drag
//    of a linear shear;
//  - the fields' validation, and that a scene without them is unchanged.

#include <cmath>
#include <cstdio>
#include <utility>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "convert/scene_from_proto.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/forces/waves.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::CollectingSink;
using testing::RunOk;
using testing::SceneError;
using testing::SceneFromJson;

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81, kRho = 1000;
// Cable: steel-like density 7850, diameter 0.05 m (also the hydrodynamic
// diameter), E 2e11 Pa: mu = 15.41 kg/m, rho A = 1.963 kg/m.
constexpr double kDensity = 7850, kD = 0.05;
const double kArea = kPi * kD * kD / 4;
const double kMu = kDensity * kArea, kRhoA = kRho * kArea;

// A straight cable from a to b (planar, gravity -y) in water of still
// level `level`, with the given extra JSON for the fluid, the cable's
// hydrodynamics and the rest of the scene.
std::string LineJson(const Eigen::Vector2d& a, const Eigen::Vector2d& b, int elements,
                     const std::string& fluid_extra, const std::string& hydro,
                     const std::string& rest) {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": %.17g %s},
    "cables": [{"name": "c", "points": [{"x": %.17g, "y": %.17g}, {"x": %.17g, "y": %.17g}],
                "elements": %d, "density": %.17g, "youngs_modulus": 2e11, "diameter": %.17g,
                "bending": "NONE", "hydrodynamics": {%s}}] %s})",
                         kRho, fluid_extra, a.x(), a.y(), b.x(), b.y(), elements, kDensity, kD,
                         hydro, rest);
}

// The inertia force's resultant, sum over the position entries of
// M zdd - f_added(zdd) for the uniform acceleration `acc` of every point
// of the free line (position coordinates acc, slopes 0), and the same
// through the Newton matrix's share (M + D) zdd, at the initial shape.
struct Inertia {
  Eigen::Vector2d force, via_matrix;
};
Inertia InertiaOf(const Scene& scene, const Eigen::Vector2d& acc) {
  Inertia out{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
  auto built = MultibodyModel::Build(scene);
  EXPECT_TRUE(built.ok()) << built.status();
  if (!built.ok()) return out;
  MultibodyModel& model = *built;
  EXPECT_EQ(model.dimension(), 2);
  EXPECT_EQ(model.dofs(), model.coordinates());
  const int n = model.dofs();
  Eigen::VectorXd q(n), zdd = Eigen::VectorXd::Zero(n);
  model.ToFull(model.initial_z(), &q);
  // Node coordinates (r, r') per node: positions at 4i, 4i + 1.
  for (int i = 0; i < n; i += 4) zdd.segment<2>(i) = acc;
  Eigen::VectorXd inertia(n), f = Eigen::VectorXd::Zero(n);
  model.mass().Multiply(zdd.data(), inertia.data());
  SkylineLdlt matrix = model.mass();
  model.AddedMassCorrection(q, zdd, &f, &matrix, 1.0);
  inertia -= f;
  Eigen::VectorXd via(n);
  matrix.Multiply(zdd.data(), via.data());
  for (int i = 0; i < n; i += 4) {
    out.force += inertia.segment<2>(i);
    out.via_matrix += via.segment<2>(i);
  }
  return out;
}

const std::string kDynamic = R"(, "solver": {"duration": 1})";

TEST(CableAddedMassTest, StraightLineAcceleratedAlongAndAcrossCarriesItsOwnCoefficient) {
  // A 10 m line along x, 5 m under the still level, C_a = 1, C_a,ax = 0.2.
  const double length = 10, ca = 1, ca_axial = 0.2;
  const Scene scene = SceneFromJson(LineJson(
      {0, -5}, {length, -5}, 8, "", R"("added_mass": 1, "axial_added_mass": 0.2)", kDynamic));
  for (const auto& [acc, c] : {std::pair{Eigen::Vector2d(1.5, 0), ca_axial},
                               std::pair{Eigen::Vector2d(0, -0.7), ca}}) {
    const Inertia got = InertiaOf(scene, acc);
    // (mu L + rho A L C) a [N]: exact for a straight line but for rounding
    // over some 40 terms of order 100 N (1e-12 relative, with margin).
    const Eigen::Vector2d expected = (kMu * length + kRhoA * length * c) * acc;
    EXPECT_NEAR(got.force.x(), expected.x(), 1e-12 * expected.norm());
    EXPECT_NEAR(got.force.y(), expected.y(), 1e-12 * expected.norm());
    // The Newton matrix's share is the force's derivative (it is linear in
    // the accelerations): the same to rounding.
    EXPECT_NEAR((got.via_matrix - got.force).norm(), 0, 1e-12 * expected.norm());
  }
  // Along a line at 30 degrees, the axial part of an acceleration along x
  // carries C_a,ax and the rest C_a.
  const double angle = kPi / 6;
  const Eigen::Vector2d t(std::cos(angle), std::sin(angle));
  const Scene tilted = SceneFromJson(LineJson({0, -9}, Eigen::Vector2d(0, -9) + length * t, 8,
                                              "", R"("added_mass": 1, "axial_added_mass": 0.2)",
                                              kDynamic));
  const Eigen::Vector2d acc(2, 0);
  const Eigen::Vector2d along = t.dot(acc) * t, across = acc - along;
  const Eigen::Vector2d expected =
      kMu * length * acc + kRhoA * length * (ca_axial * along + ca * across);
  const Inertia got = InertiaOf(tilted, acc);
  EXPECT_NEAR((got.force - expected).norm(), 0, 1e-12 * expected.norm());
}

// The kinetic energy reported (energy.kinetic) counts the added mass as
// the inertia force does: a straight 10 m line translating at v along
// itself carries 1/2 (mu + rho A C_a,ax) L v^2, across itself
// 1/2 (mu + rho A C_a) L v^2, and out of the water (above the surface)
// 1/2 mu L v^2. Before, it was 1/2 (mu + rho A C_a) L v^2 in every case.
// Exact for a straight line (the velocity is uniform) to rounding.
TEST(CableAddedMassTest, KineticEnergyCountsTheAddedMassAlongAcrossAndOutOfTheWater) {
  const double length = 10, ca = 1, ca_axial = 0.2;
  struct Case {
    Eigen::Vector2d a, b, v;
    double c;  // the added mass coefficient the motion carries
    std::string fluid;
  };
  const Case cases[] = {
      {{0, -5}, {length, -5}, {1.5, 0}, ca_axial, ""},
      {{0, -5}, {length, -5}, {0, -0.7}, ca, ""},
      {{0, 5}, {length, 5}, {0, -0.7}, 0, R"(, "free_surface": true)"},
  };
  for (const Case& c : cases) {
    auto built = MultibodyModel::Build(SceneFromJson(
        LineJson(c.a, c.b, 8, c.fluid, R"("added_mass": 1, "axial_added_mass": 0.2)", kDynamic)));
    ASSERT_TRUE(built.ok()) << built.status();
    const int n = built->coordinates();
    Eigen::VectorXd q(n), qdot = Eigen::VectorXd::Zero(n);
    built->ToFull(built->initial_z(), &q);
    for (int i = 0; i < n; i += 4) qdot.segment<2>(i) = c.v;
    const double expected = 0.5 * (kMu + kRhoA * c.c) * length * c.v.squaredNorm();
    const double got = built->Energy(q, qdot, 1.0, nullptr).kinetic;
    EXPECT_NEAR(got, expected, 1e-12 * expected) << "v " << c.v.transpose() << " C " << c.c;
  }
}

TEST(CableAddedMassTest, WithoutTheAxialFieldTheAddedMassIsIsotropicAsBefore) {
  const Scene scene =
      SceneFromJson(LineJson({0, -5}, {10, -5}, 8, "", R"("added_mass": 1)", kDynamic));
  auto built = MultibodyModel::Build(scene);
  ASSERT_TRUE(built.ok()) << built.status();
  EXPECT_FALSE(built->has_added_mass_correction());
  const Inertia got = InertiaOf(scene, {1.5, 0});
  EXPECT_NEAR(got.force.x(), (kMu + kRhoA) * 10 * 1.5, 1e-12 * (kMu + kRhoA) * 15);
}

TEST(CableAddedMassTest, AboveTheFreeSurfaceALineCarriesNoAddedMass) {
  // A vertical 10 m line from y = 4 down to y = -6, a node at the still
  // level (10 elements of 1 m): the wet 6 m carry C_a = 1 across.
  const Scene scene = SceneFromJson(LineJson({0, 4}, {0, -6}, 10, R"(, "free_surface": true)",
                                             R"("added_mass": 1)", kDynamic));
  const Eigen::Vector2d acc(0.8, 0);
  const Inertia got = InertiaOf(scene, acc);
  const double expected = (kMu * 10 + kRhoA * 6) * acc.x();
  EXPECT_NEAR(got.force.x(), expected, 1e-12 * expected);
  EXPECT_NEAR(got.via_matrix.x(), expected, 1e-12 * expected);
}

// The top reaction [N] of a line pinned at its top, hanging still
// (STATIC), with output.reactions.
double TopReaction(const std::string& json) {
  const Scene scene = SceneFromJson(json);
  CollectingSink sink;
  RunOk(scene, &sink);
  if (sink.frames().empty() || sink.frames().back().reactions.empty()) {
    ADD_FAILURE() << "no reaction";
    return NAN;
  }
  return sink.frames().back().reactions[0].force.norm();
}

const std::string kStaticPinned =
    R"(, "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
       "output": {"reactions": true}, "solver": {"analysis": "STATIC"})";

TEST(FreeSurfaceTest, LineHangingHalfOutOfTheWaterHoldsItsAirAndSubmergedWeights) {
  // Top at y = 4, 10 m long, 10 elements: the still level y = 0 is a node.
  const std::string fluid = R"(, "free_surface": true)";
  const double top = TopReaction(LineJson({0, 4}, {0, -6}, 10, fluid, "", kStaticPinned));
  // Closed form: mu g L_dry + (mu - rho A) g L_wet, per undeformed length
  // (gravity and buoyancy act per undeformed length; EA = 3.9e8 N stretches
  // the line by 4e-6, which moves no Gauss point across the level). Exact
  // but for the static solve's tolerance (1e-6 relative, with margin).
  const double expected = kMu * kG * 4 + (kMu - kRhoA) * kG * 6;
  EXPECT_NEAR(top, expected, 1e-6 * expected);
  // Without the free surface the dry part keeps its buoyancy: 77 N (5 %)
  // less.
  const double everywhere = TopReaction(LineJson({0, 4}, {0, -6}, 10, "", "", kStaticPinned));
  EXPECT_NEAR(everywhere, (kMu - kRhoA) * kG * 10, 1e-6 * expected);
  EXPECT_GT(top - everywhere, 0.04 * expected);
}

TEST(FreeSurfaceTest, SurfaceInsideAnElementIsExactInStatics) {
  // The still level at y = 0.3: 3.7 m dry, the level 0.7 of the way along
  // the fourth element (l = 1 m). STATIC takes each section's dry fraction
  // (cable_buoyancy.h): for a straight line through the level the dry
  // length is exact (the section's band -R < h < R holds as much dry as
  // wet), so the reaction is the closed form but for the stretch (EA
  // 3.9e8 N: the 3.7 m above the level stretch by 1.3e-5 m, which moves
  // 2.5e-4 N of buoyancy: 2.0e-4 N, 1.4e-7 of the reaction, measured) and the
  // solve's tolerance: 1e-6 relative. The point-wise switch of DYNAMIC
  // (one Gauss point's share) missed it by 0.55 N (4e-4).
  const std::string fluid = R"(, "free_surface": true, "still_water_level": 0.3)";
  const double top = TopReaction(LineJson({0, 4}, {0, -6}, 10, fluid, "", kStaticPinned));
  const double exact = kMu * kG * 10 - kRhoA * kG * 6.3;
  std::printf("top %.12g N, exact %.12g N\n", top, exact);
  EXPECT_NEAR(top, exact, 1e-6 * exact);
}

// A level, buoyant line with nothing holding it (no joints): in STATIC
// each section floats at the draft where its wet fraction is the density
// ratio, 1 - g(u) = rho_c / rho (g the dry fraction of a circle whose
// centre is u R above the level, cable_buoyancy.h), whatever its length,
// and nothing moves it along the level. The level line's height is the
// same at every Gauss point, so the quadrature is exact: the nodes sit at
// u R to the solve's tolerance.
TEST(FreeSurfaceTest, LevelBuoyantLineFloatsAtItsSectionsDraft) {
  const double density = 300, d = 0.4, r = d / 2;
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "fluid": {"density": %.17g, "free_surface": true},
    "cables": [{"name": "c", "points": [{"x": 0, "y": -1}, {"x": 6, "y": -1}],
                "elements": 3, "density": %.17g, "youngs_modulus": 1e9, "diameter": %.17g,
                "bending": "NONE"}],
    "output": {"shape": true}, "solver": {"analysis": "STATIC"}})",
                                           kRho, density, d);
  const Scene scene = SceneFromJson(json);
  CollectingSink sink;
  RunOk(scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Frame& last = sink.frames().back();
  ASSERT_EQ(last.nodes.size(), 4u);
  // g(u) = (acos(-u) + u sqrt(1 - u^2)) / pi = 1 - 0.3, by bisection.
  double lo = -1, hi = 1;
  for (int k = 0; k < 100; ++k) {
    const double u = 0.5 * (lo + hi);
    const double g = (std::acos(-u) + u * std::sqrt(1 - u * u)) / kPi;
    (g < 1 - density / kRho ? lo : hi) = u;
  }
  const double draft = 0.5 * (lo + hi) * r;
  for (size_t i = 0; i < last.nodes.size(); ++i) {
    std::printf("node %zu (%.12g, %.12g), draft %.12g\n", i, last.nodes[i].x(),
                last.nodes[i].y(), draft);
    EXPECT_NEAR(last.nodes[i].y(), draft, 1e-9);
    EXPECT_NEAR(last.nodes[i].x(), 2.0 * i, 1e-9);
  }
}

// STATIC's buoyancy above the level is a potential's force with its exact
// derivative: at an inclined line crossing the level within an element
// and a level one inside the band, NetForce's f is minus the energy's
// gradient and its matrix minus f's derivative, by central differences
// (step 1e-6 m: truncation 1e-12 of the terms, rounding 1e-10 of them).
// Where the section pierces the level the force, energy and matrix are
// quadratures (kBandPoints Gauss points) of functions with square-root
// ends (g' = 0 at h = +-R, g'' unbounded), whose points move with the
// band's ends: force and energy agree to 1.4e-6 of the force (8 points;
// 1.4e-5 with 5), the matrix to 4.8e-4 of it per metre (a matrix without
// the band's stiffness is off by about 1e3 N/m here). Tolerances: 1e-5
// and 2e-3.
TEST(FreeSurfaceTest, StaticBuoyancyIsTheGradientOfItsEnergyWithItsOwnStiffness) {
  for (const auto& [a, b] : {std::pair<Eigen::Vector2d, Eigen::Vector2d>{{0, 1.3}, {3, -1.1}},
                             {{0, 0.05}, {3, 0.12}}}) {
    const std::string json = absl::StrFormat(R"({
      "gravity": {"y": -9.81},
      "fluid": {"density": %.17g, "free_surface": true},
      "cables": [{"name": "c", "points": [{"x": %.17g, "y": %.17g}, {"x": %.17g, "y": %.17g}],
                  "elements": 2, "density": 300, "youngs_modulus": 1e5, "diameter": 0.4,
                  "bending": "NONE"}],
      "solver": {"analysis": "STATIC"}})",
                                             kRho, a.x(), a.y(), b.x(), b.y());
    auto built = MultibodyModel::Build(SceneFromJson(json));
    ASSERT_TRUE(built.ok()) << built.status();
    MultibodyModel& model = *built;
    const int n = model.dofs();
    ASSERT_EQ(n, model.coordinates());
    // A bent start, so the line's height is a true cubic along it.
    Eigen::VectorXd z = model.initial_z();
    for (int i = 0; i < n; ++i) z(i) += 0.05 * std::sin(1.7 * i);
    Eigen::VectorXd q(n), f(n), fp(n), fm(n), col(n), unit(n);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    SkylineLdlt k = model.mass();
    k.SetZero();
    model.NetForce(z, 1.0, &f, &k, 1.0);
    const double h = 1e-6;
    double worst_f = 0, worst_k = 0;
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd zp = z, zm = z;
      zp(i) += h;
      zm(i) -= h;
      const double ep = model.Energy(zp, zero, 1.0).total, em = model.Energy(zm, zero, 1.0).total;
      worst_f = std::max(worst_f, std::abs(f(i) + (ep - em) / (2 * h)));
      model.NetForce(zp, 1.0, &fp);
      model.NetForce(zm, 1.0, &fm);
      unit.setZero();
      unit(i) = 1;
      k.Multiply(unit.data(), col.data());
      worst_k = std::max(worst_k, (col + (fp - fm) / (2 * h)).lpNorm<Eigen::Infinity>());
    }
    const double size = f.lpNorm<Eigen::Infinity>();
    std::printf("force vs energy %.3g N, matrix vs force %.3g N/m (force size %.3g N)\n",
                worst_f, worst_k, size);
    EXPECT_LE(worst_f, 1e-5 * size);
    EXPECT_LE(worst_k, 2e-3 * size);
  }
}

TEST(FreeSurfaceTest, PartlyImmersedLineInAWaveLosesTheBuoyancyAboveTheElevation) {
  // A vertical line from y = 2 to the bed at -18 (depth 18), x = 3, held
  // still in a regular wave of height 2 m, period 8 s; 40 elements of
  // 0.5 m. The applied force's resultant at time t is the weight with
  // buoyancy, -(mu - rho A) g L, less the buoyancy of the points above the
  // elevation eta(3, t) = (H / 2) cos(k x - omega t + phase).
  const double x = 3, height = 2, period = 8, phase = 0.3, depth = 18;
  const std::string fluid = absl::StrFormat(
      R"(, "free_surface": true, "water_depth": %.17g,
         "waves": {"regular": [{"height": %.17g, "period": %.17g, "phase": %.17g}]})",
      depth, height, period, phase);
  const Scene scene =
      SceneFromJson(LineJson({x, 2}, {x, -depth}, 40, fluid, "", kDynamic));
  auto built = MultibodyModel::Build(scene);
  ASSERT_TRUE(built.ok()) << built.status();
  MultibodyModel& model = *built;
  const int n = model.dofs();
  Eigen::VectorXd q(n);
  model.ToFull(model.initial_z(), &q);
  const double omega = 2 * kPi / period, k = WaveField::Wavenumber(omega, depth, kG);
  const GaussRule rule = MakeGaussRule(5);
  int crossings_seen = 0;
  for (double t : {0.0, 1.3, 2.9, 4.4, 6.1}) {
    const double eta = 0.5 * height * std::cos(k * x - omega * t + phase);
    model.SetTime(t);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
    model.NetForce(q, 1.0, &f);
    double fy = 0;
    for (int i = 0; i < n; i += 4) fy += f(i + 1);  // elastic forces cancel in the sum
    // The dry Gauss points' length by the quadrature (y = 2 - s).
    double dry = 0;
    for (int e = 0; e < 40; ++e)
      for (int g = 0; g < rule.n; ++g)
        if (2 - 0.5 * (e + rule.xi[g]) >= eta) dry += 0.5 * rule.weight[g];
    const double weight = (kMu - kRhoA) * kG * 20;
    EXPECT_NEAR(fy, -weight - kRhoA * kG * dry, 1e-9 * weight) << "t = " << t;
    // Against the closed form 2 - eta: within one point's share.
    EXPECT_LE(std::abs(dry - (2 - eta)), 0.5 * 0.2845) << "t = " << t;
    if (std::abs(dry - (2 - eta)) > 0) ++crossings_seen;
  }
  EXPECT_GT(crossings_seen, 0);
}

// The drag across a line from a to b (10 elements, normal drag 1.2) held
// still in the current of `fluid` (JSON of the fluid's extra fields): the
// sum of the x entries of the damping force [N].
double DragAcross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const std::string& fluid) {
  const Scene scene =
      SceneFromJson(LineJson(a, b, 10, fluid, R"("normal_drag": 1.2)", kDynamic));
  auto built = MultibodyModel::Build(scene);
  EXPECT_TRUE(built.ok()) << built.status();
  if (!built.ok()) return NAN;
  MultibodyModel& model = *built;
  const int n = model.dofs();
  Eigen::VectorXd q(n), qd = Eigen::VectorXd::Zero(n), f = Eigen::VectorXd::Zero(n);
  model.ToFull(model.initial_z(), &q);
  model.DampingForce(q, qd, &f);
  double fx = 0;
  for (int i = 0; i < n; i += 4) fx += f(i);
  return fx;
}

TEST(FreeSurfaceTest, CurrentDragActsOnTheWetPartOnly) {
  // The vertical line of the statics test held still in a current of
  // 0.5 m/s: the drag across is kn U^2 over the wet 6 m (a node at the
  // level), kn = rho C_dn d / 2.
  const double u = 0.5, cdn = 1.2;
  const double fx =
      DragAcross({0, 4}, {0, -6}, R"(, "free_surface": true, "current": {"x": 0.5})");
  const double expected = 0.5 * kRho * cdn * kD * u * u * 6;
  EXPECT_NEAR(fx, expected, 1e-12 * expected);
}

TEST(FreeSurfaceTest, FieldsAreValidatedByName) {
  EXPECT_THAT(SceneError(LineJson({0, 4}, {0, -6}, 10, "", R"("axial_added_mass": -1)", "")),
              HasSubstr("cables[0].hydrodynamics.axial_added_mass"));
  EXPECT_THAT(SceneError(R"({"fluid": {"density": 1000, "free_surface": true},
      "cables": [{"name": "c", "points": [{"x": 0}, {"x": 1}], "density": 1000,
                  "youngs_modulus": 1e9, "diameter": 0.01, "bending": "NONE"}]})"),
              HasSubstr("fluid.free_surface: needs gravity"));
  // An explicit or non-alpha stepper cannot take a direction-dependent
  // added mass: refused naming the integrator and the field.
  const Scene scene = SceneFromJson(LineJson(
      {0, -5}, {10, -5}, 8, "", R"("added_mass": 1, "axial_added_mass": 0.2)",
      R"(, "solver": {"duration": 1, "integrator": "IMPLICIT_EULER"})"));
  auto built = MultibodyModel::Build(scene);
  ASSERT_FALSE(built.ok());
  EXPECT_THAT(built.status().message(), HasSubstr("solver.integrator: IMPLICIT_EULER"));
  EXPECT_THAT(built.status().message(), HasSubstr("cables[0].hydrodynamics.axial_added_mass"));
}

TEST(CableAddedMassTest, DynamicRunWithAxialAddedMassAndFreeSurfaceSettles) {
  // A line pinned at the top, half out of the water, released from 30
  // degrees off the vertical with C_a = 1, C_a,ax = 0 and drag: it runs
  // (HHT, the default) and its energy balance holds (the run's energy guard).
  const Scene scene = SceneFromJson(LineJson(
      {0, 4}, {5, 4 - 8.66}, 10, R"(, "free_surface": true)",
      R"("added_mass": 1, "axial_added_mass": 0, "normal_drag": 1.2)",
      R"(, "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
         "solver": {"duration": 5, "step": 0.01})"));
  CollectingSink sink;
  const RunSummary s = RunOk(scene, &sink);
  EXPECT_GT(s.steps, 0);
}


TEST(CurrentProfileTest, AUniformProfileIsTheUniformCurrent) {
  const double uniform = DragAcross({0, 0}, {0, -10}, R"(, "current": {"x": 0.7})");
  const double profile = DragAcross({0, 0}, {0, -10},
      R"(, "current_profile": [{"depth": 0, "velocity": {"x": 0.7}},
                               {"depth": 50, "velocity": {"x": 0.7}}])");
  // kn U^2 L; the same Gauss points and velocities: equal to rounding.
  const double expected = 0.5 * kRho * 1.2 * kD * 0.7 * 0.7 * 10;
  EXPECT_NEAR(uniform, expected, 1e-12 * expected);
  EXPECT_NEAR(profile, uniform, 1e-12 * expected);
}

TEST(CurrentProfileTest, LinearShearGivesTheClosedFormDrag) {
  // U(d) = 1.0 m/s at the level falling linearly to 0.2 m/s at 10 m depth
  // (and held below): over the line, int_0^L kn U(d)^2 dd =
  // kn L (U_0^2 + U_0 U_L + U_L^2) / 3. The integrand is quadratic in d
  // on every element, which the 5-point rule integrates exactly: equal to
  // rounding.
  const double u0 = 1.0, ul = 0.2, length = 10;
  const double got = DragAcross({0, 0}, {0, -10},
      R"(, "current_profile": [{"depth": 0, "velocity": {"x": 1.0}},
                               {"depth": 10, "velocity": {"x": 0.2}}])");
  const double expected = 0.5 * kRho * 1.2 * kD * length * (u0 * u0 + u0 * ul + ul * ul) / 3;
  EXPECT_NEAR(got, expected, 1e-12 * expected);
  // A knot inside an element makes the integrand's derivative jump there
  // (the rule is then not exact): knots at 0, 4.5 and 10 m with the same
  // straight line give the same velocities, so the same drag.
  const double split = DragAcross({0, 0}, {0, -10},
      R"(, "current_profile": [{"depth": 0, "velocity": {"x": 1.0}},
                               {"depth": 4.5, "velocity": {"x": 0.64}},
                               {"depth": 10, "velocity": {"x": 0.2}}])");
  EXPECT_NEAR(split, expected, 1e-12 * expected);
}

TEST(CurrentProfileTest, FieldsAreValidatedByName) {
  const auto scene = [](const std::string& fluid) {
    return LineJson({0, 0}, {0, -10}, 10, fluid, R"("normal_drag": 1.2)", "");
  };
  EXPECT_THAT(SceneError(scene(R"(, "current_profile": [{"depth": 5}, {"depth": 5}])")),
              HasSubstr("fluid.current_profile[1].depth: depths must be strictly increasing"));
  EXPECT_THAT(SceneError(scene(R"(, "current": {"x": 1}, "current_profile": [{"depth": 5}])")),
              HasSubstr("fluid.current_profile: give fluid.current or fluid.current_profile"));
}

}  // namespace
}  // namespace cablesim
