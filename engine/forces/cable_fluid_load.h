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
    bool any() const {
      return drag_n != 0 || drag_t != 0 || fluid_inertia != 0 || fluid_inertia_axial != 0;
    }
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
