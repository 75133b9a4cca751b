#include "engine/steppers/central_difference_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace cablesim {

CentralDifferenceStepper::CentralDifferenceStepper(MultibodyModel* model,
                                                   const SolverSettings& settings)
    : ExplicitStepper(model, settings) {
  for (Eigen::VectorXd* x : {&z1_, &v1_, &a1_, &v_pred_}) x->setZero(n_);
}

bool CentralDifferenceStepper::Initialize(std::string* reason) {
  // Beyond omega h = 2 the amplification of an undamped mode is at once
  // above 1.2 a step (1.22 at 2.01).
  double omega_max = 0;
  return Start("CENTRAL_DIFFERENCE", 2.0, "2 / omega_max", &omega_max, reason);
}

Stepper::StepStats CentralDifferenceStepper::Step(double h) {
  StepStats st;
  v1_ = v_ + (0.5 * h) * a_;  // v_half
  z1_ = z_ + h * v1_;
  if (model_->has_damping()) v_pred_ = v_ + h * a_;
  if (!acceleration_.Evaluate(t_ + h, z1_, v_pred_, &a1_)) {
    st.reason = absl::StrFormat(
        "the acceleration after the explicit step is not finite (h = %.3g s: likely beyond "
        "CENTRAL_DIFFERENCE's stability limit, 2 / omega_max)%s",
        h, acceleration_.NotFiniteSource());
    model_->SetTime(t_);
    return st;
  }
  v1_ += (0.5 * h) * a1_;
  Accept(h, &z1_, &v1_, &a1_);
  st.converged = true;
  return st;
}

double CentralDifferenceStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  return WeightedMaxNorm(h * h / 6, a_ - a_old_, z_, n_, atol, rtol);
}

}  // namespace cablesim
