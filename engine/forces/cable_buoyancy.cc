#include "engine/forces/cable_buoyancy.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"
#include "engine/forces/element_cubic.h"

namespace cablesim {
namespace {

// A circular section of radius R whose centre is at height h above the
// level, u = h / R in [-1, 1]: its dry fraction (the area above the level
// over pi R^2), g(u) = (acos(-u) + u sqrt(1 - u^2)) / pi, and the
// integral of g from -1, G(u) = (u acos(-u) + sqrt(1 - u^2)
// - (1 - u^2)^(3/2) / 3) / pi (G(1) = 1).
double DryFraction(double u) {
  u = std::clamp(u, -1.0, 1.0);
  return (std::acos(-u) + u * std::sqrt(1 - u * u)) / std::numbers::pi;
}
double DryFractionIntegral(double u) {
  u = std::clamp(u, -1.0, 1.0);
  const double c = 1 - u * u;
  return (u * std::acos(-u) + std::sqrt(c) - c * std::sqrt(c) / 3) / std::numbers::pi;
}

}  // namespace

template <int D>
int CableSurfaceBuoyancy<D>::DryPoints(const Element& el, const AncfCableElement<D>& element,
                                       const Eigen::Matrix<double, 4 * D, 1>& e,
                                       DryPoint* points) const {
  const Eigen::Matrix<double, D, 1> up = surface_.up.head<D>();
  const double l = element.length(), r = el.radius_m;
  Eigen::Vector3d ra = Eigen::Vector3d::Zero(), rb = Eigen::Vector3d::Zero();
  ra.head<D>() = e.template segment<D>(0);
  rb.head<D>() = e.template segment<D>(2 * D);
  // The height h(xi) along the element.
  const ElementCubic h =
      ElementCubic::FromEnds(surface_.Height(ra), up.dot(e.template segment<D>(D)),
                             surface_.Height(rb), up.dot(e.template segment<D>(3 * D)), l);
  // Breaks of [0, 1] where the section starts to leave the water (h = -R)
  // and is wholly out of it (h = R).
  double cut[8];
  int cuts = 0;
  cut[cuts++] = 0;
  cuts += SignChanges(ElementCubic{{h.c[0] + r, h.c[1], h.c[2], h.c[3]}}, cut + cuts);
  if (r > 0) cuts += SignChanges(ElementCubic{{h.c[0] - r, h.c[1], h.c[2], h.c[3]}}, cut + cuts);
  cut[cuts++] = 1;
  // In order (insertion: at most 8 entries).
  for (int i = 1; i < cuts; ++i)
    for (int j = i; j > 0 && cut[j] < cut[j - 1]; --j) std::swap(cut[j], cut[j - 1]);
  static const GaussRule two = MakeGaussRule(2), band = MakeGaussRule(kBandPoints);
  int n = 0;
  for (int i = 0; i + 1 < cuts; ++i) {
    const double a = cut[i], b = cut[i + 1];
    if (!(b > a)) continue;
    const double mid = h(0.5 * (a + b));
    if (mid <= -r) continue;  // wet: nothing taken back
    // Wholly dry: g = 1, and two points integrate the cubic exactly; else
    // the section pierces the level along the whole piece.
    const bool dry = mid >= r;
    const GaussRule& rule = dry ? two : band;
    for (int g = 0; g < rule.n; ++g) {
      DryPoint& p = points[n++];
      p.xi = a + (b - a) * rule.xi[g];
      p.weight = (b - a) * rule.weight[g] * l;
      const double height = h(p.xi);
      if (dry) {
        p.fraction = 1;
        p.rate = 0;
        p.potential = height;
      } else {
        const double u = height / r;
        p.fraction = DryFraction(u);
        p.rate = 2 / (std::numbers::pi * r) * std::sqrt(std::max(0.0, 1 - u * u));
        p.potential = r * DryFractionIntegral(u);
      }
    }
  }
  return n;
}

template <int D>
bool CableSurfaceBuoyancy<D>::StaticElementLoad(const Element& el, const ForceState& s,
                                                typename AncfCableElement<D>::Coords* fe,
                                                typename AncfCableElement<D>::Matrix* ke) const {
  constexpr int kN = 4 * D;
  DryPoint points[kMaxDryPoints];
  const int n = DryPoints(el, el.element, s.q->template segment<kN>(el.first_coord), points);
  if (n == 0) return false;
  const double w = s.load_factor * el.buoyancy_n_m;
  const Eigen::Matrix<double, D, 1> up = surface_.up.head<D>();
  fe->setZero();
  if (ke) ke->setZero();
  double sh[4];
  for (int g = 0; g < n; ++g) {
    const DryPoint& p = points[g];
    HermiteShape(p.xi, el.element.length(), sh);
    for (int k = 0; k < 4; ++k)
      fe->template segment<D>(k * D) -= (p.weight * w * p.fraction * sh[k]) * up;
    // -dF/de = w g'(h) s s^T (x) up up^T: over a piercing section the
    // waterplane stiffness rho_f g A / |dh/dx| of the line there.
    if (ke && p.rate > 0)
      for (int j = 0; j < 4; ++j)
        for (int k = 0; k < 4; ++k)
          ke->template block<D, D>(j * D, k * D) +=
              (p.weight * w * p.rate * sh[j] * sh[k]) * up * up.transpose();
  }
  return true;
}

template <int D>
bool CableSurfaceBuoyancy<D>::StaticLoadOfElement(int k, const ForceState& s,
                                                  typename AncfCableElement<D>::Coords* fe) const {
  if (use_waves_ || k < 0 || k >= static_cast<int>(elements_.size())) return false;
  return StaticElementLoad(elements_[k], s, fe, nullptr);
}

template <int D>
void CableSurfaceBuoyancy<D>::AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
  constexpr int kN = 4 * D;
  if (!out->full) return;
  const WaveField* waves = use_waves_ ? s.waves : nullptr;
  bool wet[GaussRule::kMaxPoints];
  typename AncfCableElement<D>::Coords fe;
  typename AncfCableElement<D>::Matrix ke;
  for (const Element& el : elements_) {
    const auto e = s.q->template segment<kN>(el.first_coord);
    if (!use_waves_) {
      // STATIC (the still level): each section's dry fraction.
      if (!StaticElementLoad(el, s, &fe, out->matrix ? &ke : nullptr)) continue;
      out->full->template segment<kN>(el.first_coord) += fe;
      out->size = std::max(out->size, fe.template lpNorm<Eigen::Infinity>());
      if (out->matrix)
        out->map.ScatterRange(el.first_coord, kN, ke.data(), kN, out->scale, out->matrix);
      continue;
    }
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
  double u = 0;
  if (!use_waves_) {
    DryPoint points[kMaxDryPoints];
    const int n = DryPoints(el, element, e, points);
    for (int g = 0; g < n; ++g) u += el.buoyancy_n_m * points[g].weight * points[g].potential;
    return u;
  }
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
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
