#ifndef CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_
#define CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_

// ExternalWork: sums the work of torques, time-varying loads and moving
// supports over accepted steps, for the energy balance.

#include <Eigen/Core>

#include "engine/model/multibody_model.h"

namespace cablesim {

// Sums the work of torques, time-varying loads and moving supports over
// accepted steps, for the energy balance (MultibodyModel::
// AccumulateExternalWork); nothing in a scene without them.
class ExternalWork {
 public:
  explicit ExternalWork(MultibodyModel* model) : model_(model) {
    model->ResetExternalWork();
    if (!model->has_external_work()) return;
    before_.setZero(model->coordinates());
    after_.setZero(model->coordinates());
    lambda_before_.setZero(model->multipliers());
  }
  void Before(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda) {
    if (!model_->has_external_work()) return;
    model_->ToFull(z, &before_);
    t_before_ = t;
    lambda_before_ = lambda;
  }
  void After(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda,
             double load_factor) {
    if (!model_->has_external_work()) return;
    model_->ToFull(z, &after_);
    model_->AccumulateExternalWork(before_, after_, t_before_, t, lambda_before_, lambda,
                                   load_factor);
  }

 private:
  MultibodyModel* model_;
  Eigen::VectorXd before_, after_, lambda_before_;
  double t_before_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_EXTERNAL_WORK_H_
