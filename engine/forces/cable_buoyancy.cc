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
void CableSurfaceBuoyancy<D>::SetTime(double t) {
  for (const Winch& w : winches_) {
    const double l = w.reel.At(t).length / (w.element_end - w.element_begin);
    for (int k = w.element_begin; k < w.element_end; ++k) elements_[k].element.set_length(l);
  }
}

template <int D>
double CableSurfaceBuoyancy<D>::ElementEnergy(const ForceState& s, const Element& el,
                                              const AncfCableElement<D>& element) const {
  constexpr int kN = 4 * D;
  const WaveField* waves = use_waves_ ? s.waves : nullptr;
  const auto e = s.q->template segment<kN>(el.first_coord);
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  double u = 0;
  for (int g = 0; g < element.gauss_points(); ++g) {
    r.head<D>() = element.GaussPosition(e, g);
    const double eta = waves ? waves->ElevationAt(r, s.time) : 0.0;
    // U = rho_f A |g| int max(h - eta, 0) dx.
    u += el.buoyancy_n_m * element.GaussLength(g) * std::max(surface_.Height(r) - eta, 0.0);
  }
  return u;
}

template <int D>
double CableSurfaceBuoyancy<D>::StoredEnergy(const ForceState& s) const {
  double u = 0;
  for (const Element& el : elements_) u += ElementEnergy(s, el, el.element);
  return s.load_factor * u;
}

template <int D>
void CableSurfaceBuoyancy<D>::AddExternalPower(const ForceState& s, double* power) const {
  for (const Winch& w : winches_) {
    const WinchReel::State now = w.reel.At(s.time);
    const int n = w.element_end - w.element_begin;
    const double l = now.length / n, ldot = now.rate / n, dl = 1e-4 * l;
    if (ldot == 0) continue;
    for (int k = w.element_begin; k < w.element_end; ++k) {
      const Element& el = elements_[k];
      AncfCableElement<D> element = el.element;
      auto energy = [&](double length) {
        element.set_length(length);
        return ElementEnergy(s, el, element);
      };
      // dU/dl by central differences at dl and dl / 2, extrapolated
      // (Richardson), as MultibodyModel::WinchPotentialRate does for the
      // elements' own energy; U is smooth in l but where a Gauss point
      // crosses the surface within dl (a kink, one step's error).
      auto difference = [&](double h) { return (energy(l + h) - energy(l - h)) / (2 * h); };
      *power += s.load_factor * ldot * (4 * difference(dl / 2) - difference(dl)) / 3;
    }
  }
}

template <int D>
std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy(
    std::vector<typename CableSurfaceBuoyancy<D>::Element> elements, const FreeSurface& surface,
    bool use_waves, std::vector<typename CableSurfaceBuoyancy<D>::Winch> winches) {
  if (!surface.enabled) return nullptr;
  bool any = false;
  for (const auto& e : elements) any = any || e.buoyancy_n_m != 0;
  if (!any) return nullptr;
  return std::make_unique<CableSurfaceBuoyancy<D>>(std::move(elements), surface, use_waves,
                                                   std::move(winches));
}

template class CableSurfaceBuoyancy<2>;
template class CableSurfaceBuoyancy<3>;
template std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy<2>(
    std::vector<CableSurfaceBuoyancy<2>::Element>, const FreeSurface&, bool,
    std::vector<CableSurfaceBuoyancy<2>::Winch>);
template std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy<3>(
    std::vector<CableSurfaceBuoyancy<3>::Element>, const FreeSurface&, bool,
    std::vector<CableSurfaceBuoyancy<3>::Winch>);

}  // namespace cablesim
