#include "engine/forces/cable_fluid_load.h"

#include <utility>

#include "engine/elements/gauss_quadrature.h"

namespace cablesim {

template <int D>
double CableFluidLoad::Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e,
                           const ElementCoords<D>& edot, ElementCoords<D>* force,
                           ElementMatrix<D>* c) const {
  const Element& p = elements_[at.index];
  if (!p.any()) return 0;
  const ElementCoords<D> before = *force;
  if (waves_) {
    waves_->Add<D>(at.element, e, edot, at.time, p.drag_n, p.drag_t, p.fluid_inertia,
                   p.fluid_inertia_axial, force, c);
  } else if (surface_.enabled || !profile_.empty()) {
    // The current (by depth, with a profile) at each Gauss point, on the
    // points under the still level only (with the free surface).
    using Point = typename AncfCableElement<D>::Point;
    Point velocity[GaussRule::kMaxPoints];
    bool wet[GaussRule::kMaxPoints];
    surface_.WetPoints<D>(at.element, e, nullptr, at.time, wet);
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (int g = 0; g < at.element.gauss_points(); ++g) {
      if (profile_.empty()) {
        velocity[g] = current_.head<D>();
      } else {
        r.head<D>() = at.element.GaussPosition(e, g);
        velocity[g] = profile_.At(r, at.time).template head<D>();
      }
    }
    at.element.AddMorison(e, edot, velocity, nullptr, p.drag_n, p.drag_t, 0, 0,
                          surface_.enabled ? wet : nullptr, force, c);
  } else {
    at.element.AddDrag(e, edot, current_.head<D>(), p.drag_n, p.drag_t, force, c);
  }
  return -edot.dot(*force - before);
}

template double CableFluidLoad::Dissipation<2>(const ElementAt<2>&, const ElementCoords<2>&,
                                       const ElementCoords<2>&, ElementCoords<2>*,
                                       ElementMatrix<2>*) const;
template double CableFluidLoad::Dissipation<3>(const ElementAt<3>&, const ElementCoords<3>&,
                                       const ElementCoords<3>&, ElementCoords<3>*,
                                       ElementMatrix<3>*) const;

std::unique_ptr<CableFluidLoad> MakeCableFluidLoad(std::vector<CableFluidLoad::Element> elements,
                                                   std::shared_ptr<const WaveLoad> waves,
                                                   const Eigen::Vector3d& current,
                                                   const FreeSurface& surface,
                                                   CurrentProfile profile) {
  for (const CableFluidLoad::Element& e : elements)
    if (e.any())
      return std::make_unique<CableFluidLoad>(std::move(elements), std::move(waves), current,
                                              surface, std::move(profile));
  return nullptr;
}

}  // namespace cablesim
