#ifndef CABLESIM_ENGINE_FORCES_SHEAVES_H_
#define CABLESIM_ENGINE_FORCES_SHEAVES_H_

// The scene's sheaves (engine/forces/sheave.h) as one ElementTerm: per
// element the wheels that may touch its cable (a sheave touches every
// element of the cables it lists), each adding its contact force, tangent
// and energy, and its damping and friction. A wheel carried by a body
// couples the element with the body's centre: its terms over [e; c] are
// scattered through ElementAt::coupled (as a slider's, AddLocalTerms) and
// its dissipated power goes to ElementAt::coupled_power.

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "engine/forces/force_contributor.h"
#include "engine/forces/sheave.h"
#include "engine/scene/scene.h"

namespace cablesim {

class Sheaves : public ElementTerm {
 public:
  // `wheels` and, per wheel, its body's first full coordinate (-1: a fixed
  // wheel); per element of the model the bit set of the wheels that touch
  // its cable.
  Sheaves(std::vector<Sheave> wheels, std::vector<int> centre_coord, std::vector<uint64_t> mask);

  std::string_view name() const override { return "sheaves"; }
  bool dissipates() const override { return dissipates_; }
  bool DissipatesOn(int index) const override { return dissipates_ && mask_[index] != 0; }
  const std::vector<Sheave>& wheels() const { return wheels_; }

  double AddElementPotential(const ElementAt<2>& at, const ElementCoords<2>& e,
                             ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                             ElementCoords<2>* roundoff) const override {
    return Potential<2>(at, e, gradient, hessian, roundoff);
  }
  double AddElementPotential(const ElementAt<3>& at, const ElementCoords<3>& e,
                             ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                             ElementCoords<3>* roundoff) const override {
    return Potential<3>(at, e, gradient, hessian, roundoff);
  }
  void AddElementEnergy(const ElementAt<2>& at, const ElementCoords<2>& e,
                        double* energy) const override {
    Energy<2>(at, e, energy);
  }
  void AddElementEnergy(const ElementAt<3>& at, const ElementCoords<3>& e,
                        double* energy) const override {
    Energy<3>(at, e, energy);
  }
  double AddElementDissipation(const ElementAt<2>& at, const ElementCoords<2>& e,
                               const ElementCoords<2>& edot, ElementCoords<2>* force,
                               ElementMatrix<2>* c) const override {
    return Dissipation<2>(at, e, edot, force, c);
  }
  double AddElementDissipation(const ElementAt<3>& at, const ElementCoords<3>& e,
                               const ElementCoords<3>& edot, ElementCoords<3>* force,
                               ElementMatrix<3>* c) const override {
    return Dissipation<3>(at, e, edot, force, c);
  }

 private:
  template <int D>
  double Potential(const ElementAt<D>& at, const ElementCoords<D>& e, ElementCoords<D>* gradient,
                   ElementMatrix<D>* hessian, ElementCoords<D>* roundoff) const;
  template <int D>
  void Energy(const ElementAt<D>& at, const ElementCoords<D>& e, double* energy) const;
  template <int D>
  double Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e,
                     const ElementCoords<D>& edot, ElementCoords<D>* force,
                     ElementMatrix<D>* c) const;

  std::vector<Sheave> wheels_;
  std::vector<int> centre_coord_;
  std::vector<uint64_t> mask_;
  bool dissipates_ = false;
};

// The scene's sheaves over the model's elements; `cable_element_begin[c]`
// cable c's first element (one more entry: the element count),
// `body_coord[b]` body b's first full coordinate. Null without sheaves.
std::unique_ptr<Sheaves> MakeSheaves(const Scene& scene, const std::vector<int>& cable_element_begin,
                                     const std::vector<int>& body_coord);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_SHEAVES_H_
