#ifndef CABLESIM_ENGINE_FORCES_CABLE_FLUID_LOAD_H_
#define CABLESIM_ENGINE_FORCES_CABLE_FLUID_LOAD_H_

// The fluid's load on the cables as an ElementTerm: Morison drag on the
// velocity relative to a uniform current (AncfCableElement::AddDrag) or,
// in a scene with waves, relative to current plus waves, with the flow's
// inertia (Froude-Krylov plus added mass) joining the force (WaveLoad,
// evaluated at the time the model passes). The drag's velocity derivative
// goes into C (symmetric positive semi-definite); the inertia does not
// depend on the rates. A current or waves may make the dissipated power
// negative (the flow then does work on the cable).
//
// Tip loads (Hydrodynamics.start_tip, end_tip: MoorDyn's rod of zero
// length, whose two ends' loads act at one point along the direction the
// lines' bending balances; Hall, MoorDyn v2 Rod.cpp, end effects): at an
// element's first (xi = 0) or last (xi = 1) node, position r, velocity v,
// unit tangent t = r_x / |r_x|, the flow u (current and waves at r) and
// its acceleration du/dt (waves only),
//
//   f = k |w| w t + m (du/dt . t) t   [N],  w = (u - v) . t,
//
// k = rho C_d A / 2 [kg/m] and m the tip's added mass [kg], on the node's
// position coordinates, while r is under the surface (FreeSurface::Wet at
// r). -df/dv = 2 k |w| t t^T joins C (symmetric positive semi-definite);
// the derivatives through t and u(r) are left out, as for the line's drag.
// The tip's added mass on the node's own acceleration is CableAddedMass's.

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/element_dissipation_term.h"
#include "engine/forces/current_profile.h"
#include "engine/forces/force_contributor.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/wave_load.h"

namespace cablesim {

class CableFluidLoad : public ElementDissipationTerm<CableFluidLoad> {
 public:
  struct Element {
    double drag_n = 0, drag_t = 0;  // AddDrag's kn, kt [kg/m^2]
    // With waves: the flow's inertia factors (1 + C_a) rho A across the
    // line and (1 + C_a,ax) rho A along it [kg/m] (WaveLoad).
    double fluid_inertia = 0, fluid_inertia_axial = 0;
    // Tip loads at the element's first [0] and last [1] node: k [kg/m]
    // and (with waves) the added mass m [kg] the flow's acceleration acts
    // on.
    double tip_drag[2] = {0, 0};
    double tip_inertia[2] = {0, 0};
    bool distributed() const {
      return drag_n != 0 || drag_t != 0 || fluid_inertia != 0 || fluid_inertia_axial != 0;
    }
    bool tips() const {
      return tip_drag[0] != 0 || tip_drag[1] != 0 || tip_inertia[0] != 0 || tip_inertia[1] != 0;
    }
    bool any() const { return distributed() || tips(); }
  };
  // Per element of the model, in its order; `waves` the scene's wave load
  // (null: none, then `current` [m/s] is the flow, and `surface` where the
  // fluid ends: with it enabled, only the Gauss points under the still
  // level get drag, engine/forces/free_surface.h).
  // `profile` (not empty): the current by depth in place of `current`.
  CableFluidLoad(std::vector<Element> elements, std::shared_ptr<const WaveLoad> waves,
                 const Eigen::Vector3d& current, const FreeSurface& surface = {},
                 CurrentProfile profile = {})
      : elements_(std::move(elements)),
        waves_(std::move(waves)),
        current_(current),
        surface_(surface),
        profile_(std::move(profile)) {}

  std::string_view name() const override { return "cable_fluid_load"; }
  bool has_potential() const override { return false; }
  bool DissipatesOn(int index) const override { return elements_[index].any(); }

 private:
  friend class ElementDissipationTerm<CableFluidLoad>;
  template <int D>
  double Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e, const ElementCoords<D>& edot,
             ElementCoords<D>* force, ElementMatrix<D>* c) const;

  // The tip loads of element `at` (see the header comment).
  template <int D>
  void AddTips(const ElementAt<D>& at, const ElementCoords<D>& e, const ElementCoords<D>& edot,
               ElementCoords<D>* force, ElementMatrix<D>* c) const;

  std::vector<Element> elements_;
  std::shared_ptr<const WaveLoad> waves_;
  Eigen::Vector3d current_;
  FreeSurface surface_;
  CurrentProfile profile_;
};

// The scene's fluid load on its cables; null when no element has drag or
// (with waves) flow inertia.
std::unique_ptr<CableFluidLoad> MakeCableFluidLoad(std::vector<CableFluidLoad::Element> elements,
                                                   std::shared_ptr<const WaveLoad> waves,
                                                   const Eigen::Vector3d& current,
                                                   const FreeSurface& surface = {},
                                                   CurrentProfile profile = {});

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CABLE_FLUID_LOAD_H_
