// The ANCF cable element against independent references: the mass matrix
// against MODEL.md section 2 and against quadrature of S^T S; forces against
// central differences of the strain energy; tangents against central
// differences of the force; rigid motions and rotations.

#include "engine/elements/ancf_cable_element.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace cablesim {
namespace {

using E2 = AncfCableElement<2>;
using E3 = AncfCableElement<3>;

constexpr double kLength = 0.3;
constexpr double kEA = 2.0e4;
constexpr double kEI = 3.0;

// A strongly deformed element: nodes displaced and slopes rotated by up to
// ~60 degrees and stretched or shortened by up to 20 %.
template <int D>
typename AncfCableElement<D>::Coords RandomLargeDeformation(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  typename AncfCableElement<D>::Coords e;
  Eigen::Matrix<double, D, 1> r0, r1, t0, t1;
  for (int d = 0; d < D; ++d) r0(d) = u(*rng);
  Eigen::Matrix<double, D, 1> dir = Eigen::Matrix<double, D, 1>::Zero();
  dir(0) = 1;
  for (int d = 1; d < D; ++d) dir(d) = 0.8 * u(*rng);
  dir.normalize();
  r1 = r0 + kLength * (1 + 0.2 * u(*rng)) * dir;
  for (int d = 0; d < D; ++d) {
    t0(d) = dir(d) + 0.6 * u(*rng);
    t1(d) = dir(d) + 0.6 * u(*rng);
  }
  t0 *= (1 + 0.2 * u(*rng)) / t0.norm();
  t1 *= (1 + 0.2 * u(*rng)) / t1.norm();
  e << r0, t0, r1, t1;
  return e;
}

template <int D>
typename AncfCableElement<D>::Coords Straight(const Eigen::Matrix<double, D, 1>& origin,
                                               const Eigen::Matrix<double, D, 1>& unit,
                                               double stretch) {
  typename AncfCableElement<D>::Coords e;
  e << origin, stretch * unit, origin + stretch * kLength * unit, stretch * unit;
  return e;
}

TEST(AncfCableElementTest, MassMatrixMatchesModelNotesAndQuadratureOfShapeFunctions) {
  const double rho_a = 7.5;  // kg/m
  const E2 element(kLength, kEA, kEI, BendingModel::kExact);
  const E2::Matrix m = element.MassMatrix(rho_a);
  const double l = kLength, mass = rho_a * l;
  // MODEL.md section 2, including the corrected entry (5,3) = 13 l m / 420.
  EXPECT_NEAR(m(0, 0), mass * 156 / 420, 1e-14);
  EXPECT_NEAR(m(0, 2), mass * 22 * l / 420, 1e-14);
  EXPECT_NEAR(m(4, 2), mass * 13 * l / 420, 1e-14);
  EXPECT_NEAR(m(6, 6), mass * 4 * l * l / 420, 1e-14);
  EXPECT_NEAR(m(6, 0), -mass * 13 * l / 420, 1e-14);
  EXPECT_EQ(m(0, 1), 0.0);
  // Independent: M = rho A int S^T S dx by 6-point Gauss (exact, degree 6).
  const GaussRule rule = MakeGaussRule(6);
  E2::Matrix ref = E2::Matrix::Zero();
  for (int g = 0; g < rule.n; ++g) {
    E2::Matrix s_rows;  // rows 0,1: S; computed through Position of unit vectors
    Eigen::Matrix<double, 2, 8> s;
    for (int c = 0; c < 8; ++c) {
      E2::Coords unit = E2::Coords::Zero();
      unit(c) = 1;
      s.col(c) = element.Position(unit, rule.xi[g]);
    }
    ref += rule.weight[g] * l * rho_a * s.transpose() * s;
  }
  EXPECT_LT((m - ref).cwiseAbs().maxCoeff(), 1e-13 * m.cwiseAbs().maxCoeff());
  // Total mass: a rigid translation has kinetic energy m v^2 / 2.
  E2::Coords v;
  v << 1, 0, 0, 0, 1, 0, 0, 0;
  EXPECT_NEAR(v.dot(m * v), mass, 1e-13);
}

TEST(AncfCableElementTest, GravityPotentialIsMinusGravityForceDotCoordinates) {
  // The potential of a uniform straight element of mass m at height y is m g y.
  const E2 element(kLength, kEA, kEI, BendingModel::kExact);
  const Eigen::Vector2d g(0, -9.81);
  const auto e = Straight<2>(Eigen::Vector2d(0.1, 2.0), Eigen::Vector2d(0.6, 0.8), 1.0);
  const double mass = 4.0 * kLength;
  const double centre_y = 2.0 + 0.5 * kLength * 0.8;
  EXPECT_NEAR(-element.GravityForce(4.0, g).dot(e), mass * 9.81 * centre_y, 1e-12);
}

template <int D>
void CheckForceAgainstEnergyDifferences(BendingModel bending, int seed) {
  std::mt19937 rng(seed);
  const AncfCableElement<D> element(kLength, kEA, kEI, bending);
  for (int trial = 0; trial < 20; ++trial) {
    const auto e = RandomLargeDeformation<D>(&rng);
    typename AncfCableElement<D>::Coords f = AncfCableElement<D>::Coords::Zero();
    element.ElasticForce(e, &f, nullptr);
    // Central differences have error O(h^2 U''') ~ 1e-10 relative here,
    // far below the 1e-6 tolerance the issue sets.
    const double h = 1e-6;
    for (int i = 0; i < AncfCableElement<D>::kCoords; ++i) {
      auto ep = e, em = e;
      ep(i) += h;
      em(i) -= h;
      const auto up = element.StrainEnergy(ep), um = element.StrainEnergy(em);
      const double fd = ((up.axial + up.bending) - (um.axial + um.bending)) / (2 * h);
      EXPECT_NEAR(f(i), fd, 1e-6 * f.cwiseAbs().maxCoeff()) << "coordinate " << i;
    }
  }
}

template <int D>
void CheckTangentAgainstForceDifferences(BendingModel bending, int seed) {
  std::mt19937 rng(seed);
  const AncfCableElement<D> element(kLength, kEA, kEI, bending);
  using C = typename AncfCableElement<D>::Coords;
  using M = typename AncfCableElement<D>::Matrix;
  for (int trial = 0; trial < 20; ++trial) {
    const C e = RandomLargeDeformation<D>(&rng);
    C f = C::Zero();
    M k = M::Zero();
    element.ElasticForce(e, &f, &k);
    const double h = 1e-6;
    M fd;
    for (int i = 0; i < AncfCableElement<D>::kCoords; ++i) {
      C ep = e, em = e, fp = C::Zero(), fm = C::Zero();
      ep(i) += h;
      em(i) -= h;
      element.ElasticForce(ep, &fp, nullptr);
      element.ElasticForce(em, &fm, nullptr);
      fd.col(i) = (fp - fm) / (2 * h);
    }
    EXPECT_LT((k - fd).cwiseAbs().maxCoeff(), 1e-6 * k.cwiseAbs().maxCoeff());
    EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
  }
}

TEST(AncfCableElementTest, PlanarForceIsGradientOfEnergyExactBending) {
  CheckForceAgainstEnergyDifferences<2>(BendingModel::kExact, 1);
}
TEST(AncfCableElementTest, PlanarForceIsGradientOfEnergyLinearBending) {
  CheckForceAgainstEnergyDifferences<2>(BendingModel::kLinear, 2);
}
TEST(AncfCableElementTest, PlanarForceIsGradientOfEnergyNoBending) {
  CheckForceAgainstEnergyDifferences<2>(BendingModel::kNone, 3);
}
TEST(AncfCableElementTest, SpatialForceIsGradientOfEnergyExactBending) {
  CheckForceAgainstEnergyDifferences<3>(BendingModel::kExact, 4);
}
TEST(AncfCableElementTest, PlanarTangentIsJacobianOfForceExactBending) {
  CheckTangentAgainstForceDifferences<2>(BendingModel::kExact, 5);
}
TEST(AncfCableElementTest, PlanarTangentIsJacobianOfForceLinearBending) {
  CheckTangentAgainstForceDifferences<2>(BendingModel::kLinear, 6);
}
TEST(AncfCableElementTest, PlanarTangentIsJacobianOfForceNoBending) {
  CheckTangentAgainstForceDifferences<2>(BendingModel::kNone, 7);
}
TEST(AncfCableElementTest, SpatialTangentIsJacobianOfForceExactBending) {
  CheckTangentAgainstForceDifferences<3>(BendingModel::kExact, 8);
}

TEST(AncfCableElementTest, RigidMotionOfStraightElementHasNoEnergyOrForce) {
  for (BendingModel bending : {BendingModel::kExact, BendingModel::kLinear}) {
    const E2 element(kLength, kEA, kEI, bending);
    for (double angle : {0.0, 0.7, 2.0, -2.9}) {
      const auto e = Straight<2>(Eigen::Vector2d(0.4, -1.3),
                                 Eigen::Vector2d(std::cos(angle), std::sin(angle)), 1.0);
      E2::Coords f = E2::Coords::Zero();
      element.ElasticForce(e, &f, nullptr);
      const auto energy = element.StrainEnergy(e);
      EXPECT_NEAR(energy.axial + energy.bending, 0, 1e-20);
      // Roundoff: EA times machine epsilon.
      EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10 * kEA);
    }
  }
}

