#ifndef CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_
#define CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_

// ExternalWork: sums the work of torques, time-varying loads and moving
// supports over accepted steps, for the energy balance.

#include <Eigen/Core>

#include "engine/model/multibody_model.h"

namespace cablesim {

// Sums the work of torques, time-varying loads and moving supports over
// accepted steps, for the energy balance (MultibodyModel::
// AccumulateExternalWork), and the winches' (MultibodyModel::
// ExternalPower); nothing in a scene without them.
class ExternalWork {
 public:
  explicit ExternalWork(MultibodyModel* model) : model_(model) {
    model->ResetExternalWork();
    if (!model->has_external_work() && !model->has_external_power()) return;
    before_.setZero(model->coordinates());
    after_.setZero(model->coordinates());
    if (model->has_external_power()) rate_.setZero(model->coordinates());
    lambda_before_.setZero(model->multipliers());
  }
  // The step's start (t, z, lambda); `v` its rate, for a winch's power
  // (null: a load increment, which has no time to integrate over).
  void Before(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda,
              const Eigen::VectorXd* v = nullptr) {
    if (!model_->has_external_work() && !model_->has_external_power()) return;
    model_->ToFull(z, &before_);
    t_before_ = t;
    lambda_before_ = lambda;
    if (v != nullptr && model_->has_external_power() && !(power_known_ && t == power_t_)) {
      // The end of the last accepted step is this start (a step taken back
      // is restored to it): its power is known unless the run begins here.
      model_->SetTime(t);
      model_->RateToFull(*v, &rate_);
      power_ = model_->ExternalPower(before_, rate_);
      power_t_ = t;
      power_known_ = true;
    }
  }
  // The end of an accepted step. A winch's power is integrated by the
  // trapezoidal rule, as the other terms' work (AccumulateExternalWork):
  // W = (t1 - t0) (P0 + P1) / 2, second order.
  void After(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda,
             double load_factor, const Eigen::VectorXd* v = nullptr) {
    if (!model_->has_external_work() && !model_->has_external_power()) return;
    model_->ToFull(z, &after_);
    if (model_->has_external_work())
      model_->AccumulateExternalWork(before_, after_, t_before_, t, lambda_before_, lambda,
                                     load_factor);
    if (v != nullptr && model_->has_external_power() && power_known_) {
      model_->SetTime(t);
      model_->RateToFull(*v, &rate_);
      const double power = model_->ExternalPower(after_, rate_);
      model_->AddExternalWork(0.5 * (t - t_before_) * (power_ + power));
      power_ = power;
      power_t_ = t;
    }
  }

 private:
  MultibodyModel* model_;
  Eigen::VectorXd before_, after_, lambda_before_, rate_;
  double t_before_ = 0;
  double power_ = 0, power_t_ = 0;  // ExternalPower at the last step's end
  bool power_known_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_
