// Tension-strain tables (AxialLaw::kTable, engine/elements/tension_table.h):
// the table's tension, stiffness, energy and mean tension against their
// closed forms; a one-segment table against ENGINEERING with the same EA
// (the same law evaluated in another order: equal to rounding); the
// element's force and tangent as derivatives of its energy and its discrete
// gradient exact on a table of several segments; a bar pulled by a force
// between two knots stretching by the closed-form strain; energy kept by
// ENERGY_MOMENTUM on a pendulum that stretches across the knots; bad tables
// refused naming the field.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/elements/ancf_cable_element.h"
#include "engine/elements/tension_table.h"
#include "tests/ancf_element_checks.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

// Knots (0, 0), (0.01, 100), (0.03, 500), (0.05, 600): slopes 1e4, 2e4, 5e3.
TensionTable ThreeSegments() { return TensionTable({0, 0.01, 0.03, 0.05}, {0, 100, 500, 600}); }

TEST(TensionTableTest, TensionStiffnessAndEnergyAreTheClosedForms) {
  const TensionTable t = ThreeSegments();
  struct Case {
    double e, tension, stiffness, energy;
  };
  // Energy: the trapezoids up to e (W(0.01) = 0.5, W(0.03) = 6.5,
  // W(0.05) = 17.5); compression and beyond the last knot continue the
  // first and last segments.
  for (const Case& c : {Case{0.005, 50, 1e4, 0.125}, Case{0.01, 100, 2e4, 0.5},
                        Case{0.02, 300, 2e4, 0.5 + 0.01 * 200}, Case{0.04, 550, 5e3, 6.5 + 5.25},
                        Case{0.07, 700, 5e3, 17.5 + 0.02 * 650}, Case{-0.01, -100, 1e4, 0.5}}) {
    const TensionTable::Value v = t.At(c.e);
    // Sums of a few products of short decimals: rounding only.
    EXPECT_NEAR(v.tension, c.tension, 1e-12 * 700) << "e = " << c.e;
    EXPECT_NEAR(v.stiffness, c.stiffness, 1e-12 * 2e4) << "e = " << c.e;
    EXPECT_NEAR(t.Energy(c.e), c.energy, 1e-12 * 30) << "e = " << c.e;
  }
  EXPECT_NEAR(t.max_stiffness(), 2e4, 1e-12 * 2e4);
}

TEST(TensionTableTest, MeanTensionIsTheExactDifferenceQuotientOfTheEnergy) {
  const TensionTable t = ThreeSegments();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.02, 0.08);
  for (int k = 0; k < 200; ++k) {
    const double e0 = u(rng), e1 = u(rng);
    // W's values are O(30 J/m): their difference is good to ~1e-14, the
    // quotient by |e1 - e0| >= ~1e-4 to ~1e-9 N; the mean itself is exact.
    if (std::abs(e1 - e0) < 1e-4) continue;
    EXPECT_NEAR(t.MeanTension(e0, e1), (t.Energy(e1) - t.Energy(e0)) / (e1 - e0), 1e-8)
        << e0 << " " << e1;
    EXPECT_EQ(t.MeanTension(e0, e1), t.MeanTension(e1, e0));
  }
  // Equal ends: the tension there; close ends across a knot: the tension
  // at the knot, without the cancellation of the energies' difference.
  EXPECT_NEAR(t.MeanTension(0.02, 0.02), 300, 1e-12);
  EXPECT_NEAR(t.MeanTension(0.03 - 1e-13, 0.03 + 1e-13), 500, 1e-8);
}

constexpr double kLength = 0.3;
constexpr double kEA = 2.0e4;
constexpr double kEI = 3.0;

template <int D>
typename AncfCableElement<D>::Coords Deformed(std::mt19937* rng) {
  // Stretched or shortened by up to 20 %: strains across the knots below.
  return testing::Deformed<D>(rng, kLength);
}

template <int D>
AncfCableElement<D> WithTable(BendingModel bending, std::shared_ptr<const TensionTable> table) {
  return AncfCableElement<D>(kLength, kEA, kEI, bending, AncfCableElement<D>::kDefaultGaussPoints,
                             AxialLaw::kTable, std::move(table));
}

template <int D>
double Energy(const AncfCableElement<D>& element, const typename AncfCableElement<D>::Coords& e) {
  return testing::TotalStrainEnergy(element, e);
}