TEST(AncfCableElementTest, EnergyIsInvariantUnderRigidRotationOfAnyConfiguration) {
  std::mt19937 rng(11);
  for (BendingModel bending : {BendingModel::kExact, BendingModel::kLinear}) {
    const E2 element(kLength, kEA, kEI, bending);
    for (int trial = 0; trial < 10; ++trial) {
      const E2::Coords e = RandomLargeDeformation<2>(&rng);
      const double angle = 0.3 + trial;
      Eigen::Matrix2d r;
      r << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
      E2::Coords er;
      for (int k = 0; k < 4; ++k) er.segment<2>(2 * k) = r * e.segment<2>(2 * k);
      er.segment<2>(0) += Eigen::Vector2d(5, -3);  // translate the position nodes
      er.segment<2>(4) += Eigen::Vector2d(5, -3);
      const auto a = element.StrainEnergy(e), b = element.StrainEnergy(er);
      EXPECT_NEAR(a.axial, b.axial, 1e-12 * (a.axial + 1e-30));
      EXPECT_NEAR(a.bending, b.bending, 1e-12 * (a.bending + 1e-30));
    }
  }
}

TEST(AncfCableElementTest, SpatialForceIsGradientOfEnergyLinearBending) {
  CheckForceAgainstEnergyDifferences<3>(BendingModel::kLinear, 12);
}
TEST(AncfCableElementTest, SpatialForceIsGradientOfEnergyNoBending) {
  CheckForceAgainstEnergyDifferences<3>(BendingModel::kNone, 13);
}
TEST(AncfCableElementTest, SpatialTangentIsJacobianOfForceLinearBending) {
  CheckTangentAgainstForceDifferences<3>(BendingModel::kLinear, 14);
}
TEST(AncfCableElementTest, SpatialTangentIsJacobianOfForceNoBending) {
  CheckTangentAgainstForceDifferences<3>(BendingModel::kNone, 15);
}

