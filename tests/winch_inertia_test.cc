// The axially moving mesh of a winch cable (engine/forces/winch_inertia.h)
// against a rigid reel-in, whose material velocity and acceleration are
// known exactly: a straight cable along one axis held at x = 0 by the winch,
// free length L(t), reeled in with speed Ldot and acceleration Lddot. Its
// material moves as one: v = -Ldot, a = -Lddot (along the cable; per
// component the element matrices act alike, so one component suffices).
// Node i (s_i = i L / N) sits at x_i = -(L - s_i) with slope 1, so
// xdot_i = -Ldot (1 - i / N) and xddot_i = -Lddot (1 - i / N).

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "engine/forces/winch_inertia.h"
#include "engine/elements/hermite_shape.h"

namespace cablesim {
namespace {

constexpr int kN = 6;
constexpr double kMu = 3.5, kL = 2.4, kLdot = -0.7, kLddot = 0.3;

// Full scalar coordinates [x_0, x'_0, x_1, x'_1, ...] of the rigid motion.
void RigidState(Eigen::VectorXd* e, Eigen::VectorXd* edot, Eigen::VectorXd* eddot) {
  e->setZero(2 * (kN + 1));
  edot->setZero(2 * (kN + 1));
  eddot->setZero(2 * (kN + 1));
  for (int i = 0; i <= kN; ++i) {
    const double frac = 1.0 - static_cast<double>(i) / kN;
    (*e)(2 * i) = -kL * frac;
    (*e)(2 * i + 1) = 1;
    (*edot)(2 * i) = -kLdot * frac;
    (*eddot)(2 * i) = -kLddot * frac;
  }
}

// T = 1/2 mu L Ldot^2: the whole material moves at Ldot.
TEST(WinchInertiaTest, KineticEnergyOfRigidReelIn) {
  Eigen::VectorXd e, edot, eddot;
  RigidState(&e, &edot, &eddot);
  const double l = kL / kN, ldot = kLdot / kN;
  double t = 0, mass = 0;
  for (int k = 0; k < kN; ++k) {
    const WinchElementInertia in = ComputeWinchElementInertia(kMu, l, k);
    const Eigen::Vector4d q = e.segment<4>(2 * k), v = edot.segment<4>(2 * k);
    t += 0.5 * v.dot(in.m * v) + ldot * v.dot(in.g * q) + 0.5 * ldot * ldot * q.dot(in.h * q);
    // The mass is the sum of M's position-position entries (unit motion).
    mass += in.m(0, 0) + in.m(0, 2) + in.m(2, 0) + in.m(2, 2);
  }
  // Rounding of sums of O(1) terms.
  EXPECT_NEAR(t, 0.5 * kMu * kL * kLdot * kLdot, 1e-13);
  EXPECT_NEAR(mass, kMu * kL, 1e-13);
}

// Lagrange's equations of the material in [0, L]: M eddot + cv edot + ce e
// equals int mu S^T a ds, the generalized force of the uniform material
// acceleration a = -Lddot, on every coordinate but the winch node's
// position (the last node's x), where the momentum flux of the material
// leaving through it also acts (and the winch holds it).
TEST(WinchInertiaTest, ConvectiveTermsVanishOffTheWinchNode) {
  Eigen::VectorXd e, edot, eddot;
  RigidState(&e, &edot, &eddot);
  const double l = kL / kN, ldot = kLdot / kN, lddot = kLddot / kN;
  Eigen::VectorXd lhs = Eigen::VectorXd::Zero(e.size()), rhs = lhs;
  for (int k = 0; k < kN; ++k) {
    const WinchElementInertia in = ComputeWinchElementInertia(kMu, l, k);
    Eigen::Matrix4d cv, ce;
    WinchConvectiveCoefficients(in, ldot, lddot, &cv, &ce);
    lhs.segment<4>(2 * k) += in.m * eddot.segment<4>(2 * k) + cv * edot.segment<4>(2 * k) +
                             ce * e.segment<4>(2 * k);
    // int mu S^T a dx for a constant a (MODEL.md section 2's gravity).
    const double m = kMu * l, a = -kLddot;
    rhs.segment<4>(2 * k) += Eigen::Vector4d(m * a / 2, m * l * a / 12, m * a / 2, -m * l * a / 12);
  }
  for (int i = 0; i < e.size() - 2; ++i) EXPECT_NEAR(lhs(i), rhs(i), 1e-12) << "coordinate " << i;
  // The last slope too (only the position carries the flux).
  EXPECT_NEAR(lhs(e.size() - 1), rhs(e.size() - 1), 1e-12);
  // ... and the winch node's position does carry it: mu Ldot^2 (the rate at
  // which momentum leaves) on top of the acceleration's share.
  EXPECT_GT(std::abs(lhs(e.size() - 2) - rhs(e.size() - 2)), 0.1 * kMu * kLdot * kLdot);
}

// The material strain rate of a rigid reel-in is 0 everywhere, though the
// nodes' velocities differ (S' edot alone is Ldot / L on average).
TEST(WinchInertiaTest, RigidReelInHasNoMaterialStrainRate) {
  Eigen::VectorXd e, edot, eddot;
  RigidState(&e, &edot, &eddot);
  const double l = kL / kN, ldot = kLdot / kN;
  for (int k = 0; k < kN; ++k) {
    for (double xi : {0.0, 0.2, 0.5, 0.9, 1.0}) {
      double d1[4], wd[4];
      HermiteShapeD1(xi, l, d1);
      WinchSlopeRateShape(xi, l, k, wd);
      double rate = 0, nodal = 0;
      for (int a = 0; a < 4; ++a) {
        rate += d1[a] * edot(2 * k + a) + ldot * wd[a] * e(2 * k + a);
        nodal += d1[a] * edot(2 * k + a);
      }
      EXPECT_NEAR(rate, 0, 1e-14) << "element " << k << " xi " << xi;
      if (xi == 0.5) EXPECT_GT(std::abs(nodal), 0.1 * std::abs(kLdot / kL));
    }
  }
}

}  // namespace
}  // namespace cablesim
