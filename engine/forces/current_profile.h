#ifndef CABLESIM_ENGINE_FORCES_CURRENT_PROFILE_H_
#define CABLESIM_ENGINE_FORCES_CURRENT_PROFILE_H_

// A steady current that varies with depth (the scene's
// fluid.current_profile; MoorDyn's current-profile option): knots
// (d_k, U_k) of depth below the still water level d = level - up . r [m]
// and velocity [m/s], d_k strictly increasing, and
//
//   U(d) = U_k + (d - d_k) / (d_{k+1} - d_k) (U_{k+1} - U_k)   on [d_k, d_{k+1}],
//   U(d) = U_0 above d_0,  U(d) = U_last below d_last            [m/s],
//
// piecewise linear, as MoorDyn interpolates its profile. The cables' drag
// takes it at each Gauss point (CableFluidLoad, WaveLoad) in place of the
// uniform current; its derivative in the position (the shear dU/dd, which
// moves the drag as the line moves up or down) is left out of Newton's
// matrix as the waves' dependence on position is (wave_load.h).
//
// Or a current that varies in space and time (the scene's
// fluid.current_grid; MoorDyn's dynamic and 4D current files): velocities
// U_{abcd} at the nodes of a rectilinear grid over x_a, y_b, z_c (the
// scene's coordinates [m]) and times t_d [s], each axis strictly increasing
// (or a single value), and U(r, t) their multilinear interpolation over the
// cell holding (x, y, z, t), each coordinate clamped to its axis's range
// (constant beyond the grid and before the first and after the last time).
// A current profile changing in time is the grid with one x and one y.
// The current's own time derivative is not a load (as MoorDyn, whose
// dynamic currents carry no acceleration).
//
// Units SI. Allocates nothing in At.

#include <algorithm>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace cablesim {

class CurrentProfile {
 public:
  // None (empty()).
  CurrentProfile() = default;
  // `up` the unit vertical, `level` the still water level along it [m];
  // depths strictly increasing, as many velocities, at least one.
  CurrentProfile(const Eigen::Vector3d& up, double level, std::vector<double> depths,
                 std::vector<Eigen::Vector3d> velocities)
      : up_(up), level_(level), depths_(std::move(depths)), velocities_(std::move(velocities)) {}

  // A grid: the axes (each strictly increasing, at least one value) and
  // the velocities at index ((a ny + b) nz + c) nt + d.
  static CurrentProfile Grid(std::vector<double> x, std::vector<double> y, std::vector<double> z,
                             std::vector<double> t, std::vector<Eigen::Vector3d> velocities) {
    CurrentProfile p;
    p.axes_[0] = std::move(x);
    p.axes_[1] = std::move(y);
    p.axes_[2] = std::move(z);
    p.axes_[3] = std::move(t);
    p.velocities_ = std::move(velocities);
    return p;
  }

  bool empty() const { return depths_.empty() && axes_[0].empty(); }

  // U at the point r [m/s] and time t [s].
  Eigen::Vector3d At(const Eigen::Vector3d& r, double t = 0) const {
    if (depths_.empty()) return axes_[0].empty() ? Eigen::Vector3d::Zero() : GridAt(r, t);
    const double d = level_ - up_.dot(r);
    if (d <= depths_.front()) return velocities_.front();
    if (d >= depths_.back()) return velocities_.back();
    const size_t k = static_cast<size_t>(
        std::upper_bound(depths_.begin(), depths_.end(), d) - depths_.begin() - 1);
    const double w = (d - depths_[k]) / (depths_[k + 1] - depths_[k]);
    return velocities_[k] + w * (velocities_[k + 1] - velocities_[k]);
  }

 private:
  // Cell index and weight of the upper node along axis `a` at value v.
  void Locate(int a, double v, size_t* index, double* weight) const {
    const std::vector<double>& x = axes_[a];
    if (x.size() == 1 || v <= x.front()) {
      *index = 0;
      *weight = 0;
    } else if (v >= x.back()) {
      *index = x.size() - 2;
      *weight = 1;
    } else {
      *index = static_cast<size_t>(std::upper_bound(x.begin(), x.end(), v) - x.begin() - 1);
      *weight = (v - x[*index]) / (x[*index + 1] - x[*index]);
    }
  }

  Eigen::Vector3d GridAt(const Eigen::Vector3d& r, double t) const {
    const double v[4] = {r.x(), r.y(), r.z(), t};
    size_t index[4];
    double weight[4];
    size_t size[4];
    for (int a = 0; a < 4; ++a) {
      Locate(a, v[a], &index[a], &weight[a]);
      size[a] = axes_[a].size();
    }
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int corner = 0; corner < 16; ++corner) {
      double w = 1;
      size_t flat = 0;
      for (int a = 0; a < 4; ++a) {
        const bool upper = (corner >> a) & 1;
        if (upper && size[a] == 1) {
          w = 0;
          break;
        }
        w *= upper ? weight[a] : 1 - weight[a];
        flat = flat * size[a] + index[a] + (upper ? 1 : 0);
      }
      if (w != 0) u += w * velocities_[flat];
    }
    return u;
  }

  std::vector<double> axes_[4];  // x, y, z, t of a grid (empty: a profile)
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  double level_ = 0;
  std::vector<double> depths_;
  std::vector<Eigen::Vector3d> velocities_;  // by depth, or at the grid's nodes
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CURRENT_PROFILE_H_
