#include "engine/forces/cable_damping.h"

#include <utility>

namespace cablesim {

template <int D>
double CableDamping::Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e,
                         const ElementCoords<D>& edot, ElementCoords<D>* force,
                         ElementMatrix<D>* c) const {
  const Element& p = elements_[at.index];
  if (!p.any()) return 0;
  // Only the axial term acting: the force point by point, not as C edot
  // (Newton's residual-only iterations and the damping power need no C;
  // the others get C added straight into c, without a local copy).
  double power = 0;
  if (p.alpha_1_s == 0 &&
      at.element.AddAxialDampingForce(e, edot, p.axial_s, p.bending_s, force, &power)) {
    if (c) at.element.AddDampingMatrix(e, p.axial_s, p.bending_s, c);
    return power;
  }
  ElementMatrix<D> local = ElementMatrix<D>::Zero();
  if (p.axial_s != 0 || p.bending_s != 0)
    at.element.AddDampingMatrix(e, p.axial_s, p.bending_s, &local);
  if (p.alpha_1_s != 0) local += p.alpha_1_s * at.element.MassMatrix(p.mass_per_length);
  const ElementCoords<D> f = local * edot;
  *force -= f;
  if (c) *c += local;
  return edot.dot(f);
}

template <int D>
void CableDamping::AddMaterialForce(const ElementAt<D>& at, const ElementCoords<D>& e,
                                    const ElementCoords<D>& edot, ElementCoords<D>* force) const {
  const Element& p = elements_[at.index];
  if (p.axial_s == 0 && p.bending_s == 0) return;
  double power = 0;
  if (at.element.AddAxialDampingForce(e, edot, p.axial_s, p.bending_s, force, &power)) return;
  ElementMatrix<D> c = ElementMatrix<D>::Zero();
  at.element.AddDampingMatrix(e, p.axial_s, p.bending_s, &c);
  *force -= c * edot;
}

template void CableDamping::AddMaterialForce<2>(const ElementAt<2>&, const ElementCoords<2>&,
                                                const ElementCoords<2>&, ElementCoords<2>*) const;
template void CableDamping::AddMaterialForce<3>(const ElementAt<3>&, const ElementCoords<3>&,
                                                const ElementCoords<3>&, ElementCoords<3>*) const;

template double CableDamping::Dissipation<2>(const ElementAt<2>&, const ElementCoords<2>&,
                                     const ElementCoords<2>&, ElementCoords<2>*,
                                     ElementMatrix<2>*) const;
template double CableDamping::Dissipation<3>(const ElementAt<3>&, const ElementCoords<3>&,
                                     const ElementCoords<3>&, ElementCoords<3>*,
                                     ElementMatrix<3>*) const;

std::unique_ptr<CableDamping> MakeCableDamping(std::vector<CableDamping::Element> elements) {
  for (const CableDamping::Element& e : elements)
    if (e.any()) return std::make_unique<CableDamping>(std::move(elements));
  return nullptr;
}

}  // namespace cablesim
