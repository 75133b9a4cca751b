#include "engine/steppers/explicit_stepper.h"

#include "absl/strings/str_cat.h"

namespace cablesim {

ExplicitStepper::ExplicitStepper(MultibodyModel* model, const SolverSettings& settings)
    : model_(model), settings_(settings), acceleration_(model) {
  n_ = model->dofs();
  z_ = model->initial_z();
  v_ = model->initial_v();
  t_ = t_old_ = model->initial_time();  // 0 but after a joint let go (JointRelease)
  a_.setZero(n_);
  lambda_.resize(0);
  z_old_ = z_;
  v_old_ = v_;
  a_old_ = a_;
}

bool ExplicitStepper::Start(const char* stepper, double limit, const char* limit_text,
                            bool takes_rows, double* omega_max, std::string* reason) {
  if (!acceleration_.Prepare(stepper, settings_, z_, limit, limit_text, takes_rows, omega_max,
                             reason))
    return false;
  if (!acceleration_.Evaluate(t_, z_, v_, &a_)) {
    *reason = absl::StrCat("the initial acceleration is not finite",
                           acceleration_.NotFiniteSource());
    return false;
  }
  a_old_ = a_;
  return true;
}

bool ExplicitStepper::Restart(const Eigen::VectorXd& z, const Eigen::VectorXd& v, double t) {
  if (lambda_.size() > 0 || z.size() != n_ || v.size() != n_) return false;
  z_ = z;
  v_ = v;
  t_ = t;
  model_->SetTime(t_);
  if (!acceleration_.Evaluate(t_, z_, v_, &a_)) return false;
  z_old_ = z_;
  v_old_ = v_;
  a_old_ = a_;
  t_old_ = t_;
  return true;
}

void ExplicitStepper::Accept(double h, Eigen::VectorXd* z1, Eigen::VectorXd* v1,
                             Eigen::VectorXd* a1, Eigen::VectorXd* lambda1) {
  if (lambda1 != nullptr) {
    lambda_old_.swap(lambda_);
    lambda_.swap(*lambda1);
  }
  z_old_.swap(z_);
  v_old_.swap(v_);
  a_old_.swap(a_);
  z_.swap(*z1);
  v_.swap(*v1);
  a_.swap(*a1);
  t_old_ = t_;
  t_ += h;
}

void ExplicitStepper::Restore() {
  z_.swap(z_old_);
  v_.swap(v_old_);
  a_.swap(a_old_);
  lambda_.swap(lambda_old_);
  t_ = t_old_;
  model_->SetTime(t_);
}

}  // namespace cablesim