TEST(AncfCableElementTest, SpatialRigidMotionOfStraightElementHasNoEnergyOrForce) {
  std::mt19937 rng(21);
  std::normal_distribution<double> n(0, 1);
  for (BendingModel bending : {BendingModel::kExact, BendingModel::kLinear}) {
    const AncfCableElement<3> element(kLength, kEA, kEI, bending);
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::Vector3d dir = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
      const auto e = Straight<3>(Eigen::Vector3d(n(rng), n(rng), n(rng)), dir, 1.0);
      AncfCableElement<3>::Coords f = AncfCableElement<3>::Coords::Zero();
      element.ElasticForce(e, &f, nullptr);
      const auto energy = element.StrainEnergy(e);
      EXPECT_NEAR(energy.axial + energy.bending, 0, 1e-20);
      // Roundoff: EA times machine epsilon.
      EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10 * kEA);
    }
  }
}

TEST(AncfCableElementTest, SpatialEnergyIsInvariantUnderArbitraryRotationInSpace) {
  // A bent, stretched element rotated by a random rotation about a random
  // axis and translated keeps its strain energy (to rounding, 1e-12).
  std::mt19937 rng(22);
  std::normal_distribution<double> n(0, 1);
  for (BendingModel bending : {BendingModel::kExact, BendingModel::kLinear}) {
    const AncfCableElement<3> element(kLength, kEA, kEI, bending);
    for (int trial = 0; trial < 10; ++trial) {
      const AncfCableElement<3>::Coords e = RandomLargeDeformation<3>(&rng);
      const Eigen::Matrix3d r =
          Eigen::AngleAxisd(0.4 + trial, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized())
              .toRotationMatrix();
      const Eigen::Vector3d shift(n(rng), n(rng), n(rng));
      AncfCableElement<3>::Coords er;
      for (int k = 0; k < 4; ++k) er.segment<3>(3 * k) = r * e.segment<3>(3 * k);
      er.segment<3>(0) += shift;
      er.segment<3>(6) += shift;
      const auto a = element.StrainEnergy(e), b = element.StrainEnergy(er);
      EXPECT_NEAR(a.axial, b.axial, 1e-12 * (a.axial + 1e-30));
      EXPECT_NEAR(a.bending, b.bending, 1e-12 * (a.bending + 1e-30));
    }
  }
}