// A table of one segment of slope EA is ENGINEERING with that EA: the
// force, tangent, energy, damping and discrete gradient agree to rounding.
// The two evaluate T / |u| as k (s - 1) / s and EA (1 - 1/s): each is good
// to a few ulps of EA |u| ~ 2e4 N, so 1e-11 EA (about 10^5 ulps of the
// largest term) is rounding, while any real difference of the laws (a
// missing 1/s is 20 % here) is 10^10 times larger.
template <int D>
void CheckOneSegmentIsEngineering(BendingModel bending) {
  using C = typename AncfCableElement<D>::Coords;
  using M = typename AncfCableElement<D>::Matrix;
  auto table = std::make_shared<const TensionTable>(std::vector<double>{0, 0.05},
                                                    std::vector<double>{0, 0.05 * kEA});
  const AncfCableElement<D> tab = WithTable<D>(bending, table);
  const AncfCableElement<D> eng(kLength, kEA, kEI, bending,
                                AncfCableElement<D>::kDefaultGaussPoints, AxialLaw::kEngineering);
  std::mt19937 rng(31);
  double worst_force = 0, worst_tangent = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const C e = Deformed<D>(&rng), e1 = Deformed<D>(&rng);
    C f1 = C::Zero(), f2 = C::Zero(), r1 = C::Zero(), r2 = C::Zero();
    M k1 = M::Zero(), k2 = M::Zero(), c1 = M::Zero(), c2 = M::Zero();
    tab.ElasticForce(e, &f1, &k1, &r1);
    eng.ElasticForce(e, &f2, &k2, &r2);
    worst_force = std::max(worst_force, (f1 - f2).cwiseAbs().maxCoeff());
    worst_tangent = std::max(worst_tangent, (k1 - k2).cwiseAbs().maxCoeff());
    EXPECT_NEAR(tab.StrainEnergy(e).axial, eng.StrainEnergy(e).axial, 1e-11 * kEA * kLength);
    EXPECT_LT((r1 - r2).cwiseAbs().maxCoeff(), 1e-6 * r2.cwiseAbs().maxCoeff());
    tab.AddDampingMatrix(e, 0.01, 0.02, &c1);
    eng.AddDampingMatrix(e, 0.01, 0.02, &c2);
    EXPECT_EQ(c1, c2);  // the same formula on the same nominal EA
    C g1 = C::Zero(), g2 = C::Zero();
    tab.AddDiscreteGradientCorrection(e, e1, &g1);
    eng.AddDiscreteGradientCorrection(e, e1, &g2);
    EXPECT_LT((g1 - g2).cwiseAbs().maxCoeff(), 1e-11 * kEA);
  }
  std::printf("one-segment table against ENGINEERING (D = %d): force %.2g N, tangent %.2g N/m "
              "(EA %g N)\n",
              D, worst_force, worst_tangent, kEA);
  EXPECT_LT(worst_force, 1e-11 * kEA);
  EXPECT_LT(worst_tangent, 1e-11 * kEA / (kLength * kLength));
}

TEST(TensionTableTest, OneSegmentTableIsEngineeringToRounding) {
  CheckOneSegmentIsEngineering<2>(BendingModel::kNone);
  CheckOneSegmentIsEngineering<2>(BendingModel::kExact);
  CheckOneSegmentIsEngineering<3>(BendingModel::kExact);
}

// Three segments whose knots (strains 0.05, 0.1, 0.15 at slopes EA, 3 EA,
// 0.5 EA) fall inside the deformed elements' +-20 % stretch.
std::shared_ptr<const TensionTable> Kinked() {
  return std::make_shared<const TensionTable>(
      std::vector<double>{0, 0.05, 0.1, 0.15},
      std::vector<double>{0, 0.05 * kEA, 0.2 * kEA, 0.225 * kEA});
}

// Force and tangent against central differences (ancf_element_checks.h;
// where the difference straddles a knot's kink it errs, but a Gauss
// point's strain within ~1e-6 of a knot has probability ~1e-4 per point).
template <int D>
void CheckForceAndTangent(BendingModel bending, int seed) {
  testing::CheckForceAndTangent<D>(WithTable<D>(bending, Kinked()), seed);
}

TEST(TensionTableTest, ForceAndTangentAreDerivativesOfTheEnergy) {
  CheckForceAndTangent<2>(BendingModel::kNone, 41);
  CheckForceAndTangent<2>(BendingModel::kExact, 42);
  CheckForceAndTangent<3>(BendingModel::kExact, 43);
}

