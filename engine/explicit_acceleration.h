#ifndef CABLESIM_ENGINE_EXPLICIT_ACCELERATION_H_
#define CABLESIM_ENGINE_EXPLICIT_ACCELERATION_H_

// The explicit steppers' one operation on the model (central_difference_
// stepper.h, dormand_prince_stepper.h): the acceleration of the
// unconstrained equations of motion,
//
//   a = M^-1 f(t, z, v),   f = Q_a(z, t) - Q_k(z) - C(z) v   [m/s^2, 1/s^2],
//
// with the constant reduced mass matrix M factored once (SkylineLdlt) and
// f from MultibodyModel::NetForce and DampingForce at time t.
// Evaluate() allocates nothing.

#include <string>

#include <Eigen/Core>

#include "engine/multibody_model.h"
#include "engine/skyline_ldlt.h"

namespace cablesim {

class ExplicitAcceleration {
 public:
  explicit ExplicitAcceleration(MultibodyModel* model);

  // Factors the mass; false with `reason` when the model has constraint
  // rows (ModelBuilder::CheckIntegratorFits refuses those first) or the
  // mass is not positive definite. `stepper` names the caller in messages.
  bool Prepare(const char* stepper, std::string* reason);

  // acc = M^-1 f(t, z, v); false when it is not finite.
  bool Evaluate(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v,
                Eigen::VectorXd* acc);

 private:
  MultibodyModel* model_;
  SkylineLdlt mass_;
  Eigen::VectorXd q_, qd_, f_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_EXPLICIT_ACCELERATION_H_
