#ifndef CABLESIM_ENGINE_FORCES_GRAVITY_LOADS_H_
#define CABLESIM_ENGINE_FORCES_GRAVITY_LOADS_H_

// Gravity and the loads' constant forces (MODEL.md section 4) as one
// ForceContributor: a constant generalized force F on the full
// coordinates, V = -F . q.
//
//  - a cable element's gravity is m [g/2, l g/12, g/2, -l g/12] per
//    component (AncfCableElement::GravityForce, m = (rho A - displaced
//    fluid per length) l: buoyancy is the displaced fluid's weight off
//    gravity), exactly -dV/de of its potential -Q_g . e;
//  - a body's is m g on its centre of mass;
//  - a constant force F at a point r = sum_i a_i q_i + c (linear in q)
//    does the work F . dr: sum_d F_d a_{d,i} on q_i.
//
// Summed once into one vector (in that order, so that the model's sums
// are those of the vector), scaled by the load factor (statics ramps
// them) and added first among the applied loads. On a winch cable
// (WinchReel) the elements' length L(t) / N changes, and with it their
// gravity: SetTime sums it again onto the vector without those elements.
//
// Its energy is in energy.potential; EnergyParts gets it per cable and per
// body (`gravity`) and the point loads' share in `loads` (AddEnergyParts).

#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/force_contributor.h"
#include "engine/forces/winch_inertia.h"
#include "engine/output/results.h"

namespace cablesim {

template <int D>
class GravityLoads : public ForceContributor {
 public:
  using Coords = Eigen::Matrix<double, 4 * D, 1>;
  // A cable element: its first full coordinate, its cable (scene order)
  // and the mass per length its gravity acts on [kg/m].
  struct Element {
    int first_coord = 0;
    int cable = 0;
    double weight_per_length = 0;
    double length = 0;  // [m]
  };
  struct Body {
    int coord = 0;  // full index of r_c
    double mass = 0;
  };
  // A winch cable's elements [element_begin, element_end) (indices into the
  // element list) and its reel.
  struct Winch {
    int element_begin = 0, element_end = 0;
    WinchReel reel;
  };

  // `load_terms`: the point loads' (full index, a_{d,i} F_d) in scene
  // order. `coordinates`: the size of q.
  GravityLoads(std::vector<Element> elements, std::vector<Body> bodies,
               const std::vector<std::pair<int, double>>& load_terms, bool has_loads,
               const Eigen::Vector3d& g, std::vector<Winch> winches, int coordinates);

  std::string_view name() const override { return "gravity_loads"; }
  EnergyBucket bucket() const override { return EnergyBucket::kPotential; }
  bool time_dependent() const override { return !winches_.empty(); }
  const Eigen::VectorXd* ConstantAppliedLoad() const override {
    return winches_.empty() ? &force_ : nullptr;
  }
  void SetTime(double t) override;
  void AddAppliedLoad(const ForceState& s, ForceOutput* out) const override;
  double StoredEnergy(const ForceState& s) const override;
  void AddEnergyParts(const ForceState& s, EnergyParts* parts) const override;
  // A winch element's gravity Q_g(l) = mu l [g/2, l g/12, g/2, -l g/12]
  // changes with its length l(t) = L(t) / N: the explicit rate of the
  // potential -Q_g . e is -ldot dQ_g/dl . e, dQ_g/dl = Q_g(2 l) / (2 l)
  // (exact for Q_g = a l + b l^2).
  void AddExternalPower(const ForceState& s, double* power) const override;

 private:
  std::vector<Element> elements_;
  std::vector<Coords> gravity_;  // per element, at its current length
  std::vector<Body> bodies_;
  Eigen::Vector3d g_;
  Eigen::VectorXd force_;  // full: gravity and the point loads
  Eigen::VectorXd loads_;  // full: the point loads alone (empty without loads)
  std::vector<Winch> winches_;
  Eigen::VectorXd base_;  // force_ without the winch elements' gravity
};

// The contributor, or null when gravity is zero and no load has a
// constant force. `element_weight[k]`: element k's mass per length for
// gravity [kg/m]; `element_first`, `element_length`, `element_cable`: its
// first full coordinate, length [m] and cable; `body_coord`, `body_mass`
// per body; `load_terms` as above; `winches` (empty without any).
std::unique_ptr<ForceContributor> MakeGravityLoads(
    int dim, const Eigen::Vector3d& g, const std::vector<double>& element_weight,
    const std::vector<int>& element_first, const std::vector<double>& element_length,
    const std::vector<int>& element_cable, const std::vector<int>& body_coord,
    const std::vector<double>& body_mass, const std::vector<std::pair<int, double>>& load_terms,
    bool has_loads, const std::vector<std::pair<std::pair<int, int>, WinchReel>>& winches,
    int coordinates);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_GRAVITY_LOADS_H_
