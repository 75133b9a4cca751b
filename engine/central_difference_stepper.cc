#include "engine/central_difference_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace cablesim {

CentralDifferenceStepper::CentralDifferenceStepper(MultibodyModel* model,
                                                   const SolverSettings& settings)
    : model_(model), settings_(settings), acceleration_(model) {
  n_ = model->dofs();
  z_ = model->initial_z();
  v_ = model->initial_v();
  a_.setZero(n_);
  lambda_.resize(0);
  z_old_ = z_;
  v_old_ = v_;
  a_old_ = a_;
  v_pred_.setZero(n_);
}

bool CentralDifferenceStepper::Initialize(std::string* reason) {
  // Beyond omega h = 2 the amplification of an undamped mode is at once
  // above 1.2 a step (1.22 at 2.01).
  if (!acceleration_.Prepare("CENTRAL_DIFFERENCE", settings_, z_, 2.0, "2 / omega_max", reason))
    return false;
  if (!acceleration_.Evaluate(t_, z_, v_, &a_)) {
    *reason = "the initial acceleration is not finite";
    return false;
  }
  a_old_ = a_;
  return true;
}

Stepper::StepStats CentralDifferenceStepper::Step(double h) {
  StepStats st;
  z_old_ = z_;
  v_old_ = v_;
  a_old_ = a_;
  v_ += (0.5 * h) * a_;  // v_half
  z_ += h * v_;
  if (model_->has_damping()) v_pred_ = v_ + (0.5 * h) * a_old_;  // v_n + h a_n
  if (!acceleration_.Evaluate(t_ + h, z_, v_pred_, &a_)) {
    z_.swap(z_old_);
    v_.swap(v_old_);
    a_.swap(a_old_);
    model_->SetTime(t_);
    st.reason = absl::StrFormat(
        "the acceleration after the explicit step is not finite (h = %.3g s: likely beyond "
        "CENTRAL_DIFFERENCE's stability limit, 2 / omega_max)",
        h);
    return st;
  }
  v_ += (0.5 * h) * a_;
  t_old_ = t_;
  t_ += h;
  st.converged = true;
  return st;
}

void CentralDifferenceStepper::Restore() {
  z_.swap(z_old_);
  v_.swap(v_old_);
  a_.swap(a_old_);
  t_ = t_old_;
  model_->SetTime(t_);
}

double CentralDifferenceStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  double worst = 0;
  const double k = h * h / 6;
  for (int i = 0; i < n_; ++i)
    worst = std::max(worst, k * std::abs(a_(i) - a_old_(i)) / (atol + rtol * std::abs(z_(i))));
  return worst;
}

}  // namespace cablesim
