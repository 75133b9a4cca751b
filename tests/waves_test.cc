// Airy wave kinematics (engine/forces/waves.h) against closed forms: the
// dispersion relation, the decay with depth, the time derivative, the
// continuity equation and the surface's kinematic condition; JONSWAP's
// significant height, peak and seed.

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "engine/forces/waves.h"

namespace cablesim {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = std::numbers::pi;
using Eigen::Vector3d;

// The dispersion relation holds to a relative residual of 1e-10 over deep,
// intermediate and shallow water, and k matches its limits: deep water
// k = omega^2 / g (tanh(k h) = 1 to 1e-16 once k h > 19), shallow water
// k = omega / sqrt(g h) (1 + (k h)^2 / 6 + O((k h)^4)), and an independent
// bisection to 1e-14.
TEST(WavesTest, DispersionRelationSolvedTo1e10) {
  for (double depth : {1.0, 5.0, 20.0, 100.0, 1000.0, 1e5}) {
    for (double period : {1.0, 4.0, 10.0, 20.0, 60.0}) {
      const double w = 2 * kPi / period;
      const double k = WaveField::Wavenumber(w, depth, kG);
      const double residual = (kG * k * std::tanh(k * depth) - w * w) / (w * w);
      EXPECT_LT(std::abs(residual), 1e-10) << depth << " " << period;
      double lo = 0, hi = 1e3;
      for (int i = 0; i < 200; ++i) {
        const double m = 0.5 * (lo + hi);
        (kG * m * std::tanh(m * depth) < w * w ? lo : hi) = m;
      }
      EXPECT_NEAR(k, 0.5 * (lo + hi), 1e-12 * k) << depth << " " << period;
      if (k * depth > 19) {
        EXPECT_NEAR(k, w * w / kG, 1e-14 * k);
      }
      if (k * depth < 0.05) {
        const double kh = k * depth;
        EXPECT_NEAR(k, w / std::sqrt(kG * depth) * (1 + kh * kh / 6), 0.1 * std::pow(kh, 4) * k);
      }
    }
  }
}

// Under a crest (theta = 0) the horizontal velocity is
// a omega cosh(k (z + h)) / sinh(k h) and decays with depth as
// cosh(k (z + h)) / cosh(k h); at a node (theta = pi / 2) the vertical
// one is a omega sinh(k (z + h)) / sinh(k h), 0 on the bed. To 1e-12.
TEST(WavesTest, VelocityDecaysWithDepthAsCosh) {
  const double depth = 30, a = 1.5, period = 9;
  WaveField field(Vector3d::UnitZ(), 0, depth, kG, 0);
  field.AddRegular(2 * a, period, Vector3d::UnitX(), 0);
  const double w = 2 * kPi / period, k = field.components()[0].wavenumber_1_m;
  const double top = field.At(Vector3d::Zero(), 0).velocity_m_s.x();
  EXPECT_NEAR(top, a * w / std::tanh(k * depth), 1e-12 * top);
  for (double z : {-1.0, -5.0, -15.0, -29.0, -30.0}) {
    const WaveField::Kinematics crest = field.At(Vector3d(0, 0, z), 0);
    EXPECT_NEAR(crest.velocity_m_s.x() / top, std::cosh(k * (z + depth)) / std::cosh(k * depth),
                1e-12)
        << z;
    EXPECT_NEAR(crest.velocity_m_s.z(), 0, 1e-12 * top);
    // theta = pi / 2 at x = pi / (2 k).
    const WaveField::Kinematics node = field.At(Vector3d(kPi / (2 * k), 0, z), 0);
    EXPECT_NEAR(node.velocity_m_s.z(), a * w * std::sinh(k * (z + depth)) / std::sinh(k * depth),
                1e-12 * top)
        << z;
  }
  // Deep water: exp(k z).
  WaveField deep(Vector3d::UnitZ(), 0, 5000, kG, 0);
  deep.AddRegular(2, 8, Vector3d::UnitX(), 0);
  const double kd = deep.components()[0].wavenumber_1_m;
  const double u0 = deep.At(Vector3d::Zero(), 0).velocity_m_s.x();
  EXPECT_NEAR(deep.At(Vector3d(0, 0, -20), 0).velocity_m_s.x() / u0, std::exp(-20 * kd), 1e-12);
}

// The acceleration is the time derivative of the velocity (central
// differences, error h^2 omega^3 a / 6 ~ 1e-7), the flow is divergence
// free (k^2 a omega-sized terms cancel; differences to 1e-7), and at the
// still level the vertical velocity is d eta / dt (linear kinematic
// condition). An oblique wave in a planar-style frame (up = y) checks the
// axes.
TEST(WavesTest, AccelerationContinuityAndSurfaceCondition) {
  WaveField field(Vector3d::UnitY(), 2, 40, kG, 0);
  field.AddRegular(3, 7, Vector3d(1, 0, 1), 0.3);
  field.AddRegular(1, 11, Vector3d(1, 0, -0.2), 1.1);
  const Vector3d r(3, -10, 4);
  const double t = 2.5, h = 1e-4;
  const auto k0 = field.At(r, t);
  const Vector3d dudt =
      (field.At(r, t + h).velocity_m_s - field.At(r, t - h).velocity_m_s) / (2 * h);
  EXPECT_LT((dudt - k0.acceleration_m_s2).norm(), 1e-6 * k0.acceleration_m_s2.norm());
  double div = 0;
  for (int d = 0; d < 3; ++d) {
    Vector3d e = Vector3d::Zero();
    e(d) = 1e-4;
    div += (field.At(r + e, t).velocity_m_s(d) - field.At(r - e, t).velocity_m_s(d)) / 2e-4;
  }
  EXPECT_NEAR(div, 0, 1e-6);
  const Vector3d surface(3, 2, 4);
  const double deta =
      (field.At(surface, t + h).elevation_m - field.At(surface, t - h).elevation_m) / (2 * h);
  EXPECT_NEAR(field.At(surface, t).velocity_m_s.y(), deta, 1e-6);
}

// JONSWAP: the components' variance gives Hs exactly (4 sqrt(sum a^2 / 2)),
// the largest amplitude sits at the bin nearest the peak, a seed gives the
// same phases and another seed others; the ramp starts the sea from rest.
TEST(WavesTest, JonswapSeaHasItsSignificantHeightAndSeed) {
  WaveField a(Vector3d::UnitZ(), 0, 200, kG, 20), b(Vector3d::UnitZ(), 0, 200, kG, 20),
      c(Vector3d::UnitZ(), 0, 200, kG, 20);
  a.AddJonswap(4, 10, 3.3, Vector3d::UnitX(), 100, 42);
  b.AddJonswap(4, 10, 3.3, Vector3d::UnitX(), 100, 42);
  c.AddJonswap(4, 10, 3.3, Vector3d::UnitX(), 100, 43);
  double m0 = 0, best = 0, best_w = 0;
  for (const auto& comp : a.components()) {
    m0 += comp.amplitude_m * comp.amplitude_m / 2;
    if (comp.amplitude_m > best) {
      best = comp.amplitude_m;
      best_w = comp.omega_rad_s;
    }
  }
  EXPECT_NEAR(4 * std::sqrt(m0), 4, 1e-12);
  const double wp = 2 * kPi / 10, dw = 3 * wp / 100;
  EXPECT_NEAR(best_w, wp, 0.5 * dw);
  int same = 0;
  for (size_t i = 0; i < a.components().size(); ++i) {
    EXPECT_EQ(a.components()[i].phase_rad, b.components()[i].phase_rad);
    if (a.components()[i].phase_rad == c.components()[i].phase_rad) ++same;
  }
  EXPECT_EQ(same, 0);
  const Vector3d r(10, 0, -5);
  EXPECT_EQ(a.At(r, 0).velocity_m_s.norm(), 0);
  // Past the ramp, the ramped field equals an unramped one.
  WaveField d(Vector3d::UnitZ(), 0, 200, kG, 0);
  d.AddJonswap(4, 10, 3.3, Vector3d::UnitX(), 100, 42);
  EXPECT_EQ(a.At(r, 25).velocity_m_s, d.At(r, 25).velocity_m_s);
  EXPECT_NEAR(a.At(r, 10).velocity_m_s.x(), 0.5 * d.At(r, 10).velocity_m_s.x(),
              1e-15 + 1e-12 * std::abs(d.At(r, 10).velocity_m_s.x()));
}

// ElevationAt is At's elevation to the bit (the free surface's wet test and
// the buoyancy call it instead of At), before, inside and after a ramp, in
// a sea of many components and of one, with a mean level from a series.
TEST(WavesTest, ElevationAtIsAtsElevationToTheBit) {
  WaveField sea(Vector3d::UnitZ(), 0, 200, kG, 20);
  sea.AddJonswap(6, 12, 3.3, Vector3d(1, 1, 0), 80, 7);
  sea.AddRegular(2, 7, Vector3d::UnitY(), 0.3);
  WaveField series(Vector3d::UnitZ(), 0, 30, kG, 0);
  series.AddElevationSeries({0, 1, 2, 3, 4, 5, 6, 7, 8}, {0.1, 0.5, 0.2, -0.3, 0.4, 0.0, -0.2, 0.3, 0.1},
                            1, 0, Vector3d::UnitX());
  ASSERT_NE(series.mean_elevation(), 0);
  int compared = 0;
  for (const WaveField* f : {&sea, &series})
    for (double t : {-1.0, 0.0, 0.5, 7.3, 19.99, 20.0, 41.7})
      for (const Vector3d& r : {Vector3d(0, 0, -10), Vector3d(130.5, -42.25, -199), Vector3d(-7, 3, 2)}) {
        EXPECT_EQ(f->ElevationAt(r, t), f->At(r, t).elevation_m) << t << " " << r.transpose();
        ++compared;
      }
  EXPECT_EQ(compared, 42);
  EXPECT_NE(sea.ElevationAt(Vector3d::Zero(), 7.3), 0);  // not all zero
}

// At evaluates its sines, cosines and exponentials a block at a time
// (glibc's vector math library on x86-64, within 4 ulp of each value).
// Against the same sums written out here with libm one component at a
// time: seas of 1, 2, 3, 5, 64, 65 and 100 components (every remainder of
// the 4- and 2-lane blocks and of At's 64-component block), at the
// surface, mid-depth, the bed and above the surface, and at times up to
// three hours (phases of 1e4 rad). The tolerance, 1e-13 of the sum of the
// terms' sizes, is far above four ulp per term and far below what a term
// taken from the wrong lane or component would give (the whole term).
TEST(WavesTest, BlockEvaluationAgreesWithLibmTermByTerm) {
  const double depth = 150;
  int compared = 0;
  for (int count : {1, 2, 3, 5, 64, 65, 100}) {
    WaveField sea(Vector3d::UnitZ(), 0, depth, kG, 0);
    sea.AddJonswap(3, 9, 3.3, Vector3d(1, 0.4, 0), count, 11);
    for (double t : {0.3, 61.7, 3600.0, 10799.9}) {
      for (const Vector3d& r : {Vector3d(0, 0, 0), Vector3d(412.5, -87.25, -61),
                                Vector3d(-1300, 640, -150), Vector3d(5, 5, 1.5)}) {
        const WaveField::Kinematics k = sea.At(r, t);
        Vector3d u = Vector3d::Zero(), a = Vector3d::Zero(), u_size = Vector3d::Zero(),
                 a_size = Vector3d::Zero();
        double eta = 0, eta_size = 0;
        const double z = std::clamp(r.z(), -depth, 0.0);
        for (const WaveField::Component& c : sea.components()) {
          const double kw = c.wavenumber_1_m, w = c.omega_rad_s;
          const double theta = kw * c.direction.dot(r) - w * t + c.phase_rad;
          const double ch = std::cosh(kw * (z + depth)) / std::sinh(kw * depth);
          const double sh = std::sinh(kw * (z + depth)) / std::sinh(kw * depth);
          const double aw = c.amplitude_m * w;
          eta += c.amplitude_m * std::cos(theta);
          eta_size += c.amplitude_m;
          u += aw * ch * std::cos(theta) * c.direction + aw * sh * std::sin(theta) * Vector3d::UnitZ();
          a += aw * w * ch * std::sin(theta) * c.direction -
               aw * w * sh * std::cos(theta) * Vector3d::UnitZ();
          u_size += aw * ch * c.direction.cwiseAbs() + aw * sh * Vector3d::UnitZ();
          a_size += aw * w * ch * c.direction.cwiseAbs() + aw * w * sh * Vector3d::UnitZ();
        }
        EXPECT_LE(std::abs(k.elevation_m - eta), 1e-13 * eta_size) << count << " " << t;
        for (int i = 0; i < 3; ++i) {
          EXPECT_LE(std::abs(k.velocity_m_s(i) - u(i)), 1e-13 * u_size(i) + 1e-300)
              << count << " " << t << " " << r.transpose() << " " << i;
          EXPECT_LE(std::abs(k.acceleration_m_s2(i) - a(i)), 1e-13 * a_size(i) + 1e-300)
              << count << " " << t << " " << r.transpose() << " " << i;
        }
        ++compared;
      }
    }
  }
  EXPECT_EQ(compared, 7 * 4 * 4);
}

}  // namespace
}  // namespace cablesim
