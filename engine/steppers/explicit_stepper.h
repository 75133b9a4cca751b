#ifndef CABLESIM_ENGINE_STEPPERS_EXPLICIT_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_EXPLICIT_STEPPER_H_

// What the explicit steppers (CentralDifferenceStepper, DormandPrinceStepper)
// share: the state (z, v, a) at t [s] and the one before the last converged
// step (for Restore), their ExplicitAcceleration (a = M^-1 f, the mass
// factored once), and the start: the stability check of a fixed step and the
// initial acceleration. A step computes its end into scratch vectors and
// hands them to Accept() only when it succeeded, so a failed step leaves
// both the state and the one Restore() returns to untouched. lambda() is
// empty unless the stepper takes constraint rows (CENTRAL_DIFFERENCE): then
// it holds the multipliers of the state, swapped with the state.

#include <string>

#include <Eigen/Core>

#include "engine/steppers/explicit_acceleration.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

class ExplicitStepper : public Stepper {
 public:
  void Restore() override;
  // Unconstrained only: the state, then a = M^-1 f there (one evaluation).
  bool Restart(const Eigen::VectorXd& z, const Eigen::VectorXd& v, double t) override;

  const Eigen::VectorXd& z() const final { return z_; }
  const Eigen::VectorXd& v() const final { return v_; }
  const Eigen::VectorXd& a() const final { return a_; }
  const Eigen::VectorXd& lambda() const final { return lambda_; }

 protected:
  ExplicitStepper(MultibodyModel* model, const SolverSettings& settings);

  // ExplicitAcceleration::Prepare (named `stepper`, with its stability
  // `limit` on omega h explained by `limit_text`; omega_max of the initial
  // state into *omega_max), then a = M^-1 f at the start.
  // `takes_rows`: the stepper integrates constraint rows itself.
  bool Start(const char* stepper, double limit, const char* limit_text, bool takes_rows,
             double* omega_max, std::string* reason);

  // The step of size h succeeded with end state (z1, v1, a1): the current
  // state becomes the one Restore() returns to and the end state the
  // current one. Swaps (no allocation); the vectors come back as scratch.
  // `lambda1`: the end's multipliers (null: none, the model has no rows).
  void Accept(double h, Eigen::VectorXd* z1, Eigen::VectorXd* v1, Eigen::VectorXd* a1,
              Eigen::VectorXd* lambda1 = nullptr);

  MultibodyModel* model_;
  SolverSettings settings_;
  ExplicitAcceleration acceleration_;
  int n_ = 0;
  Eigen::VectorXd z_, v_, a_, lambda_;
  Eigen::VectorXd z_old_, v_old_, a_old_, lambda_old_;
  double t_ = 0, t_old_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_EXPLICIT_STEPPER_H_