// DG U(e0, e1) . (e1 - e0) = U(e1) - U(e0) to rounding, the strains of
// e0 and e1 on different segments.
TEST(TensionTableTest, DiscreteGradientIsExactAcrossKnots) {
  using C = AncfCableElement<3>::Coords;
  std::mt19937 rng(51);
  const AncfCableElement<3> element = WithTable<3>(BendingModel::kExact, Kinked());
  for (int trial = 0; trial < 20; ++trial) {
    const C e0 = Deformed<3>(&rng), e1 = Deformed<3>(&rng);
    C dg = C::Zero();
    element.ElasticForce(0.5 * (e0 + e1), &dg, nullptr);
    element.AddDiscreteGradientCorrection(e0, e1, &dg);
    const double du = Energy(element, e1) - Energy(element, e0);
    EXPECT_NEAR(dg.dot(e1 - e0), du, 1e-10 * (std::abs(Energy(element, e0)) + 1));
  }
}

// A bar of 1 m clamped at one end and pulled along its axis at the other,
// solved by STATIC: its end moves by the table's strain at that force.
std::string BarScene(const std::string& cable_law, double force) {
  return absl::StrFormat(R"({
    "cables": [{"name": "bar", "length": 1, "elements": 4, "density": 1140,
                "diameter": 0.02, %s}],
    "joints": [{"type": "FIXED", "a": {"cable": "bar", "s": 0}}],
    "loads": [{"at": {"cable": "bar", "s": 1}, "force": {"x": %.17g}}],
    "probes": [{"name": "end", "cable": "bar", "s": 1}],
    "solver": {"analysis": "STATIC", "newton_tolerance": 1e-12}})",
                         cable_law, force);
}

double BarStrain(const std::string& cable_law, double force) {
  const Scene scene = testing::SceneFromJson(BarScene(cable_law, force));
  testing::CollectingSink sink;
  testing::RunOk(scene, &sink);
  if (sink.frames().empty()) return NAN;
  return sink.frames().back().probes[0].position_m.x() - 1;
}

// A rope-like table: stiffening, then softening. Knots (0.02, 2e4 N),
// (0.05, 1.1e5 N), (0.08, 1.4e5 N).
constexpr const char* kRope =
    R"("axial_law": "TABLE", "tension_table": {"strains": [0.02, 0.05, 0.08],
       "tensions": [2e4, 1.1e5, 1.4e5]})";

TEST(TensionTableTest, BarPulledBetweenKnotsStretchesByTheTablesStrain) {
  // Newton's tolerance 1e-12 on |q| ~ 1 m: 1e-10 on the strain is far
  // above it and far below a knot's effect (a wrong segment is off by
  // 1e-3 or more here).
  // 6e4 N lies on the second segment (slope 3e6 N): e = 0.02 + 4e4 / 3e6.
  EXPECT_NEAR(BarStrain(kRope, 6e4), 0.02 + 4e4 / 3e6, 1e-10);
  // 1e4 N on the first (slope 1e6 N): e = 0.01.
  EXPECT_NEAR(BarStrain(kRope, 1e4), 0.01, 1e-10);
  // 1.6e5 N beyond the last knot, on the last segment continued (slope
  // 1e6 N): e = 0.08 + 2e4 / 1e6.
  EXPECT_NEAR(BarStrain(kRope, 1.6e5), 0.1, 1e-10);
  // Pushed by 1e3 N: the first segment continued into compression.
  EXPECT_NEAR(BarStrain(kRope, -1e3), -1e-3, 1e-10);
  // One segment of slope EA: ENGINEERING's strain F / EA.
  const double ea = 1e6;
  const std::string one = R"("axial_law": "TABLE", "tension_table": {"strains": [0.1],
       "tensions": [1e5]})";
  const double e_table = BarStrain(one, 1e4);
  const double e_eng =
      BarStrain(absl::StrFormat(R"("axial_law": "ENGINEERING", "youngs_modulus": %.17g)",
                                ea / (M_PI * 0.02 * 0.02 / 4)),
                1e4);
  EXPECT_NEAR(e_table, 0.01, 1e-10);
  EXPECT_NEAR(e_table, e_eng, 1e-12);
}

