#include "engine/steppers/explicit_acceleration.h"

#include <cmath>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {

ExplicitAcceleration::ExplicitAcceleration(MultibodyModel* model)
    : model_(model), mass_(model->mass()) {
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
  f_.setZero(model->dofs());
  stiffness_.SetPattern(model->envelope());
  x_.setZero(model->dofs());
  kx_.setZero(model->dofs());
  mx_.setZero(model->dofs());
  StartVector();
}

bool ExplicitAcceleration::Prepare(const char* stepper, const SolverSettings& settings,
                                   const Eigen::VectorXd& z0, double limit,
                                   const char* limit_text, bool takes_rows,
                                   double* omega_max, std::string* reason) {
  if (model_->multipliers() > 0 && !takes_rows) {
    *reason = absl::StrCat(stepper, " integrates unconstrained motion only");
    return false;
  }
  if (!mass_.Factor() || mass_.small_pivots() > 0 || mass_.negative_pivots() > 0) {
    *reason = "the mass matrix could not be factorized (not positive definite)";
    return false;
  }
  const double omega = StiffestFrequency(z0, 300);
  *omega_max = omega;
  if (!settings.adaptive) {
    if (settings.step_s * omega > limit) {
      *reason = absl::StrFormat(
          "solver.step: %.4g s is beyond %s's stability limit for this scene, about %.3g s "
          "(%s; omega_max = %.4g rad/s, the stiffest mode of the initial state, which tension "
          "raises during the run): use a smaller step, adaptive steps, or an implicit "
          "integrator (HHT)",
          settings.step_s, stepper, limit / omega, limit_text, omega);
      return false;
    }
  }
  return true;
}

double ExplicitAcceleration::StiffestFrequency(const Eigen::VectorXd& z, int iterations) {
  if (model_->dofs() == 0) return 0;
  stiffness_.SetZero();
  model_->ToFull(z, &q_);
  model_->NetForce(q_, 1.0, &f_, &stiffness_, 1.0);
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    stiffness_.Multiply(x_.data(), kx_.data());
    model_->mass().Multiply(x_.data(), mx_.data());
    const double xmx = x_.dot(mx_);
    if (!(xmx > 0)) break;
    const double next = x_.dot(kx_) / xmx;
    const bool settled = it > 0 && std::abs(next - lambda) <= 1e-6 * std::abs(next);
    lambda = next;
    if (settled) break;
    x_ = kx_;
    mass_.Solve(x_.data());
    const double norm = x_.lpNorm<Eigen::Infinity>();
    if (!(norm > 0) || !std::isfinite(norm)) {
      StartVector();
      break;
    }
    x_ /= norm;
  }
  return std::sqrt(std::abs(lambda));
}

void ExplicitAcceleration::StartVector() {
  // Every mode in it: a fixed pseudo-random vector (an alternating pattern
  // would repeat node by node, 4 or 6 unknowns a node, and be smooth along
  // the cable).
  uint64_t state = 0x9e3779b97f4a7c15ULL;
  for (int i = 0; i < x_.size(); ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    x_(i) = static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5;
  }
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

std::string ExplicitAcceleration::NotFiniteSource() const {
  const std::string where =
      model_->DescribeNonFinite(q_, model_->has_damping() ? &qd_ : nullptr, 1.0);
  return where.empty() ? std::string() : absl::StrCat(": ", where);
}

}  // namespace cablesim
