#include "engine/forces/bathymetry_grid.h"

#include <algorithm>
#include <cmath>

namespace cablesim {

BathymetryGrid::BathymetryGrid(const BathymetrySpec& spec, int up_axis, double up_sign)
    : up_(up_axis),
      sign_(up_sign),
      u0_(spec.origin_x_m),
      v0_(spec.origin_y_m),
      du_(spec.dx_m),
      dv_(spec.dy_m),
      nu_(spec.nx),
      nv_(spec.ny),
      depths_(spec.depths_m) {
  iu_ = up_ == 0 ? 1 : 0;
  iv_ = up_ == 2 ? 1 : 2;
  min_depth_ = depths_.empty() ? 0 : *std::min_element(depths_.begin(), depths_.end());
}

int BathymetryGrid::Cell(double x, double x0, double dx, int n) {
  if (n < 2) return 0;
  const double t = std::floor((x - x0) / dx);
  if (!(t >= 0)) return -1;
  if (t >= n - 1) return n - 1;
  return static_cast<int>(t);
}

BathymetryGrid::Sample BathymetryGrid::At(double u, double v) const {
  // Cell and local coordinate along one axis; `inside` false where the
  // coordinate is clamped (the slope along that axis is then zero).
  auto locate = [](double x, double x0, double dx, int n, int* i, double* a, bool* inside) {
    *i = 0;
    *a = 0;
    *inside = false;
    if (n < 2) return;
    const double t = (x - x0) / dx;
    if (!(t > 0)) return;  // also a NaN coordinate: the first cell, never an index from it
    if (t >= n - 1) {
      *i = n - 2;
      *a = 1;
      return;
    }
    *i = std::min(static_cast<int>(t), n - 2);
    *a = t - *i;
    *inside = true;
  };
  int i, j;
  double a, b;
  bool in_u, in_v;
  locate(u, u0_, du_, nu_, &i, &a, &in_u);
  locate(v, v0_, dv_, nv_, &j, &b, &in_v);
  const int i1 = nu_ < 2 ? i : i + 1, j1 = nv_ < 2 ? j : j + 1;
  const double d00 = depths_[j * nu_ + i], d10 = depths_[j * nu_ + i1];
  const double d01 = depths_[j1 * nu_ + i], d11 = depths_[j1 * nu_ + i1];
  Sample s;
  s.depth = (1 - a) * (1 - b) * d00 + a * (1 - b) * d10 + (1 - a) * b * d01 + a * b * d11;
  if (in_u) s.du = ((1 - b) * (d10 - d00) + b * (d11 - d01)) / du_;
  if (in_v) s.dv = ((1 - a) * (d01 - d00) + a * (d11 - d10)) / dv_;
  if (in_u && in_v) s.duv = (d11 - d10 - d01 + d00) / (du_ * dv_);
  return s;
}

}  // namespace cablesim
