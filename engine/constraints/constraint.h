#ifndef CABLESIM_ENGINE_CONSTRAINTS_CONSTRAINT_H_
#define CABLESIM_ENGINE_CONSTRAINTS_CONSTRAINT_H_

// The one shape of a constraint family: a ConstraintFamily. The model
// (engine/model/multibody_model.h) holds the families a scene uses and
// assembles its rows Phi(q, t) = 0, their Jacobian on the unknowns, the
// Hessian term, the acceleration right-hand side and the work of rheonomic
// rows over that list; it names no family. Two families today:
//
//  - JointRows (joint_rows.h): the flat rows of every joint and body axis
//    constraint, each at most quadratic in q (QuadraticForm), with a fixed
//    pattern; they own the rows' values, Jacobian and Hessian.
//  - PrescribedMotion (prescribed_motion.h): the time law of moving and
//    turning supports. It owns no rows of its own: it moves the constants
//    (moving support, Phi = r - p - d(t)) and linear coefficients (turning
//    support, Phi = n(t) . x) of some JointRows rows at SetTime, and gives
//    their time derivatives Phi_t, Phi_tt, their reactions and the work
//    the supports do.
//
// Row indices are the model's (its multipliers). Each method adds to what
// the model passes (the model zeroes first), except Residual, whose family
// writes the rows it owns.
//
// The sliding joint is not a constraint but a penalty force
// (engine/forces/sliding_joint.h): as rows with a material unknown s they
// would be cubic in s and change their coordinates whenever s crosses a
// node, while every row here keeps a fixed pattern.
//
// tests/contributor_conformance_test.cc checks every family against
// central differences of itself.

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/linear/coordinate_map.h"
#include "engine/linear/skyline_ldlt.h"
#include "engine/linear/sparse_rows.h"

namespace cablesim {

// The two ends of an accepted step: full configurations, times and
// multipliers.
struct ConstraintStep {
  const Eigen::VectorXd* q_before = nullptr;
  const Eigen::VectorXd* q_after = nullptr;
  double t_before = 0, t_after = 0;
  const Eigen::VectorXd* lambda_before = nullptr;
  const Eigen::VectorXd* lambda_after = nullptr;
};

class ConstraintFamily {
 public:
  virtual ~ConstraintFamily() = default;

  virtual std::string_view name() const = 0;
  virtual bool time_dependent() const { return false; }
  virtual void SetTime(double t) { (void)t; }

  // Phi(q) of its rows into `phi`, and dPhi/dz into `jac`'s values (the
  // model's pattern, row by row) when not null.
  virtual void Residual(const Eigen::VectorXd& q, const CoordinateMap& map,
                        Eigen::VectorXd* phi, SparseRows* jac) const {
    (void)q, (void)map, (void)phi, (void)jac;
  }
  // Adds scale * sum_i lambda_i d^2 Phi_i / dz^2 to `a`.
  virtual void AddHessian(const Eigen::VectorXd& lambda, double scale, SkylineLdlt* a) const {
    (void)lambda, (void)scale, (void)a;
  }
  // Adds its terms of gamma = -qdot^T Phi_qq qdot - 2 Phi_qt qdot - Phi_tt.
  virtual void AddGamma(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                        Eigen::VectorXd* gamma) const {
    (void)q, (void)qdot, (void)gamma;
  }
  // Adds Phi_t (so that Phi_z zdot + Phi_t = 0 on the motion).
  virtual void AddRate(const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const {
    (void)q, (void)phi_t;
  }
  // Adds the work [J] its rows' supports did over a step (rheonomic rows:
  // int lambda Phi_t dt).
  virtual void AddStepWork(const ConstraintStep& step, double* work) const {
    (void)step, (void)work;
  }
  // The force [N] and moment [N m] each scene joint's rows exert on the
  // joint's side a at full configuration q, from the multipliers: adds to
  // (*forces)[j] and (*moments)[j] (sized to the scene's joints) for the
  // joints it knows.
  virtual void AddReactions(const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                            std::vector<Eigen::Vector3d>* forces,
                            std::vector<Eigen::Vector3d>* moments) const {
    (void)q, (void)lambda, (void)forces, (void)moments;
  }
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_CONSTRAINTS_CONSTRAINT_H_
