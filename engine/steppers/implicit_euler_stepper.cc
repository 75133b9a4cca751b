#include "engine/steppers/implicit_euler_stepper.h"

#include <algorithm>
#include <cmath>

#include "engine/steppers/newton_convergence.h"

namespace cablesim {

ImplicitEulerStepper::ImplicitEulerStepper(MultibodyModel* model, const SolverSettings& settings)
    : ImplicitStepper(model, settings) {
  for (Eigen::VectorXd* x : {&v1_, &f_, &mdv_, &bt_mu_}) x->setZero(n_);
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
}

double ImplicitEulerStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  return WeightedMaxNorm(0.5 * h * h, a_, z_, n_, atol, rtol);
}

bool ImplicitEulerStepper::Initialize(std::string* reason) {
  model_->SetTime(t_);
  model_->ToFull(z_, &q_);
  Forces(v_, &f_, nullptr, 0, nullptr);
  model_->Constraints(q_, &phi_, &solver_.b());
  Eigen::VectorXd qdot(model_->coordinates()), gamma(m_);
  model_->RateToFull(v_, &qdot);
  model_->ConstraintGamma(q_, qdot, &gamma);
  LoadMass();
  if (!SolveInitialAcceleration(&solver_, settings_, f_, gamma, &rhs_, &dx_, reason)) return false;
  a_ = dx_.head(n_);
  lambda_ = dx_.tail(m_);
  KeepInitialState();
  return true;
}

double ImplicitEulerStepper::Forces(const Eigen::VectorXd& v, Eigen::VectorXd* f,
                                    SkylineLdlt* a, double h, Eigen::VectorXd* roundoff) {
  double size = model_->NetForce(q_, 1.0, f, a, h * h, roundoff);
  if (model_->has_damping()) {
    model_->RateToFull(v, &qd_);
    size = std::max(size, model_->DampingForce(q_, qd_, f, a, h, roundoff, h * h));
  }
  return size;
}

double ImplicitEulerStepper::AssembleForces(double h) {
  LoadMass();
  return Forces(v1_, &f_, &solver_.a(), h, nullptr);
}

ImplicitEulerStepper::StepStats ImplicitEulerStepper::Step(double h) {
  h_ = h;
  model_->SetTime(t_ + h);
  v1_ = v_ + h * a_;
  lambda1_ = lambda_;
  // A fresh Newton matrix every iteration.
  StepStats st = Newton(/*fresh=*/true, /*reuse=*/false);
  if (!st.converged) return st;
  // Keep the previous state for Restore() (swaps, no copies: z1_, v1_ and
  // lambda1_ are rewritten at the start of every step).
  KeepPreviousState();
  z_.swap(z1_);
  v_.swap(v1_);
  lambda_.swap(lambda1_);
  a_ = (v_ - v_old_) / h;
  t_old_ = t_;
  t_ += h;
  return st;
}

void ImplicitEulerStepper::PlaceIterate() {
  z1_ = z_ + h_ * v1_;
  model_->ToFull(z1_, &q_);
}

double ImplicitEulerStepper::EvaluateResidual(bool assemble, bool with_floor) {
  const double h = h_;
  // Newton matrix M + h^2 (K_T + H_lambda), assembled with the forces
  // unless this evaluation is expected to be the converged one.
  const double force_size = assemble ? AssembleForces(h)
                                     : Forces(v1_, &f_, nullptr, h, with_floor ? &floor_ : nullptr);
  model_->Constraints(q_, &phi_, &solver_.b());
  // R_v = M (v1 - v0) - h f + Phi_z^T (h lambda).
  const double scale = VelocityResidual(v1_, f_, force_size, solver_.b(), h, &mdv_, &bt_mu_);
  if (m_ > 0) rhs_.tail(m_) = phi_ / h;
  return scale;
}

void ImplicitEulerStepper::ComputeFloor(bool with_floor) {
  const double h = h_;
  // floor = h roundoff(f) + rounding of the other terms summed into R_v
  // (M v1, M v0 and h Phi_z^T lambda); the forces once more, for their
  // bound, only where it matters, unless it came with them.
  if (!with_floor) Forces(v1_, &f_floor_, nullptr, h, &floor_);
  VelocityResidualFloor(v1_, solver_.b(), h);
}

bool ImplicitEulerStepper::FactorMatrix(bool assembled, StepStats* st) {
  if (!assembled) AssembleForces(h_);
  if (m_ > 0) model_->AddConstraintHessian(q_, lambda1_, h_ * h_, &solver_.a());
  if (!solver_.Prepare()) {
    st->reason = "the Newton matrix has a non-finite pivot";
    return false;
  }
  ++st->factorizations;
  return true;
}

double ImplicitEulerStepper::ApplyCorrection() {
  v1_ += dx_.head(n_);
  if (m_ > 0) lambda1_ += dx_.tail(m_) / h_;
  return h_ * dx_.head(n_).lpNorm<Eigen::Infinity>();
}

}  // namespace cablesim
