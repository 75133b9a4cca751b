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

  bool empty() const { return depths_.empty(); }

  // U at the point r [m/s].
  Eigen::Vector3d At(const Eigen::Vector3d& r) const {
    const double d = level_ - up_.dot(r);
    if (d <= depths_.front()) return velocities_.front();
    if (d >= depths_.back()) return velocities_.back();
    const size_t k = static_cast<size_t>(
        std::upper_bound(depths_.begin(), depths_.end(), d) - depths_.begin() - 1);
    const double w = (d - depths_[k]) / (depths_[k + 1] - depths_[k]);
    return velocities_[k] + w * (velocities_[k + 1] - velocities_[k]);
  }

 private:
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  double level_ = 0;
  std::vector<double> depths_;
  std::vector<Eigen::Vector3d> velocities_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CURRENT_PROFILE_H_
