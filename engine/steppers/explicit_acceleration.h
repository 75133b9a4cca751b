#ifndef CABLESIM_ENGINE_STEPPERS_EXPLICIT_ACCELERATION_H_
#define CABLESIM_ENGINE_STEPPERS_EXPLICIT_ACCELERATION_H_

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

#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/linear/skyline_ldlt.h"

namespace cablesim {

class ExplicitAcceleration {
 public:
  explicit ExplicitAcceleration(MultibodyModel* model);

  // Factors the mass; false with `reason` when the model has constraint
  // rows and the stepper does not take them (`takes_rows` false;
  // ModelBuilder::CheckIntegratorFits refuses those first) or the mass is
  // not positive definite. With rows, omega_max is that of the
  // unconstrained mesh: the rows only take modes away (the constrained
  // frequencies interlace below it), apart from the multipliers' own
  // stiffness (lambda . Phi_zz), which is not counted. `stepper` names the caller in messages.
  // Puts omega_max at the initial state z0 (StiffestFrequency) into
  // *omega_max. With a fixed step (settings not adaptive), also false when
  // the step is beyond `limit` / omega_max (`limit`: the stepper's omega h
  // where its stiffest undamped mode starts to grow by more than 1 % a
  // step; `limit_text` explains it in the message).
  bool Prepare(const char* stepper, const SolverSettings& settings, const Eigen::VectorXd& z0,
               double limit, const char* limit_text, bool takes_rows, double* omega_max,
               std::string* reason);

  // The reduced mass matrix as factored by Prepare.
  const SkylineLdlt& factored_mass() const { return mass_; }

  // The stiffest mode's angular frequency [rad/s] of the linearization at
  // z (time as last set): sqrt of the largest |eigenvalue| of M^-1 K_T(z),
  // by power iteration in the M inner product (at most `iterations`, until
  // the Rayleigh quotient settles to 1e-6), warm-started from the last
  // call's vector (so a few iterations follow a slowly changing mode). The
  // quotient approaches the eigenvalue from below: a lower bound, so a step
  // refused by it is surely beyond the limit at that state. Allocates
  // nothing.
  double StiffestFrequency(const Eigen::VectorXd& z, int iterations);

  // acc = M^-1 f(t, z, v); false when it is not finite.
  bool Evaluate(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v,
                Eigen::VectorXd* acc);
  // After Evaluate returned false: ": " and the force term and place the
  // non-finite value came from (MultibodyModel::DescribeNonFinite), or
  // nothing when every term is finite (the mass solve overflowed).
  std::string NotFiniteSource() const;

 private:
  void StartVector();

  MultibodyModel* model_;
  SkylineLdlt mass_;
  SkylineLdlt stiffness_;  // K_T for StiffestFrequency
  Eigen::VectorXd q_, qd_, f_, x_, kx_, mx_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_EXPLICIT_ACCELERATION_H_
