#include "engine/forces/cable_buoyancy.h"

#include <algorithm>
#include <utility>

#include "engine/elements/gauss_quadrature.h"

namespace cablesim {

template <int D>
void CableSurfaceBuoyancy<D>::AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
  constexpr int kN = 4 * D;
  if (!out->full) return;
  const WaveField* waves = use_waves_ ? s.waves : nullptr;
  bool wet[GaussRule::kMaxPoints];
  typename AncfCableElement<D>::Coords fe;
  for (const Element& el : elements_) {
    const auto e = s.q->template segment<kN>(el.first_coord);
    surface_.WetPoints<D>(el.element, e, waves, s.time, wet);
    // q = -rho_f A |g| up on the dry points [N/m], scaled with gravity.
    const typename AncfCableElement<D>::Point q =
        (-s.load_factor * el.buoyancy_n_m) * surface_.up.head<D>();
    fe.setZero();
    bool any = false;
    for (int g = 0; g < el.element.gauss_points(); ++g) {
      if (wet[g]) continue;
      el.element.AddLoadAtGaussPoint(g, q, &fe);
      any = true;
    }
    if (!any) continue;
    out->full->template segment<kN>(el.first_coord) += fe;
    out->size = std::max(out->size, fe.template lpNorm<Eigen::Infinity>());
  }
}

template <int D>
double CableSurfaceBuoyancy<D>::StoredEnergy(const ForceState& s) const {
  constexpr int kN = 4 * D;
  const WaveField* waves = use_waves_ ? s.waves : nullptr;
  double u = 0;
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  for (const Element& el : elements_) {
    const auto e = s.q->template segment<kN>(el.first_coord);
    for (int g = 0; g < el.element.gauss_points(); ++g) {
      r.head<D>() = el.element.GaussPosition(e, g);
      const double eta = waves ? waves->At(r, s.time).elevation_m : 0.0;
      // U = rho_f A |g| int max(h - eta, 0) dx.
      u += el.buoyancy_n_m * el.element.GaussLength(g) * std::max(surface_.Height(r) - eta, 0.0);
    }
  }
  return s.load_factor * u;
}

template <int D>
std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy(
    std::vector<typename CableSurfaceBuoyancy<D>::Element> elements, const FreeSurface& surface,
    bool use_waves) {
  if (!surface.enabled) return nullptr;
  bool any = false;
  for (const auto& e : elements) any = any || e.buoyancy_n_m != 0;
  if (!any) return nullptr;
  return std::make_unique<CableSurfaceBuoyancy<D>>(std::move(elements), surface, use_waves);
}

template class CableSurfaceBuoyancy<2>;
template class CableSurfaceBuoyancy<3>;
template std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy<2>(
    std::vector<CableSurfaceBuoyancy<2>::Element>, const FreeSurface&, bool);
template std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy<3>(
    std::vector<CableSurfaceBuoyancy<3>::Element>, const FreeSurface&, bool);

}  // namespace cablesim
