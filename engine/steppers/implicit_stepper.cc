#include "engine/steppers/implicit_stepper.h"

#include <algorithm>

namespace cablesim {

ImplicitStepper::ImplicitStepper(MultibodyModel* model, const SolverSettings& settings)
    : model_(model), settings_(settings) {
  n_ = model->dofs();
  m_ = model->multipliers();
  solver_.Resize(model->envelope(), model->jacobian_pattern());
  solver_.Configure(settings.preconditioner, settings.accept_inexact_solves);
  z_ = model->initial_z();
  v_ = model->initial_v();
  t_ = t_old_ = model->initial_time();  // 0 but after a joint let go (JointRelease)
  a_.setZero(n_);
  lambda_.setZero(m_);
  for (Eigen::VectorXd* x : {&floor_, &abs_terms_, &f_floor_}) x->setZero(n_);
  rhs_.setZero(n_ + m_);
  dx_.setZero(n_ + m_);
  z_old_ = z_;
  v_old_ = v_;
  a_old_ = a_;
  lambda_old_ = lambda_;
}

void ImplicitStepper::Restore() {
  z_ = z_old_;
  v_ = v_old_;
  a_ = a_old_;
  lambda_ = lambda_old_;
  t_ = t_old_;
  h_last_ = h_old_;
  RestoreScheme();
}

void ImplicitStepper::LoadMass() {
  const SkylineLdlt& mass = model_->mass();
  std::copy(mass.values(), mass.values() + mass.stored(), solver_.a().values());
}

void ImplicitStepper::KeepInitialState() {
  a_old_ = a_;
  lambda_old_ = lambda_;
}

void ImplicitStepper::KeepPreviousState() {
  z_old_.swap(z_);
  v_old_.swap(v_);
  a_old_.swap(a_);
  lambda_old_.swap(lambda_);
}

}  // namespace cablesim
