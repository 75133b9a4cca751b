#include "engine/forces/cable_added_mass.h"

#include <utility>

#include "engine/elements/gauss_quadrature.h"

namespace cablesim {

template <int D>
void CableAddedMass::PointMasses(const AncfCableElement<D>& element, const Element& p,
                                 const typename AncfCableElement<D>::Coords& e, double t_s,
                                 double* a_n, double* a_t) const {
  bool wet[GaussRule::kMaxPoints];
  surface_.WetPoints<D>(element, e, waves_, t_s, wet);
  for (int g = 0; g < element.gauss_points(); ++g) {
    // D = m_a - rho_f A C_a I, split across (a_n) and along (a_t) [kg/m].
    a_n[g] = wet[g] ? 0.0 : -p.displaced_kg_m * p.added_mass;
    a_t[g] = wet[g] ? p.displaced_kg_m * (p.axial_added_mass - p.added_mass)
                    : -p.displaced_kg_m * p.added_mass;
  }
}

namespace {

// The tip mass m t t^T at node `end` (0: first, 1: last) of an element at
// e, when under the surface: true and `tt` (D x D) set.
template <int D>
bool TipMass(const typename AncfCableElement<D>::Coords& e, int end, double mass,
             const FreeSurface& surface, const WaveField* waves, double t_s,
             Eigen::Matrix<double, D, D>* tt) {
  const int i = 2 * D * end;  // the node's position coordinates
  Eigen::Vector3d r = Eigen::Vector3d::Zero(), t = Eigen::Vector3d::Zero();
  r.head<D>() = e.template segment<D>(i);
  t.head<D>() = e.template segment<D>(i + D);
  const double stretch = t.norm();
  if (!(stretch > 0)) return false;
  t /= stretch;
  if (!surface.Wet(r, surface.enabled && waves ? waves->ElevationAt(r, t_s) : 0.0)) return false;
  const Eigen::Matrix3d tt3 = mass * t * t.transpose();
  *tt = tt3.topLeftCorner<D, D>();
  return true;
}

}  // namespace

template <int D>
void CableAddedMass::Add(const AncfCableElement<D>& element, int index,
                         const typename AncfCableElement<D>::Coords& e,
                         const typename AncfCableElement<D>::Coords& edd, double t_s,
                         typename AncfCableElement<D>::Coords* force,
                         typename AncfCableElement<D>::Matrix* m) const {
  const Element& p = elements_[index];
  if (!p.any(surface_.enabled)) return;
  for (int end = 0; end < 2; ++end) {
    if (p.tip_mass[end] == 0) continue;
    Eigen::Matrix<double, D, D> tt;
    if (!TipMass<D>(e, end, p.tip_mass[end], surface_, waves_, t_s, &tt)) continue;
    const int i = 2 * D * end;
    force->template segment<D>(i) -= tt * edd.template segment<D>(i);
    if (m != nullptr) m->template block<D, D>(i, i) += tt;
  }
  if (!p.distributed(surface_.enabled)) return;
  double a_n[GaussRule::kMaxPoints], a_t[GaussRule::kMaxPoints];
  PointMasses<D>(element, p, e, t_s, a_n, a_t);
  element.AddDirectionalMass(e, edd, a_n, a_t, force, m);
}

template <int D>
double CableAddedMass::KineticEnergy(const AncfCableElement<D>& element, int index,
                                     const typename AncfCableElement<D>::Coords& e,
                                     const typename AncfCableElement<D>::Coords& edot,
                                     double t_s) const {
  const Element& p = elements_[index];
  if (!p.any(surface_.enabled)) return 0;
  double energy = 0;
  for (int end = 0; end < 2; ++end) {
    if (p.tip_mass[end] == 0) continue;
    Eigen::Matrix<double, D, D> tt;
    if (!TipMass<D>(e, end, p.tip_mass[end], surface_, waves_, t_s, &tt)) continue;
    const auto v = edot.template segment<D>(2 * D * end);
    energy += 0.5 * v.dot(tt * v);
  }
  if (!p.distributed(surface_.enabled)) return energy;
  double a_n[GaussRule::kMaxPoints], a_t[GaussRule::kMaxPoints];
  PointMasses<D>(element, p, e, t_s, a_n, a_t);
  return energy + element.DirectionalKineticEnergy(e, edot, a_n, a_t);
}

template double CableAddedMass::KineticEnergy<2>(const AncfCableElement<2>&, int,
                                                 const AncfCableElement<2>::Coords&,
                                                 const AncfCableElement<2>::Coords&,
                                                 double) const;
template double CableAddedMass::KineticEnergy<3>(const AncfCableElement<3>&, int,
                                                 const AncfCableElement<3>::Coords&,
                                                 const AncfCableElement<3>::Coords&,
                                                 double) const;
template void CableAddedMass::Add<2>(const AncfCableElement<2>&, int,
                                     const AncfCableElement<2>::Coords&,
                                     const AncfCableElement<2>::Coords&, double,
                                     AncfCableElement<2>::Coords*,
                                     AncfCableElement<2>::Matrix*) const;
template void CableAddedMass::Add<3>(const AncfCableElement<3>&, int,
                                     const AncfCableElement<3>::Coords&,
                                     const AncfCableElement<3>::Coords&, double,
                                     AncfCableElement<3>::Coords*,
                                     AncfCableElement<3>::Matrix*) const;

std::unique_ptr<CableAddedMass> MakeCableAddedMass(std::vector<CableAddedMass::Element> elements,
                                                   const FreeSurface& surface,
                                                   const WaveField* waves) {
  for (const CableAddedMass::Element& e : elements)
    if (e.any(surface.enabled))
      return std::make_unique<CableAddedMass>(std::move(elements), surface, waves);
  return nullptr;
}

}  // namespace cablesim
