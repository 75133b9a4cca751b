#ifndef CABLESIM_ENGINE_FORCES_ELEMENT_DISSIPATION_TERM_H_
#define CABLESIM_ENGINE_FORCES_ELEMENT_DISSIPATION_TERM_H_

// An ElementTerm whose dissipation is one template over the dimension:
// Derived defines
//   template <int D> double Dissipation(const ElementAt<D>&, const ElementCoords<D>& e,
//       const ElementCoords<D>& edot, ElementCoords<D>* force, ElementMatrix<D>* c) const;
// and this base forwards both of ElementTerm's (virtual, so per dimension)
// AddElementDissipation to it.

#include "engine/forces/force_contributor.h"

namespace cablesim {

template <class Derived>
class ElementDissipationTerm : public ElementTerm {
 public:
  bool dissipates() const override { return true; }
  double AddElementDissipation(const ElementAt<2>& at, const ElementCoords<2>& e,
                               const ElementCoords<2>& edot, ElementCoords<2>* force,
                               ElementMatrix<2>* c) const override {
    return static_cast<const Derived*>(this)->template Dissipation<2>(at, e, edot, force, c);
  }
  double AddElementDissipation(const ElementAt<3>& at, const ElementCoords<3>& e,
                               const ElementCoords<3>& edot, ElementCoords<3>* force,
                               ElementMatrix<3>* c) const override {
    return static_cast<const Derived*>(this)->template Dissipation<3>(at, e, edot, force, c);
  }
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_ELEMENT_DISSIPATION_TERM_H_
