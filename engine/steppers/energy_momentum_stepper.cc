#include "engine/steppers/energy_momentum_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"
#include "engine/steppers/newton_convergence.h"

namespace cablesim {

EnergyMomentumStepper::EnergyMomentumStepper(MultibodyModel* model,
                                             const SolverSettings& settings)
    : ImplicitStepper(model, settings) {
  jac1_ = model->jacobian_pattern();
  jacm_ = model->jacobian_pattern();
  for (Eigen::VectorXd* x : {&abar_, &v1_, &f_, &mdv_, &bt_mu_}) x->setZero(n_);
  phim_.setZero(m_);
  for (Eigen::VectorXd* x : {&q0_, &q1_, &qm_, &qd_}) x->setZero(model->coordinates());
  abar_old_ = abar_;
}

bool EnergyMomentumStepper::Initialize(std::string* reason) {
  kept_.have = false;  // the solver's matrices now hold M and Phi_z
  model_->SetTime(t_);
  model_->ToFull(z_, &qm_);
  model_->NetForce(qm_, 1.0, &f_);
  if (model_->has_damping()) {
    model_->RateToFull(v_, &qd_);
    model_->DampingForce(qm_, qd_, &f_);
  }
  model_->Constraints(qm_, &phi_, &solver_.b());
  Eigen::VectorXd gamma(m_);
  model_->RateToFull(v_, &qd_);
  model_->ConstraintGamma(qm_, qd_, &gamma);
  LoadMass();
  if (!SolveInitialAcceleration(&solver_, settings_, f_, gamma, &rhs_, &dx_, reason)) return false;
  a_ = dx_.head(n_);
  abar_ = a_;
  lambda_ = dx_.tail(m_);
  KeepInitialState();
  abar_old_ = abar_;
  return true;
}

void EnergyMomentumStepper::RestoreScheme() { abar_ = abar_old_; }

double EnergyMomentumStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  return WeightedMaxNorm(h * h / (6 * (1 + h_old_ / h)), abar_ - abar_old_, z_, n_, atol, rtol);
}

double EnergyMomentumStepper::Forces(double h, Eigen::VectorXd* f, SkylineLdlt* a,
                                     Eigen::VectorXd* roundoff) {
  // Loads, torques and the elastic force at zm and t + h/2, then the
  // elastic force replaced by its discrete gradient.
  model_->SetTime(t_ + 0.5 * h);
  double size = model_->NetForce(qm_, 1.0, f, a, 0.25 * h * h, roundoff);
  model_->SubtractDiscreteGradientCorrection(q0_, q1_, f);
  if (model_->has_damping()) {
    mdv_ = 0.5 * (v_ + v1_);  // scratch: the mean velocity
    model_->RateToFull(mdv_, &qd_);
    size = std::max(size, model_->DampingForce(qm_, qd_, f, a, 0.5 * h, roundoff,
                                                  0.25 * h * h));
  }
  return size;
}

Stepper::StepStats EnergyMomentumStepper::Step(double h) {
  return SolveWithFreshRetry(settings_.reuse_factorization, kept_.refresh,
                             [&](bool fresh) { return Solve(h, fresh); });
}

Stepper::StepStats EnergyMomentumStepper::Solve(double h, bool fresh) {
  h_ = h;
  c_ = 0.25 * h * h;
  if (kept_.Stale(c_)) fresh = true;
  // Predictor: the mean acceleration of the last step.
  v1_ = v_ + h * abar_;
  lambda1_ = lambda_;
  model_->ToFull(z_, &q0_);
  StepStats st = Newton(fresh, settings_.reuse_factorization);
  if (!st.converged) return st;
  KeepPreviousState();
  abar_old_.swap(abar_);
  z_.swap(z1_);
  v_.swap(v1_);
  lambda_.swap(lambda1_);
  abar_ = (v_ - v_old_) / h;
  // a(t + h) ~ abar + (h / 2) (abar - abar_old) / ((h + h_last) / 2); on the
  // first step abar_old is a(0), half a step before abar.
  const double span = 0.5 * (h + h_last_);
  a_ = abar_ + (0.5 * h / span) * (abar_ - abar_old_);
  h_old_ = h_last_;
  h_last_ = h;
  t_old_ = t_;
  t_ += h;
  model_->SetTime(t_);
  return st;
}

void EnergyMomentumStepper::PlaceIterate() {
  z1_ = z_ + (0.5 * h_) * (v_ + v1_);
  model_->ToFull(z1_, &q1_);
  qm_ = 0.5 * (q0_ + q1_);
}

double EnergyMomentumStepper::EvaluateResidual(bool assemble, bool with_floor) {
  const double h = h_;
  if (assemble) LoadMass();
  const double force_size =
      Forces(h, &f_, assemble ? &solver_.a() : nullptr, with_floor ? &floor_ : nullptr);
  // Phi(z1, t + h) (jac1_ only as its scratch), and Phi_z(zm).
  model_->SetTime(t_ + h);
  model_->Constraints(q1_, &phi_, &jac1_);
  model_->Constraints(qm_, &phim_, &jacm_);
  // R_v = M (v1 - v0) - h f + Phi_z(zm)^T (h lambda).
  const double scale = VelocityResidual(v1_, f_, force_size, jacm_, h, &mdv_, &bt_mu_);
  if (m_ > 0) rhs_.tail(m_) = phi_ * (2 / h);
  return scale;
}

void EnergyMomentumStepper::ComputeFloor(bool with_floor) {
  const double h = h_;
  if (!with_floor) Forces(h, &f_floor_, nullptr, &floor_);
  VelocityResidualFloor(v1_, jacm_, h);
}

bool EnergyMomentumStepper::FactorMatrix(bool assembled, StepStats* st) {
  SkylineLdlt& a = solver_.a();
  if (!assembled) {
    LoadMass();
    Forces(h_, &f_floor_, &a, nullptr);
  }
  if (m_ > 0) model_->AddConstraintHessian(qm_, lambda1_, c_, &a);
  return FactorNewtonMatrix(&solver_, jacm_, c_, &kept_, st);
}

double EnergyMomentumStepper::ApplyCorrection() {
  v1_ += dx_.head(n_);
  if (m_ > 0) lambda1_ += dx_.tail(m_) / h_;
  return 0.5 * h_ * dx_.head(n_).lpNorm<Eigen::Infinity>();
}

}  // namespace cablesim
