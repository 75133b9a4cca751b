#include "engine/steppers/central_difference_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace cablesim {

CentralDifferenceStepper::CentralDifferenceStepper(MultibodyModel* model,
                                                   const SolverSettings& settings)
    : ExplicitStepper(model, settings),
      rows_(model, &acceleration_.factored_mass()) {
  for (Eigen::VectorXd* x : {&z1_, &v1_, &a1_, &v_pred_}) x->setZero(n_);
  lambda1_.setZero(rows_.rows());
}

bool CentralDifferenceStepper::Initialize(std::string* reason) {
  // Beyond omega h = 2 the amplification of an undamped mode is at once
  // above 1.2 a step (1.22 at 2.01).
  double omega_max = 0;
  if (!Start("CENTRAL_DIFFERENCE", 2.0, "2 / omega_max", /*takes_rows=*/true, &omega_max, reason))
    return false;
  if (omega_max > 0) stable_step_ = 0.9 * 2.0 / omega_max;
  if (rows_.rows() == 0) return true;
  // The consistent start: a from [M G^T; G 0][a; lambda] = [f; gamma].
  lambda_.setZero(rows_.rows());
  lambda_old_.setZero(rows_.rows());
  model_->SetTime(t_);
  if (!rows_.Rebuild(z_)) {
    *reason = "the constraint rows' matrix G M^-1 G^T is not finite at the initial state";
    return false;
  }
  rows_.ConsistentAcceleration(v_, &a_, &lambda_);
  if (!a_.allFinite() || !lambda_.allFinite()) {
    *reason = "the initial acceleration with the constraint rows is not finite";
    return false;
  }
  a_old_ = a_;
  lambda_old_ = lambda_;
  rows_current_ = true;
  return true;
}

Stepper::StepStats CentralDifferenceStepper::Step(double h) {
  StepStats st;
  // A failed step leaves the state and the model's time as they were.
  const auto fail = [&](const std::string& what) {
    st.reason = absl::StrFormat("%s after the explicit step (h = %.3g s)", what, h);
    model_->SetTime(t_);
    return st;
  };
  const bool rows = rows_.rows() > 0;
  if (rows && !rows_current_) {
    model_->SetTime(t_);
    if (!rows_.Rebuild(z_)) {
      st.reason = "the constraint rows' matrix G M^-1 G^T is not finite";
      return st;
    }
    rows_current_ = true;
  }
  v1_ = v_ + (0.5 * h) * a_;  // v_half
  z1_ = z_ + h * v1_;
  if (rows) {
    model_->SetTime(t_ + h);
    if (!rows_.ProjectPositions(h, &z1_, &v1_, &st.reason)) {
      model_->SetTime(t_);
      return st;
    }
    // From here the rows' matrices are those of the step's end.
    rows_current_ = false;
    if (!rows_.Rebuild(z1_)) return fail("the constraint rows' matrix G M^-1 G^T is not finite");
  }
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
  if (rows) {
    rows_.ProjectVelocity(&v1_);
    rows_.ConsistentAcceleration(v1_, &a1_, &lambda1_);
    if (!a1_.allFinite() || !lambda1_.allFinite())
      return fail("the acceleration with the constraint rows is not finite");
    Accept(h, &z1_, &v1_, &a1_, &lambda1_);
    rows_current_ = true;
  } else {
    Accept(h, &z1_, &v1_, &a1_);
  }
  st.converged = true;
  return st;
}

void CentralDifferenceStepper::Restore() {
  ExplicitStepper::Restore();
  rows_current_ = false;
}

double CentralDifferenceStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  return WeightedMaxNorm(h * h / 6, a_ - a_old_, z_, n_, atol, rtol);
}

}  // namespace cablesim
