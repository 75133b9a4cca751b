#include "engine/explicit_acceleration.h"

#include "absl/strings/str_cat.h"

namespace cablesim {

ExplicitAcceleration::ExplicitAcceleration(MultibodyModel* model)
    : model_(model), mass_(model->mass()) {
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
  f_.setZero(model->dofs());
}

bool ExplicitAcceleration::Prepare(const char* stepper, std::string* reason) {
  if (model_->multipliers() > 0) {
    *reason = absl::StrCat(stepper, " integrates unconstrained motion only");
    return false;
  }
  if (!mass_.Factor() || mass_.small_pivots() > 0 || mass_.negative_pivots() > 0) {
    *reason = "the mass matrix could not be factorized (not positive definite)";
    return false;
  }
  return true;
}

bool ExplicitAcceleration::Evaluate(double t, const Eigen::VectorXd& z,
                                    const Eigen::VectorXd& v, Eigen::VectorXd* acc) {
  model_->SetTime(t);
  model_->ToFull(z, &q_);
  model_->NetForce(q_, 1.0, &f_);
  if (model_->has_damping()) {
    model_->RateToFull(v, &qd_);
    model_->DampingForce(q_, qd_, &f_);
  }
  *acc = f_;
  mass_.Solve(acc->data());
  return acc->allFinite();
}

}  // namespace cablesim
