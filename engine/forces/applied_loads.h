#ifndef CABLESIM_ENGINE_FORCES_APPLIED_LOADS_H_
#define CABLESIM_ENGINE_FORCES_APPLIED_LOADS_H_

// The scene's loads that are not constant generalized forces, as one
// ForceContributor (the constant ones, gravity and the loads' constant
// forces, are GravityLoads', gravity_loads.h: V = -F . q):
//
//  - a time-varying force F(t) at a point x linear in q (a cable point or
//    a body point): the generalized force sum_d F_d a_{d,i} on q_i; its
//    work over a step the trapezoidal rule (F(t0) + F(t1)) / 2 . (x1 - x0)
//    (second order);
//  - a torque T (constant plus varying) on a body: its virtual work
//    T . dphi, with de_k = dphi x e_k, is done by the generalized forces
//    (1/2) T x e_k on the spatial axes and T_z perp(u) on the planar u,
//    on the unit, orthogonal axes the constraints keep. Their derivative is
//    skew-symmetric, so the symmetric Newton matrix leaves it out (Newton
//    then converges linearly, at a rate of order h^2 |T| / J). Its work
//    over a step: the mean torque times the rotation vector of the step
//    (exact in the plane for a constant torque, in space when the rotation
//    axis is fixed, second order otherwise).
//
// Both count with the applied loads (scaled by the load factor) and store
// no energy: their work is summed step by step (StepWork).

#include <array>
#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/force_contributor.h"
#include "engine/scene/scene.h"
#include "engine/scene/time_function.h"

namespace cablesim {

class AppliedLoads : public ForceContributor {
 public:
  // A flat linear form sum coeff * q[coord].
  struct Term {
    int coord = 0;
    double coeff = 0;
  };
  // A time-varying force at a point: per component d, the point's linear
  // form (the generalized force is F_d coeff on q[coord]).
  struct VaryingForce {
    std::array<std::vector<Term>, 3> point;
    TimeVector force;
    Eigen::Vector3d value = Eigen::Vector3d::Zero();  // force(time)
  };
  // A torque on the body whose centre is at full index `coord`: torque =
  // base + varying(t).
  struct Torque {
    int coord = 0;
    Eigen::Vector3d torque = Eigen::Vector3d::Zero();
    Eigen::Vector3d base = Eigen::Vector3d::Zero();
    TimeVector varying;
    bool is_varying = false;
  };

  AppliedLoads(std::vector<VaryingForce> forces, std::vector<Torque> torques, int dim);

  std::string_view name() const override { return "applied_loads"; }
  bool time_dependent() const override;
  void SetTime(double t) override;
  void AddAppliedLoad(const ForceState& s, ForceOutput* out) const override;
  void AddStepWork(const StepEnds& e, double* work) const override;

 private:
  std::vector<VaryingForce> forces_;
  std::vector<Torque> torques_;
  int dim_;
};

// The contributor for the scene's time-varying forces and torques, or null
// without any. `point_of(at)`: the attachment's position as a linear form
// over the full coordinates (per component, (index, coefficient) terms);
// `body_coord[b]`: body b's first full coordinate.
std::unique_ptr<AppliedLoads> MakeAppliedLoads(
    const Scene& scene, const std::vector<std::array<std::vector<AppliedLoads::Term>, 3>>& points,
    const std::vector<int>& body_coord, int dim);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_APPLIED_LOADS_H_
