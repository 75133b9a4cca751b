#include "engine/explicit_acceleration.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {

ExplicitAcceleration::ExplicitAcceleration(MultibodyModel* model)
    : model_(model), mass_(model->mass()) {
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
  f_.setZero(model->dofs());
}

bool ExplicitAcceleration::Prepare(const char* stepper, const SolverSettings& settings,
                                   const Eigen::VectorXd& z0, double limit,
                                   const char* limit_text, std::string* reason) {
  if (model_->multipliers() > 0) {
    *reason = absl::StrCat(stepper, " integrates unconstrained motion only");
    return false;
  }
  if (!mass_.Factor() || mass_.small_pivots() > 0 || mass_.negative_pivots() > 0) {
    *reason = "the mass matrix could not be factorized (not positive definite)";
    return false;
  }
  if (!settings.adaptive) {
    const double omega = StiffestFrequency(z0);
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

double ExplicitAcceleration::StiffestFrequency(const Eigen::VectorXd& z) {
  const int n = model_->dofs();
  if (n == 0) return 0;
  SkylineLdlt stiffness;
  stiffness.SetPattern(model_->envelope());
  stiffness.SetZero();
  model_->ToFull(z, &q_);
  model_->NetForce(q_, 1.0, &f_, &stiffness, 1.0);
  // A start rich in the highest modes: neighbouring unknowns of opposite
  // sign, perturbed so that no mode is missed by symmetry.
  Eigen::VectorXd x(n), kx(n), mx(n);
  for (int i = 0; i < n; ++i) x(i) = (i % 2 ? -1.0 : 1.0) * (1 + 0.1 * std::sin(1.7 * i + 0.3));
  double lambda = 0;
  for (int it = 0; it < 300; ++it) {
    stiffness.Multiply(x.data(), kx.data());
    model_->mass().Multiply(x.data(), mx.data());
    const double xmx = x.dot(mx);
    if (!(xmx > 0)) break;
    const double next = x.dot(kx) / xmx;
    const bool settled = it > 0 && std::abs(next - lambda) <= 1e-6 * std::abs(next);
    lambda = next;
    if (settled) break;
    x = kx;
    mass_.Solve(x.data());
    const double norm = x.lpNorm<Eigen::Infinity>();
    if (!(norm > 0) || !std::isfinite(norm)) break;
    x /= norm;
  }
  return std::sqrt(std::abs(lambda));
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
