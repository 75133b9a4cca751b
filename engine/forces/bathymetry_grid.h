#ifndef CABLESIM_ENGINE_FORCES_BATHYMETRY_GRID_H_
#define CABLESIM_ENGINE_FORCES_BATHYMETRY_GRID_H_

// A seabed given as depths on a regular grid, bilinear between the nodes
// (Seabed, engine/forces/seabed.h).
//
// The bed's normal n (a coordinate axis, sign s) points up into the water;
// the grid lies across it on the two other axes in x, y, z order (u, v):
// up = y gives (u, v) = (x, z), up = z gives (x, y). Nodes sit at
// u_i = u0 + i du, v_j = v0 + j dv (i < nu, j < nv) with depths d_ij [m]
// below the origin along n (row-major: d_ij = depths[j nu + i]). Inside a
// cell, with a = (u - u_i) / du, b = (v - v_j) / dv in [0, 1],
//
//   d(u, v) = (1-a)(1-b) d_ij + a (1-b) d_i+1,j + (1-a) b d_i,j+1 + a b d_i+1,j+1,
//
// and the bed is the surface s r_n = -d(u, v). Outside the grid the edge
// values continue unchanged (a and b clamped to [0, 1]; the slope across
// the edge is then zero); a single node along an axis (nu or nv = 1) makes
// the bed constant along it. The depth is continuous; its gradient jumps
// across the cell edges (the grid lines), where the contact cuts an
// element's integrals (Seabed).
//
// Units SI.

#include <vector>

#include "engine/scene/scene.h"

namespace cablesim {

class BathymetryGrid {
 public:
  // The depth and its derivatives at a point.
  struct Sample {
    double depth = 0;        // d [m]
    double du = 0, dv = 0;   // dd/du, dd/dv [-]
    double duv = 0;          // d^2 d / du dv [1/m] (dd/du^2 = dd/dv^2 = 0)
  };

  // `spec` valid (convert/ checks it); `up_axis` 0, 1 or 2 and `up_sign`
  // +-1: the bed's normal.
  BathymetryGrid(const BathymetrySpec& spec, int up_axis, double up_sign);

  int up_axis() const { return up_; }
  double up_sign() const { return sign_; }
  int u_axis() const { return iu_; }
  int v_axis() const { return iv_; }
  double min_depth() const { return min_depth_; }

  // The cell index along u (v) of a coordinate, -1 before the first grid
  // line and nu - 1 (nv - 1) after the last: consecutive indices differ by
  // one grid line crossed.
  int CellU(double u) const { return Cell(u, u0_, du_, nu_); }
  int CellV(double v) const { return Cell(v, v0_, dv_, nv_); }
  double LineU(int i) const { return u0_ + i * du_; }
  double LineV(int j) const { return v0_ + j * dv_; }

  Sample At(double u, double v) const;

 private:
  static int Cell(double x, double x0, double dx, int n);

  int up_ = 1, iu_ = 0, iv_ = 2;
  double sign_ = 1;
  double u0_ = 0, v0_ = 0, du_ = 1, dv_ = 1;
  int nu_ = 1, nv_ = 1;
  double min_depth_ = 0;
  std::vector<double> depths_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_BATHYMETRY_GRID_H_