// An element laid along a circular arc of radius `radius` from the origin,
// with slope magnitudes (stretches) s0 and s1 at its ends; it subtends the
// angle kLength * (s0 + s1) / (2 radius).
E2::Coords Arc(double radius, double s0, double s1) {
  const double mean = (s0 + s1) / 2, phi = kLength * mean / radius;
  E2::Coords e;
  e << 0, 0, s0, 0, radius * std::sin(phi), radius * (1 - std::cos(phi)), s1 * std::cos(phi),
      s1 * std::sin(phi);
  return e;
}

TEST(AncfCableElementTest, ExactBendingIgnoresStretchLinearBendingDoesNot) {
  // Along an arc of radius R, exact kappa = 1/R whatever the stretch s, so
  // U_b = EI l / (2 R^2); the linear model's r''.r'' = s^4 / R^2 instead.
  const double radius = 2.0;
  const double ref = 0.5 * kEI * kLength / (radius * radius);
  const E2 exact(kLength, kEA, kEI, BendingModel::kExact);
  const E2 linear(kLength, kEA, kEI, BendingModel::kLinear);
  for (double s : {1.0, 1.1}) {
    const E2::Coords e = Arc(radius, s, s);
    // The cubic interpolates the arc to O(phi^4), phi = 0.15: 1e-3 relative.
    EXPECT_NEAR(exact.StrainEnergy(e).bending, ref, 1e-3 * ref) << "stretch " << s;
    const double lin = std::pow(s, 4) * ref;
    EXPECT_NEAR(linear.StrainEnergy(e).bending, lin, 1e-3 * lin) << "stretch " << s;
  }
}

TEST(AncfCableElementTest, FiveGaussPointsConvergeTheExactCurvatureEnergy) {
  // The measured basis of kDefaultGaussPoints. Elements bent through up to
  // 1 rad with stretches varying by up to 5 % along them: the 5-point bending
  // energy is within 1e-5 of the 8-point one (measured worst: 2.3e-6); the
  // axial energy, a degree-8 polynomial, is exact. (With 20 % stretch
  // variation inside one element the difference grows to ~3e-3, a sign
  // that the mesh is too coarse, not that the quadrature is.)
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  for (double angle : {0.1, 0.3, 0.6, 1.0}) {
    for (int trial = 0; trial < 50; ++trial) {
      const E2::Coords e = Arc(kLength / angle, 1 + 0.05 * u(rng), 1 + 0.05 * u(rng));
      const E2 five(kLength, kEA, kEI, BendingModel::kExact, 5);
      const E2 eight(kLength, kEA, kEI, BendingModel::kExact, 8);
      const auto a = five.StrainEnergy(e), b = eight.StrainEnergy(e);
      EXPECT_NEAR(a.axial, b.axial, 1e-12 * b.axial);
      worst = std::max(worst, std::abs(a.bending - b.bending) / b.bending);
    }
  }
  std::printf("5 vs 8 Gauss points, exact bending energy: worst relative difference %.3g\n",
              worst);
  EXPECT_LT(worst, 1e-5);
}

