#ifndef CABLESIM_ENGINE_FORCES_WAVE_LOAD_H_
#define CABLESIM_ENGINE_FORCES_WAVE_LOAD_H_

// The Morison load of a fluid with waves on ANCF cable elements: drag on
// the velocity of the flow relative to the cable, and the flow's inertia
// (Morison, O'Brien, Johnson and Schaaf, "The force exerted by surface
// waves on piles", J. Petroleum Technology 2(5), 1950, eq. 1; the split
// across and along a slender line as in Hall and Goupee, "Validation of a
// lumped-mass mooring line model with DeepCwind semisubmersible model test
// data", Ocean Engineering 104, 2015, section 2).
//
// The flow at a point r and time t is the uniform current U (or the current
// by depth, engine/forces/current_profile.h) plus the wave
// kinematics of WaveField (engine/forces/waves.h): u(r, t) = U + u_w(r, t),
// du/dt = a_w(r, t). At each Gauss point x_g of an element, with the
// cable's position r = S(x_g) e, velocity rdot = S(x_g) edot, unit tangent
// t = r' / |r'| and the relative velocity v_r = u(r, t) - rdot split into
// v_t = (v_r . t) t and v_n = v_r - v_t, the force per unit undeformed
// length is
//
//   q = kn |v_n| v_n + kt |v_t| v_t + mi du/dt   [N/m]
//
// with kn = rho C_dn d / 2, kt = rho C_dt pi d / 2 [kg/m^2] (as
// AncfCableElement::AddDrag) and mi = (1 + C_a) rho A [kg/m], A = pi d^2 / 4
// the displaced area: the Froude-Krylov force rho A du/dt (the pressure
// gradient of the undisturbed wave) plus the added-mass force C_a rho A
// du/dt. The cable's own added mass C_a rho A joins its mass matrix in every
// direction (ModelBuilder: one coefficient, so the mass matrix stays
// constant), so with one coefficient the inertia term takes the whole
// vector du/dt with that same C_a: the relative-acceleration form
// C_a rho A (du/dt - rddot) in every direction, MoorDyn's line load with
// C_an = C_at = C_a. With an axial coefficient see below. Gauss quadrature
// (the element's rule, 5 points by default) integrates q.
//
// Above the still water level the kinematics are those at the level (z = 0)
// and below the bed those at the bed, as WaveField::At documents. Without
// the free surface the fluid of a scene fills all space (buoyancy and the
// current act on every cable, whatever its height); with it
// (engine/forces/free_surface.h) a Gauss point above the instantaneous
// level h >= eta(x, t) gets no drag and no inertia (the points between the
// still level and a crest keep the kinematics at z = 0: no stretching).
//
// Added mass along and across the line (MoorDyn's Ca and CaAx): the inertia
// factor splits into mi_n = (1 + C_a) rho A across the line and
// mi_t = (1 + C_a,ax) rho A along it, q_inertia = mi_n P du/dt +
// mi_t t t^T du/dt (P = I - t t^T); the cable's own added mass is then
// direction-dependent too (engine/forces/cable_added_mass.h).
//
// Tangent: -dQ/d(edot) is the drag's (AddDrag's formula, symmetric
// positive semi-definite). The derivatives in e (through t and through the
// flow's dependence on position, du/dr ~ k |u_w|, k the wavenumber) are
// left out, as for the current's drag: for waves long against the element
// their share of the Newton matrix is of order h k |u_w| / (1 + h C / M),
// and tests/wave_load_test.cc measures that a riser in waves takes the
// same Newton iterations per step as in still water.
//
// Energy: the load is not a potential's; its power -Q . edot is part of the
// damping power (MultibodyModel::DampingPower), so energy.damped counts the
// work the waves do on the cable (negative while they feed it energy) and
// energy.total + energy.damped stays what the exact solution conserves.
//
// Units SI. Allocates nothing. Used by MultibodyModel only when the scene's
// fluid has waves; a scene without keeps AddDrag's constant current.

#include <Eigen/Core>

#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/current_profile.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/waves.h"

namespace cablesim {

class WaveLoad {
 public:
  // `field` the waves, `current` the fluid's uniform current [m/s] (or,
  // when `profile` is not empty, the current by depth), `free_surface`
  // whether the fluid ends at the waves' surface.
  WaveLoad(WaveField field, const Eigen::Vector3d& current, bool free_surface = false,
           CurrentProfile profile = {});

  const WaveField& field() const { return field_; }
  // The surface the load ends at (disabled: none).
  const FreeSurface& surface() const { return surface_; }

  // For one element at coordinates e and rates edot at time t [s], with the
  // drag factors kn, kt [kg/m^2] and the inertia factors mi_n (across),
  // mi_t (along) [kg/m]: adds Q = int S^T q dx to `force` and, when `c` is
  // not null, -dQ/d(edot) to it.
  template <int D>
  void Add(const AncfCableElement<D>& element, const typename AncfCableElement<D>::Coords& e,
           const typename AncfCableElement<D>::Coords& edot, double t, double kn, double kt,
           double mi_n, double mi_t, typename AncfCableElement<D>::Coords* force,
           typename AncfCableElement<D>::Matrix* c) const;

 private:
  WaveField field_;
  Eigen::Vector3d current_;
  FreeSurface surface_;
  CurrentProfile profile_;
};

extern template void WaveLoad::Add<2>(const AncfCableElement<2>&,
                                      const AncfCableElement<2>::Coords&,
                                      const AncfCableElement<2>::Coords&, double, double, double,
                                      double, double, AncfCableElement<2>::Coords*,
                                      AncfCableElement<2>::Matrix*) const;
extern template void WaveLoad::Add<3>(const AncfCableElement<3>&,
                                      const AncfCableElement<3>::Coords&,
                                      const AncfCableElement<3>::Coords&, double, double, double,
                                      double, double, AncfCableElement<3>::Coords*,
                                      AncfCableElement<3>::Matrix*) const;

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_WAVE_LOAD_H_
