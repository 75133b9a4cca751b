#ifndef CABLESIM_ENGINE_FORCES_FREE_SURFACE_H_
#define CABLESIM_ENGINE_FORCES_FREE_SURFACE_H_

// Where the water ends (the scene's fluid.free_surface): a point r is wet
// when its height above the still water level, h = up . r - level [m], is
// below the surface's elevation eta above the same level [m] (the waves'
// elevation at the point's horizontal position and the time, 0 without
// waves): h < eta. Disabled, every point is wet (the fluid fills all
// space, as before the option).
//
// The loads that use it switch point by point (but a STATIC analysis's
// cable buoyancy, which takes each section's dry fraction:
// cable_buoyancy.h): at each Gauss point of an
// element the point is wet or dry by its own position, so an element that
// pierces the surface carries the load of its wet points only, and the
// force jumps by one point's share (w_g l times the load per length) when
// a point crosses. Newton tolerates that jump: the Jacobian each load hands
// the solver is exact on either side (the buoyancy's is zero on both), so
// an iteration that moves no point across the level converges as if the
// switch were not there, and one that does is followed by iterations on
// the new side; the error against an exact integral over the wet length is
// the quadrature's on a step function, at most one point's share per
// element, which mesh refinement shrinks as the element length.
//
// Units SI. Allocates nothing.

#include <Eigen/Core>

#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/waves.h"

namespace cablesim {

struct FreeSurface {
  bool enabled = false;
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit, against gravity
  double level_m = 0;                             // still water level along up

  // Height of r above the still level [m].
  double Height(const Eigen::Vector3d& r) const { return up.dot(r) - level_m; }
  // Whether r is under a surface at elevation eta [m] above the still level.
  bool Wet(const Eigen::Vector3d& r, double eta) const { return !enabled || Height(r) < eta; }

  // wet[g] for each Gauss point g of the element at e, time t [s], under
  // the surface of `waves` (null: the still level).
  template <int D>
  void WetPoints(const AncfCableElement<D>& element,
                 const typename AncfCableElement<D>::Coords& e, const WaveField* waves, double t,
                 bool* wet) const {
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (int g = 0; g < element.gauss_points(); ++g) {
      if (!enabled) {
        wet[g] = true;
        continue;
      }
      r.template head<D>() = element.GaussPosition(e, g);
      wet[g] = Wet(r, waves ? waves->ElevationAt(r, t) : 0.0);
    }
  }
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_FREE_SURFACE_H_