// AddDirectionalMass sums only the node blocks k <= j of its symmetric
// matrix and mirrors them: against the plain 16-block quadrature
// sum_g w_g l S_g^T A_g S_g, A_g = a_n I + (a_t - a_n) t t^T, with a
// different mass per point and a point without one (skipped). Tolerance
// 1e-13 relative: five-term sums of terms of one sign per entry, a few
// eps each; a lower block left unset or taken from the wrong upper block
// is off by O(1).
TEST(AncfCableElementTest, DirectionalMassMatrixIsTheQuadratureOfItsTensor) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const E3 element(kLength, kEA, 0, BendingModel::kNone);
  for (int trial = 0; trial < 5; ++trial) {
    const E3::Coords e = RandomLargeDeformation<3>(&rng);
    E3::Coords edd;
    for (int i = 0; i < 12; ++i) edd(i) = u(rng);
    double a_n[GaussRule::kMaxPoints], a_t[GaussRule::kMaxPoints];
    for (int g = 0; g < GaussRule::kMaxPoints; ++g) {
      a_n[g] = 1.5 + 0.3 * u(rng);  // kg/m
      a_t[g] = 0.2 + 0.1 * u(rng);
    }
    a_n[2] = a_t[2] = 0;  // no mass at the middle point
    E3::Matrix m = E3::Matrix::Zero();
    E3::Coords force = E3::Coords::Zero();
    element.AddDirectionalMass(e, edd, a_n, a_t, &force, &m);

    const GaussRule rule = MakeGaussRule(element.gauss_points());
    E3::Matrix ref = E3::Matrix::Zero();
    for (int g = 0; g < rule.n; ++g) {
      double s[4], s1[4];
      HermiteShape(rule.xi[g], kLength, s);
      HermiteShapeD1(rule.xi[g], kLength, s1);
      Eigen::Vector3d slope = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) slope += s1[k] * e.segment<3>(3 * k);
      const Eigen::Vector3d t = slope.normalized();
      const Eigen::Matrix3d a =
          a_n[g] * Eigen::Matrix3d::Identity() + (a_t[g] - a_n[g]) * t * t.transpose();
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
          ref.block<3, 3>(3 * k, 3 * j) += rule.weight[g] * kLength * s[k] * s[j] * a;
    }
    EXPECT_LE((m - ref).cwiseAbs().maxCoeff(), 1e-13 * ref.cwiseAbs().maxCoeff()) << trial;
    // The inertia force is -M edd (the same quadrature).
    const E3::Coords f_ref = -ref * edd;
    EXPECT_LE((force - f_ref).cwiseAbs().maxCoeff(), 1e-13 * f_ref.cwiseAbs().maxCoeff())
        << trial;
    // Mirrored: each lower block exactly the transpose of its upper one
    // (the diagonal blocks carry A_g's own last-bit asymmetry).
    for (int k = 0; k < 4; ++k)
      for (int j = k + 1; j < 4; ++j) {
        const Eigen::Matrix3d up = m.block<3, 3>(3 * k, 3 * j);
        const Eigen::Matrix3d lo = m.block<3, 3>(3 * j, 3 * k);
        EXPECT_EQ((lo - up.transpose()).cwiseAbs().maxCoeff(), 0.0) << trial << k << j;
      }
  }
}

