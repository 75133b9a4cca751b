// User-supplied water kinematics (engine/forces/waves.h, current_profile.h)
// against independent references: an elevation series of sinusoids gives
// back the Regular waves' kinematics (the closed-form Airy formulas of
// waves_test.cc), one given component is the Regular wave of the same
// amplitude and period, and a current grid holding an analytic field is
// interpolated to it between its nodes.

#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "engine/forces/current_profile.h"
#include "engine/forces/waves.h"

namespace cablesim {
namespace {

constexpr double kG = 9.81;
constexpr double kPi = std::numbers::pi;
using Eigen::Vector3d;

// The largest difference of the kinematics of two fields over points at
// the surface, mid-depth and near the bed, along and across the waves, and
// over two periods.
double MaxDifference(const WaveField& a, const WaveField& b, double depth, double period) {
  double worst = 0;
  for (double x : {-37.0, 0.0, 12.5, 80.0})
    for (double y : {0.0, 9.0})
      for (double z : {0.0, -0.3 * depth, -0.95 * depth})
        for (int i = 0; i <= 40; ++i) {
          const double t = 3.7 + i * period / 20;
          const Vector3d r(x, y, z);
          const WaveField::Kinematics ka = a.At(r, t), kb = b.At(r, t);
          worst = std::max({worst, (ka.velocity_m_s - kb.velocity_m_s).norm(),
                            (ka.acceleration_m_s2 - kb.acceleration_m_s2).norm(),
                            std::abs(ka.elevation_m - kb.elevation_m)});
        }
  return worst;
}

// An elevation series sampling a Regular wave of height H, period T and
// phase phi at the origin, eta(t) = H/2 cos(phi - omega t), 32 times over
// one period (both ends included), decomposed by the FFT: the one harmonic
// it holds is that wave, so the velocities, accelerations and elevations
// agree everywhere to round-off. Tolerance 1e-9 of the acceleration's scale
// a omega^2 / tanh(k h) (about 0.5 m/s^2 here): the transform of 32 exact
// samples of one harmonic carries round-off near 1e-15 per sample, and
// harmonics below 1e-12 of the largest are left out, so 1e-9 leaves room
// for both and still fails on a wrong phase, frequency or sign (which err
// by the scale itself).
TEST(UserWaveKinematicsTest, ElevationSeriesOfOneSinusoidIsTheRegularWave) {
  const double depth = 40, height = 3, period = 9, phase = 0.7;
  for (double t0 : {0.0, 5.3}) {
    WaveField regular(Vector3d::UnitZ(), 0, depth, kG, 0);
    regular.AddRegular(height, period, Vector3d(1, 1, 0), phase);
    const double w = 2 * kPi / period;
    std::vector<double> times, elevations;
    for (int j = 0; j <= 32; ++j) {
      const double t = t0 + j * period / 32;
      times.push_back(t);
      elevations.push_back(0.5 * height * std::cos(phase - w * t));
    }
    WaveField series(Vector3d::UnitZ(), 0, depth, kG, 0);
    EXPECT_EQ(series.AddElevationSeries(times, elevations, 0, 0, Vector3d(1, 1, 0)), 1);
    EXPECT_NEAR(series.mean_elevation(), 0, 1e-14);
    ASSERT_EQ(series.components().size(), 1u);
    EXPECT_NEAR(series.components()[0].omega_rad_s, w, 1e-14 * w);
    EXPECT_NEAR(series.components()[0].amplitude_m, 0.5 * height, 1e-13);
    const double k = regular.components()[0].wavenumber_1_m;
    const double scale = 0.5 * height * w * w / std::tanh(k * depth);
    EXPECT_LT(MaxDifference(series, regular, depth, period), 1e-9 * scale) << "t0 " << t0;
  }
}

// Two harmonics (the first and the third of the period) and a mean level:
// both components come back with their amplitudes and phases, the mean
// raises the elevation only; a cutoff between them keeps the first alone.
// Resampling: the series is given every T/64 and resampled every T/32
// (interval), which the linear interpolation does exactly at those times.
// Tolerances as above.
TEST(UserWaveKinematicsTest, ElevationSeriesHarmonicsMeanAndCutoff) {
  const double depth = 25, period = 12, mean = 0.4;
  const double w1 = 2 * kPi / period, w3 = 3 * w1;
  std::vector<double> times, elevations;
  for (int j = 0; j <= 64; ++j) {
    const double t = j * period / 64;
    times.push_back(t);
    elevations.push_back(mean + 1.0 * std::cos(0.3 - w1 * t) + 0.25 * std::cos(-1.1 - w3 * t));
  }
  WaveField reference(Vector3d::UnitZ(), 0, depth, kG, 0);
  reference.AddRegular(2.0, period, Vector3d::UnitX(), 0.3);
  reference.AddRegular(0.5, period / 3, Vector3d::UnitX(), -1.1);
  WaveField series(Vector3d::UnitZ(), 0, depth, kG, 0);
  EXPECT_EQ(series.AddElevationSeries(times, elevations, period / 32, 0, Vector3d::UnitX()), 2);
  EXPECT_NEAR(series.mean_elevation(), mean, 1e-13);
  // The velocities and accelerations are the two waves'; the elevation
  // is theirs plus the mean.
  const Vector3d r(7, 0, -6);
  for (double t : {0.0, 1.3, 8.9}) {
    const WaveField::Kinematics a = series.At(r, t), b = reference.At(r, t);
    EXPECT_LT((a.velocity_m_s - b.velocity_m_s).norm(), 1e-9);
    EXPECT_LT((a.acceleration_m_s2 - b.acceleration_m_s2).norm(), 1e-9);
    EXPECT_NEAR(a.elevation_m, b.elevation_m + mean, 1e-9);
  }
  WaveField cut(Vector3d::UnitZ(), 0, depth, kG, 0);
  EXPECT_EQ(cut.AddElevationSeries(times, elevations, 0, 2 * w1, Vector3d::UnitX()), 1);
  EXPECT_NEAR(cut.components()[0].omega_rad_s, w1, 1e-14);
}

// A component given by amplitude and angular frequency is the Regular
// wave of height 2a and period 2 pi / omega: identical kinematics (the
// same formulas, so exactly, to the last bit of the period's round trip).
TEST(UserWaveKinematicsTest, ComponentIsTheRegularWave) {
  WaveField regular(Vector3d::UnitZ(), 0, 60, kG, 0), component(Vector3d::UnitZ(), 0, 60, kG, 0);
  regular.AddRegular(2.4, 7.5, Vector3d(0.3, 1, 0), -0.4);
  component.AddComponent(1.2, 2 * kPi / 7.5, Vector3d(0.3, 1, 0), -0.4);
  EXPECT_LT(MaxDifference(regular, component, 60, 7.5), 1e-12);
}

// A grid holding a field linear in each coordinate separately (a
// multilinear field: products such as x t and y z included) is reproduced
// exactly between its nodes on uneven axes (round-off: 1e-12 of the field's
// size, about 10 m/s), and each coordinate beyond its axis is clamped to
// the axis's end (the value there).
TEST(UserWaveKinematicsTest, GridInterpolatesAMultilinearFieldExactly) {
  const std::vector<double> xs{-50, -20, 5, 40}, ys{-3, 2}, zs{-30, -12, -4, 0}, ts{0, 4, 15};
  auto field = [](double x, double y, double z, double t) {
    return Vector3d(1 + 0.02 * x - 0.3 * y + 0.05 * z + 0.1 * t + 0.001 * x * t,
                    -0.5 + 0.01 * y * z, 0.2 * x * y * z * t / 1e4);
  };
  std::vector<Vector3d> u;
  for (double x : xs)
    for (double y : ys)
      for (double z : zs)
        for (double t : ts) u.push_back(field(x, y, z, t));
  const CurrentProfile grid = CurrentProfile::Grid(xs, ys, zs, ts, u);
  ASSERT_FALSE(grid.empty());
  for (double x : {-44.0, -20.0, 0.3, 39.9})
    for (double y : {-2.5, 1.0})
      for (double z : {-29.0, -7.7, -0.1})
        for (double t : {0.0, 2.2, 9.0, 14.0})
          EXPECT_LT((grid.At(Vector3d(x, y, z), t) - field(x, y, z, t)).norm(), 1e-12)
              << x << " " << y << " " << z << " " << t;
  // Clamped: beyond x, y, z and after the last time.
  EXPECT_LT((grid.At(Vector3d(100, -9, -80), 30) - field(40, -3, -30, 15)).norm(), 1e-12);
  EXPECT_LT((grid.At(Vector3d(-90, 5, 3), -1) - field(-50, 2, 0, 0)).norm(), 1e-12);
}

// A smooth field that is not multilinear, u = sin(x / 10) cos(z / 7) at
// t-independent nodes every 2 m: linear interpolation errs by at most
// h^2 / 8 max|u''| per axis (the interpolation remainder), here
// (4 / 8)(1 / 100 + 1 / 49) = 0.0152; measured below it at every point,
// and above a tenth of it somewhere (so the bound is not vacuous).
TEST(UserWaveKinematicsTest, GridErrorOnASmoothFieldWithinTheInterpolationBound) {
  std::vector<double> xs, zs;
  for (int i = 0; i <= 30; ++i) xs.push_back(-30 + 2.0 * i);
  for (int i = 0; i <= 20; ++i) zs.push_back(-40 + 2.0 * i);
  auto f = [](double x, double z) { return std::sin(x / 10) * std::cos(z / 7); };
  std::vector<Vector3d> u;
  for (double x : xs)
    for (double z : zs) u.push_back(Vector3d(f(x, z), 0, 0));
  const CurrentProfile grid = CurrentProfile::Grid(xs, {0.0}, zs, {0.0}, u);
  const double bound = 4.0 / 8 * (1.0 / 100 + 1.0 / 49);
  double worst = 0;
  for (double x = -29.3; x < 30; x += 0.77)
    for (double z = -39.1; z < 0; z += 0.61) {
      const double e = std::abs(grid.At(Vector3d(x, 5, z), 3).x() - f(x, z));
      worst = std::max(worst, e);
      EXPECT_LE(e, bound) << x << " " << z;
    }
  EXPECT_GT(worst, 0.1 * bound);
}

}  // namespace
}  // namespace cablesim
