#ifndef CABLESIM_ENGINE_FORCES_BODY_SEABED_CONTACT_H_
#define CABLESIM_ENGINE_FORCES_BODY_SEABED_CONTACT_H_

// Rigid bodies' contact points on the seabed (BodySpec::contact_points_m)
// as one ForceContributor: per point the seabed's point law
// (Seabed::PointPotential, PointDissipation, PointStaticFriction: a spring
// k normal to the bed, a damper c, regularized Coulomb friction mu).
//
// A body point p (body frame) is at r = B q_b, linear in the body's natural
// coordinates q_b (planar r_c + p_x u + p_y perp(u), spatial r_c + sum p_k
// e_k; engine/model/multibody_model.h), so the generalized force is B^T f
// and the matrix B^T H B, within the body's own block. Energy: the springs'
// in energy.contact; the damper and friction in the damping power.

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/force_contributor.h"
#include "engine/forces/seabed.h"
#include "engine/scene/scene.h"

namespace cablesim {

class BodySeabedContact : public ForceContributor {
 public:
  // One body's points: body frame [m], spring k [N/m], damper c [N s/m],
  // friction mu [-].
  struct Body {
    int coord = 0;  // full index of the body's r_c
    std::vector<Eigen::Vector3d> points;
    double k = 0, c = 0, mu = 0;
  };

  BodySeabedContact(const Seabed& bed, std::vector<Body> bodies, int dim);

  int count() const { return static_cast<int>(bodies_.size()); }

  std::string_view name() const override { return "body_seabed_contact"; }
  EnergyBucket bucket() const override { return EnergyBucket::kContact; }
  void AddConservative(const ForceState& s, ForceOutput* out) const override;
  void AddDissipative(const ForceState& s, ForceOutput* out) const override;
  double StoredEnergy(const ForceState& s) const override;
  void AddDissipatedPower(const ForceState& s, double* power) const override;
  bool dissipates() const override;
  bool has_static_friction() const override;
  void AddStaticFriction(const Eigen::VectorXd& q, const Eigen::VectorXd& q_start,
                         ForceOutput* out) const override;

 private:
  enum class Term { kPotential, kDissipation, kStaticFriction };
  // kPotential (at q: returns U, adds -dU/dq and its Hessian),
  // kDissipation (`other` the rate: returns the power, adds the force and
  // its velocity tangent), kStaticFriction (`other` the start: returns 0).
  // `out` may be null (the value only).
  template <int D>
  double Terms(Term term, const Eigen::VectorXd& q, const Eigen::VectorXd* other,
               ForceOutput* out) const;
  double Dispatch(Term term, const Eigen::VectorXd& q, const Eigen::VectorXd* other,
                  ForceOutput* out) const;

  Seabed bed_;
  std::vector<Body> bodies_;
  int dim_;
};

// The contributor for a scene's bodies with contact points, or null when
// none has any (or the scene has no seabed). `body_coord[b]`: body b's
// first full coordinate.
std::unique_ptr<BodySeabedContact> MakeBodySeabedContact(const Scene& scene,
                                                         const std::vector<int>& body_coord,
                                                         int dim);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_BODY_SEABED_CONTACT_H_