// The matrix-free damping force is AddDampingMatrix's C times edot, and its
// power edot^T C edot, for the three axial laws' scalings (Green-Lagrange:
// EA axial_s u u^T; engineering: over |u|^2), in space and in the plane;
// with a bending term it declines (false, nothing added). Tolerance 1e-12
// relative: the same five-point sums in another order (a few eps per
// term); a missing 1/|u|^2, a wrong sign or a lost point is off by O(1).
template <int D>
void CheckAxialDampingForce(AxialLaw law, std::mt19937* rng) {
  using E = AncfCableElement<D>;
  std::uniform_real_distribution<double> u(-1, 1);
  const E element(kLength, kEA, 0, BendingModel::kNone, E::kDefaultGaussPoints, law);
  for (int trial = 0; trial < 5; ++trial) {
    const typename E::Coords e = RandomLargeDeformation<D>(rng);
    typename E::Coords edot;
    for (int i = 0; i < 4 * D; ++i) edot(i) = u(*rng);
    const double axial_s = 0.01 * (1.5 + u(*rng));
    typename E::Matrix c = E::Matrix::Zero();
    element.AddDampingMatrix(e, axial_s, 0.0, &c);
    const typename E::Coords f_ref = -c * edot;
    typename E::Coords f = E::Coords::Zero();
    double power = -1;
    ASSERT_TRUE(element.AddAxialDampingForce(e, edot, axial_s, 0.0, &f, &power));
    EXPECT_LE((f - f_ref).cwiseAbs().maxCoeff(), 1e-12 * f_ref.cwiseAbs().maxCoeff())
        << static_cast<int>(law) << " " << trial;
    const double power_ref = edot.dot(c * edot);
    EXPECT_GT(power_ref, 0);
    EXPECT_NEAR(power, power_ref, 1e-12 * power_ref) << static_cast<int>(law) << " " << trial;
  }
  // A bending term: C must be formed.
  const E bent(kLength, kEA, kEI, BendingModel::kExact, E::kDefaultGaussPoints, law);
  typename E::Coords f = E::Coords::Zero();
  double power = 0;
  EXPECT_FALSE(bent.AddAxialDampingForce(RandomLargeDeformation<D>(rng),
                                         E::Coords::Ones(), 0.01, 0.01, &f, &power));
  EXPECT_EQ(f.cwiseAbs().maxCoeff(), 0.0);
  // ... but with bending_s 0 only the axial term acts.
  EXPECT_TRUE(bent.AddAxialDampingForce(RandomLargeDeformation<D>(rng), E::Coords::Ones(), 0.01,
                                        0.0, &f, &power));
}

TEST(AncfCableElementTest, AxialDampingForceIsTheDampingMatrixTimesTheRates) {
  std::mt19937 rng(5);
  for (AxialLaw law : {AxialLaw::kGreenLagrange, AxialLaw::kEngineering}) {
    CheckAxialDampingForce<3>(law, &rng);
    CheckAxialDampingForce<2>(law, &rng);
  }
}

// The directional added mass's kinetic energy is 1/2 edot^T M edot with M
// AddDirectionalMass's matrix (a point without mass included). Tolerance
// 1e-13 relative, as above.
TEST(AncfCableElementTest, DirectionalKineticEnergyIsHalfTheRatesThroughItsMatrix) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1);
  const E3 element(kLength, kEA, 0, BendingModel::kNone);
  for (int trial = 0; trial < 5; ++trial) {
    const E3::Coords e = RandomLargeDeformation<3>(&rng);
    E3::Coords edot;
    for (int i = 0; i < 12; ++i) edot(i) = u(rng);
    double a_n[GaussRule::kMaxPoints], a_t[GaussRule::kMaxPoints];
    for (int g = 0; g < GaussRule::kMaxPoints; ++g) {
      a_n[g] = 1.5 + 0.3 * u(rng);  // kg/m
      a_t[g] = -0.2 + 0.1 * u(rng);  // below the mass matrix's part, as CaAx < Ca
    }
    a_n[3] = a_t[3] = 0;
    E3::Matrix m = E3::Matrix::Zero();
    E3::Coords force = E3::Coords::Zero();
    element.AddDirectionalMass(e, edot, a_n, a_t, &force, &m);
    const double ref = 0.5 * edot.dot(m * edot);
    EXPECT_NEAR(element.DirectionalKineticEnergy(e, edot, a_n, a_t), ref,
                1e-13 * 0.5 * edot.cwiseAbs().dot(m.cwiseAbs() * edot.cwiseAbs()))
        << trial;
  }
}

}  // namespace
}  // namespace cablesim
