#ifndef CABLESIM_ENGINE_FORCES_WAVES_H_
#define CABLESIM_ENGINE_FORCES_WAVES_H_

// Linear (Airy) wave kinematics at finite depth: the fluid velocity and
// acceleration under a sum of regular wave components (Dean and Dalrymple,
// Water Wave Mechanics for Engineers and Scientists, 1991, ch. 3-4).
//
// Geometry: `up` is the unit vertical (the opposite of gravity), the still
// water level is up . r = surface, the bed is at depth h below it. A point
// r has elevation z = up . r - surface in [-h, 0] (points above the still
// level are evaluated at z = 0, points below the bed at z = -h: no
// stretching). Each component i has amplitude a_i [m], angular frequency
// omega_i [rad/s], wavenumber k_i from the dispersion relation
//
//   omega^2 = g k tanh(k h)                               (Dean eq. 4.22)
//
// solved by Newton to a relative residual below 1e-10, a horizontal unit
// direction d_i and a phase phi_i; with theta = k d . x - omega t + phi
// (x the horizontal position),
//
//   eta  = a cos(theta)
//   u_h  = a omega cosh(k (z + h)) / sinh(k h) cos(theta) d
//   u_z  = a omega sinh(k (z + h)) / sinh(k h) sin(theta) up
//   du/dt: the time derivative at the fixed point, a omega^2 (...) sin and
//          -a omega^2 (...) cos.                           (Dean eq. 4.13)
//
// A ramp-in over T_r multiplies everything by R(t) = (1 - cos(pi t / T_r)) / 2
// for t < T_r (and adds R'(t) u to the acceleration).
//
// Irregular seas: JONSWAP (Hasselmann et al. 1973; DNV-RP-C205 eq. 3.5.5)
//
//   S(omega) = alpha g^2 omega^-5 exp(-5/4 (omega_p / omega)^4) gamma^r,
//   r = exp(-(omega - omega_p)^2 / (2 sigma^2 omega_p^2)),
//   sigma = 0.07 (omega <= omega_p), 0.09 (above),
//
// with alpha scaled so that 4 sqrt(m0) = Hs over the components; N
// components at the midpoints of equal bins over [0.5, 3.5] omega_p, each of
// amplitude sqrt(2 S(omega_i) d omega) and a phase uniform in [0, 2 pi)
// from a seeded 64-bit Mersenne twister (std::mt19937_64, whose output is
// fixed by the C++ standard, so a seed gives the same sea everywhere).
//
// User-supplied seas:
//
// - components given one by one (AddComponent: amplitude, angular
//   frequency, direction, phase; MoorDyn's wave_frequencies.txt), each
//   evaluated by the formulas above;
// - an elevation time series eta(t_j) at the origin's horizontal position
//   (AddElevationSeries; MoorDyn's wave_elevation.txt), taken as one period
//   of a periodic sea of period T = t_last - t_0: resampled by linear
//   interpolation at N = max(2, round(T / interval)) equal steps
//   dt = T / N, transformed by the discrete Fourier transform
//   X_m = sum_j x_j exp(-2 pi i m j / N) (Eigen's FFT), and written back as
//   the sum of its real harmonics
//
//     eta(t) = X_0 / N + sum_{0 < m < N/2} (2 |X_m| / N) cos(omega_m (t - t_0) + arg X_m)
//              [+ (|X_{N/2}| / N) cos(omega_{N/2} (t - t_0) + arg X_{N/2}) for N even],
//     omega_m = 2 pi m / T,
//
//   which passes through every resampled point (the inverse transform);
//   each harmonic up to the cutoff frequency becomes a component travelling
//   along the series' direction (phase omega_m t_0 - arg X_m, so that its
//   elevation at the origin is the harmonic's), its kinematics by linear
//   theory as any other component; X_0 / N, the series' mean, raises the
//   surface everywhere (no velocity). Harmonics below 1e-12 of the largest
//   amplitude (round-off of the transform) are left out.
//
// Units SI.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace cablesim {