// The whole model: the spatial pendulum of axial_law_test (spun about the
// vertical, stretching as it swings) with a soft table whose knots it
// crosses, run by ENERGY_MOMENTUM, keeps its energy to the Newton
// tolerance (the tolerance of axial_law_test's engineering-law pendulum):
// the table's strain energy is the exact integral of its tension and its
// discrete gradient exact, so the energy diagnostics close.
TEST(TensionTableTest, EnergyMomentumKeepsEnergyWithATable) {
  // Knots at strains 5e-4 and 1.5e-3 (slopes 40, 20, 60 N: the
  // engineering-law pendulum's EA of 40 N, softening, then stiffening).
  const testing::PendulumDrift d = testing::SpunPendulumDrift(
      R"("axial_law": "TABLE",
         "tension_table": {"strains": [5e-4, 1.5e-3, 1e-2], "tensions": [0.02, 0.04, 0.55]})");
  std::printf("table, ENERGY_MOMENTUM: |dL_y| / L_y = %.3g, |dE| = %.3g J, largest axial "
              "energy %.3g J, tip stretch %.3g m\n",
              d.momentum, d.energy, d.axial, d.stretch);
  // A mean strain past the second knot: every knot crossed somewhere.
  EXPECT_GT(d.stretch, 1.5e-3);
  EXPECT_LT(d.momentum, 1e-11);
  EXPECT_LT(d.energy, 1e-9 * d.kinetic);
}

std::string TableCable(const std::string& extra) {
  return absl::StrFormat(R"({
    "cables": [{"name": "c", "length": 1, "density": 1140, "diameter": 0.02, %s}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": {"analysis": "STATIC"}})",
                         extra);
}

TEST(TensionTableTest, BadTablesAreRefusedNamingTheField) {
  struct Case {
    const char* extra;
    const char* field;
  };
  for (const Case& c : {
           Case{R"("axial_law": "TABLE")", "cables[0].tension_table: required"},
           Case{R"("axial_law": "TABLE", "tension_table": {"strains": [], "tensions": []})",
                "cables[0].tension_table.strains: must have"},
           Case{R"("axial_law": "TABLE", "tension_table": {"strains": [0.1], "tensions": []})",
                "cables[0].tension_table.tensions: must have as many"},
           Case{R"("axial_law": "TABLE",
                   "tension_table": {"strains": [0.1, 0.05], "tensions": [1, 2]})",
                "cables[0].tension_table.strains: strains must increase"},
           Case{R"("axial_law": "TABLE",
                   "tension_table": {"strains": [0.1, 0.2], "tensions": [2, 1]})",
                "cables[0].tension_table.tensions: tensions must not decrease"},
           Case{R"("axial_law": "TABLE",
                   "tension_table": {"strains": [0, 0.2], "tensions": [5, 10]})",
                "cables[0].tension_table.tensions[0]: must be 0 at zero strain"},
           Case{R"("axial_law": "TABLE",
                   "tension_table": {"strains": [-0.1, 0.2], "tensions": [0, 10]})",
                "cables[0].tension_table.strains[0]"},
           Case{R"("axial_law": "TABLE", "tension_table": {"strains": [0.1], "tensions": [0]})",
                "cables[0].tension_table.tensions: must not all be 0"},
           Case{R"("youngs_modulus": 1e9,
                   "tension_table": {"strains": [0.1], "tensions": [10]})",
                "cables[0].tension_table: only with axial_law TABLE"},
           Case{R"("axial_law": "ENGINEERING")", "cables[0].youngs_modulus"},
       }) {
    const std::string error = testing::SceneError(TableCable(c.extra));
    EXPECT_NE(error.find(c.field), std::string::npos) << c.extra << "\n" << error;
  }
  // A winch keeps the Green-Lagrange law.
  const std::string winch = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "density": 7850, "diameter": 0.01,
                "axial_law": "TABLE", "tension_table": {"strains": [0.1], "tensions": [1e5]},
                "winch": {}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1}}],
    "solver": {"analysis": "STATIC"}})";
  EXPECT_NE(testing::SceneError(winch).find("cables[0].axial_law: TABLE"), std::string::npos)
      << testing::SceneError(winch);
}

// Without youngs_modulus a table's steepest slope over the area is the
// nominal modulus (what damping's axial_time multiplies).
TEST(TensionTableTest, YoungsModulusDefaultsToTheSteepestSlope) {
  const Scene scene = testing::SceneFromJson(BarScene(kRope, 1));
  ASSERT_EQ(scene.cables.size(), 1u);
  EXPECT_NEAR(scene.cables[0].youngs_modulus_pa * scene.cables[0].area_m2, 3e6, 1e-6);
  EXPECT_EQ(scene.cables[0].tension_table_strains, (std::vector<double>{0, 0.02, 0.05, 0.08}));
}

}  // namespace
}  // namespace cablesim
