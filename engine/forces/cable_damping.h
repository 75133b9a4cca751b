#ifndef CABLESIM_ENGINE_FORCES_CABLE_DAMPING_H_
#define CABLESIM_ENGINE_FORCES_CABLE_DAMPING_H_

// The cables' structural damping as an ElementTerm: per element
// Kelvin-Voigt damping (AncfCableElement::AddDampingMatrix, retardation
// times axial_s + beta and bending_s + beta) plus Rayleigh alpha times the
// element mass matrix. Q_d = -C(q) edot with C symmetric positive
// semi-definite; it dissipates edot^T C edot >= 0. The model adds C, not
// the derivative of C(q) edot in q (MultibodyModel::DampingForce).
//
// A winch cable's elements carry none: the winch damps the material motion
// instead (ClearMaterialDamping; WinchCables, forces/winch_cables.h).

#include <memory>
#include <string_view>
#include <vector>

#include "engine/forces/element_dissipation_term.h"
#include "engine/forces/force_contributor.h"

namespace cablesim {

class CableDamping : public ElementDissipationTerm<CableDamping> {
 public:
  struct Element {
    double axial_s = 0, bending_s = 0;  // Kelvin-Voigt times, Rayleigh beta included [s]
    double alpha_1_s = 0;               // Rayleigh alpha [1/s]
    double mass_per_length = 0;         // of the mass matrix alpha scales [kg/m]
    bool any() const { return axial_s != 0 || bending_s != 0 || alpha_1_s != 0; }
  };
  // Per element of the model, in its order.
  explicit CableDamping(std::vector<Element> elements) : elements_(std::move(elements)) {}

  std::string_view name() const override { return "cable_damping"; }
  bool has_potential() const override { return false; }
  bool DissipatesOn(int index) const override { return elements_[index].any(); }
  // The material (Kelvin-Voigt) part alone, -C edot with C of
  // AddDampingMatrix (axial_s and bending_s; Rayleigh alpha left out: it
  // acts on the mass, as a viscous medium would, not across a section),
  // added to `force` of element at.index: what the section force of the
  // tension outputs carries besides the elastic force
  // (MultibodyModel::Tensions).
  template <int D>
  void AddMaterialForce(const ElementAt<D>& at, const ElementCoords<D>& e,
                        const ElementCoords<D>& edot, ElementCoords<D>* force) const;
  // Removes element `index`'s axial and Rayleigh alpha damping (a winch
  // cable's, which the winch applies to the material motion instead).
  void ClearMaterialDamping(int index) {
    elements_[index].axial_s = 0;
    elements_[index].alpha_1_s = 0;
  }

 private:
  friend class ElementDissipationTerm<CableDamping>;
  template <int D>
  double Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e, const ElementCoords<D>& edot,
             ElementCoords<D>* force, ElementMatrix<D>* c) const;

  std::vector<Element> elements_;
};

// The scene's cable damping, given per element; null when no element is
// damped (the zero-cost rule).
std::unique_ptr<CableDamping> MakeCableDamping(std::vector<CableDamping::Element> elements);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CABLE_DAMPING_H_