class WaveField {
 public:
  struct Component {
    double amplitude_m = 0;
    double omega_rad_s = 0;
    double wavenumber_1_m = 0;
    Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // horizontal, unit
    double phase_rad = 0;
    // exp(-2 k h) for the field's depth h, set when the component is added
    // (At's deep-water-safe cosh and sinh ratios use it at every point).
    double depth_decay = 0;
  };
  struct Kinematics {
    Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
    Eigen::Vector3d acceleration_m_s2 = Eigen::Vector3d::Zero();
    double elevation_m = 0;  // of the surface above the point's (x, y)
  };

  // The wavenumber k [1/m] of angular frequency omega [rad/s] in water of
  // depth h [m] under gravity g [m/s^2]: omega^2 = g k tanh(k h), by Newton
  // from the deep-water value, to a relative residual below 1e-10.
  static double Wavenumber(double omega, double depth, double g);

  // The JONSWAP spectral density [m^2 s] without its alpha scaling (alpha =
  // 1), peak angular frequency omega_p, peak factor gamma.
  static double JonswapShape(double omega, double omega_p, double gamma, double g);

  // `up` the unit vertical, `surface` the still water level along it [m],
  // `depth` h [m], `g` [m/s^2], `ramp_s` T_r (0: none).
  WaveField(const Eigen::Vector3d& up, double surface, double depth, double g, double ramp_s);

  // A regular wave of height H = 2 a [m], period [s], horizontal direction
  // (projected onto the horizontal plane and normalised) and phase [rad].
  void AddRegular(double height_m, double period_s, const Eigen::Vector3d& direction,
                  double phase_rad);

  // A JONSWAP sea of significant height Hs [m], peak period Tp [s], peak
  // factor gamma (3.3 typical), along `direction`, from `components`
  // components and `seed`.
  void AddJonswap(double hs_m, double tp_s, double gamma, const Eigen::Vector3d& direction,
                  int components, uint64_t seed);

  // One component: amplitude a [m] (>= 0), angular frequency omega
  // [rad/s] (> 0), horizontal direction (as AddRegular) and phase [rad]
  // (the elevation at the origin at t = 0 is a cos(phase)).
  void AddComponent(double amplitude_m, double omega_rad_s, const Eigen::Vector3d& direction,
                    double phase_rad);

  // A sea from the elevations [m] at times [s] (strictly increasing, at
  // least 2) at the origin, as the header says: resampled at about
  // `interval_s` (0: the series' mean interval), harmonics above
  // `cutoff_rad_s` (0: none) dropped, travelling along `direction`.
  // Returns the number of components added.
  int AddElevationSeries(const std::vector<double>& times_s,
                         const std::vector<double>& elevations_m, double interval_s,
                         double cutoff_rad_s, const Eigen::Vector3d& direction);

  const std::vector<Component>& components() const { return components_; }
  // The surface's mean elevation above the still level from elevation
  // series [m] (0 without).
  double mean_elevation() const { return mean_elevation_m_; }
  // The unit vertical and the still water level along it [m].
  const Eigen::Vector3d& up() const { return up_; }
  double surface() const { return surface_; }

  // The kinematics at point r [m] and time t [s]. Allocates nothing.
  Kinematics At(const Eigen::Vector3d& r, double t) const;

  // At(r, t).elevation_m alone, to the bit, without the velocities and
  // accelerations (one cosine per component instead of a cosine, a sine
  // and two exponentials): the free surface's wet test and the buoyancy
  // need only the elevation.
  double ElevationAt(const Eigen::Vector3d& r, double t) const;

 private:
  Eigen::Vector3d Horizontal(const Eigen::Vector3d& direction) const;
  // The ramp-in factor r(t) = (1 - cos(pi t / ramp_s)) / 2 over the first
  // ramp_s seconds (1 after, or without a ramp) into `ramp` and its rate
  // [1/s] into `rate` (may be null); false at t <= 0 inside a ramp: no
  // waves yet.
  bool Ramp(double t, double* ramp, double* rate) const;

  Eigen::Vector3d up_;
  double surface_ = 0, depth_ = 0, g_ = 9.81, ramp_s_ = 0;
  double mean_elevation_m_ = 0;
  std::vector<Component> components_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_WAVES_H_
