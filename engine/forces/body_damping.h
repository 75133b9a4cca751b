#ifndef CABLESIM_ENGINE_FORCES_BODY_DAMPING_H_
#define CABLESIM_ENGINE_FORCES_BODY_DAMPING_H_

// Rigid bodies' own damping (BodySpec linear_damping, angular_damping) as a
// ForceContributor: -c v on the centre of mass and a torque -c omega, which
// in natural coordinates is the force -c udot on the planar axis u, and
// -(c / 2) edot_k on each spatial axis (for orthonormal axes |omega|^2 =
// (1/2) sum_k |edot_k|^2). Q_d = -C qdot with C diagonal, positive
// semi-definite; it dissipates qdot^T C qdot >= 0.

#include <memory>
#include <string_view>
#include <vector>

#include "engine/forces/force_contributor.h"
#include "engine/scene/scene.h"

namespace cablesim {

class BodyDamping : public ForceContributor {
 public:
  struct Body {
    int coord = 0;  // full index of r_c
    double linear = 0;   // [N s/m]
    double angular = 0;  // [N m s/rad]
  };
  BodyDamping(std::vector<Body> bodies, int dim);

  std::string_view name() const override { return "body_damping"; }
  void AddDissipative(const ForceState& s, ForceOutput* out) const override;
  void AddDissipatedPower(const ForceState& s, double* power) const override;
  bool dissipates() const override { return true; }

 private:
  // The coefficient c_k of the force -c_k qdot_k on the body's k-th
  // natural coordinate.
  double Coefficient(const Body& b, int k) const;

  std::vector<Body> bodies_;
  int dim_, stride_;
};

// The contributor for the scene's damped bodies, or null without any.
std::unique_ptr<BodyDamping> MakeBodyDamping(const Scene& scene,
                                             const std::vector<int>& body_coord, int dim);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_BODY_DAMPING_H_
