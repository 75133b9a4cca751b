#include "engine/steppers/generalized_alpha_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"
#include "engine/steppers/newton_convergence.h"

namespace cablesim {
GeneralizedAlphaStepper::GeneralizedAlphaStepper(MultibodyModel* model,
                                                 const SolverSettings& settings, Variant variant)
    : ImplicitStepper(model, settings), variant_(variant) {
  finish_on_last_matrix_ = true;  // ImplicitStepper::kFinishRatio
  const double rho = std::clamp(settings.rho_infinity, 0.0, 1.0);
  if (variant == Variant::kGeneralizedAlpha) {
    alpha_m_ = (2 * rho - 1) / (rho + 1);
    alpha_f_ = rho / (rho + 1);
    gamma_ = 0.5 + alpha_f_ - alpha_m_;
    beta_ = 0.25 * (gamma_ + 0.5) * (gamma_ + 0.5);
    w_ = 1;
  } else {
    const double alpha = std::clamp((rho - 1) / (rho + 1), -1.0 / 3, 0.0);
    beta_ = 0.25 * (1 - alpha) * (1 - alpha);
    gamma_ = 0.5 - alpha;
    w_ = 1 + alpha;
  }
  jac_ = model->jacobian_pattern();
  acc_.setZero(n_);
  acc_h_.setZero(n_);
  g_.setZero(n_);
  for (Eigen::VectorXd* x : {&z_pred_, &v_pred_, &zdd1_, &f_, &bt_lambda_, &added_})
    x->setZero(n_);
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
  v1_.setZero(n_);
  acc_old_ = acc_;
  g_old_ = g_;
  floor_with_forces_when_judged_ = true;
}

double GeneralizedAlphaStepper::Forces(const Eigen::VectorXd& v, Eigen::VectorXd* f,
                                       SkylineLdlt* a, double c, double cd,
                                       Eigen::VectorXd* roundoff) {
  double size = model_->NetForce(q_, 1.0, f, a, c, roundoff);
  if (model_->has_damping()) {
    model_->RateToFull(v, &qd_);
    size = std::max(size, model_->DampingForce(q_, qd_, f, a, cd, roundoff, c));
  }
  return size;
}

bool GeneralizedAlphaStepper::Initialize(std::string* reason) {
  model_->SetTime(t_);
  model_->ToFull(z_, &q_);
  Forces(v_, &f_, nullptr, 0, 0, nullptr);
  model_->Constraints(q_, &phi_, &solver_.b());
  Eigen::VectorXd qdot(model_->coordinates()), gamma(m_);
  model_->RateToFull(v_, &qdot);
  model_->ConstraintGamma(q_, qdot, &gamma);
  LoadMass();
  // The added mass beyond M joins the matrix of the initial solve (its
  // force at zdd = 0 is zero).
  if (model_->has_added_mass_correction()) {
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
    added_.setZero();
    model_->AddedMassCorrection(q_, zero, &added_, &solver_.a(), 1.0);
  }
  kept_.have = false;
  if (!solver_.Prepare()) {
    *reason = "the mass matrix could not be factorized";
    return false;
  }
  rhs_.head(n_) = f_;
  if (m_ > 0) rhs_.tail(m_) = gamma;
  const auto stats = solver_.Solve(settings_.linear_solver, rhs_, 1e-12,
                                   std::max(settings_.max_linear_iterations, 1000), &dx_);
  if (!(stats.relative_residual <= 1e-8)) {
    *reason = absl::StrFormat(
        "the initial acceleration solve did not converge (relative residual %.3g)",
        stats.relative_residual);
    return false;
  }
  a_ = dx_.head(n_);
  acc_ = a_;  // a_0 = zdd_0 (Arnold and Bruls' starting value)
  lambda_ = dx_.tail(m_);
  // g_0 = Phi_z^T lambda_0 - f_0.
  g_ = -f_;
  solver_.b().AddTransposeMultiply(lambda_.data(), g_.data());
  KeepInitialState();
  acc_old_ = acc_;
  g_old_ = g_;
  return true;
}

void GeneralizedAlphaStepper::RestoreScheme() {
  acc_ = acc_old_;
  g_ = g_old_;
}

double GeneralizedAlphaStepper::LocalErrorNorm(double h, double atol, double rtol) const {
  return WeightedMaxNorm(h * h * std::abs(beta_ - 1.0 / 6), a_ - a_old_, z_, n_, atol, rtol);
}

Stepper::StepStats GeneralizedAlphaStepper::Step(double h) {
  model_->SetTime(t_ + h);
  return SolveWithFreshRetry(settings_.reuse_factorization, kept_.refresh,
                             [&](bool fresh) { return Solve(h, fresh); });
}

Stepper::StepStats GeneralizedAlphaStepper::Solve(double h, bool fresh) {
  const bool ga = variant_ == Variant::kGeneralizedAlpha;
  // Predictors: everything in z_{n+1}, v_{n+1} except s a_{n+1}.
  if (ga) {
    const double k = 1 / (1 - alpha_m_);
    // Variable steps: a_n approximates zdd(t_n + (alpha_m - alpha_f) h)
    // (Arnold and Bruls, section 3), so a change of h shifts it, to first
    // order a_n <- zdd_n + (h / h_last) (a_n - zdd_n). Without it, halving
    // and regrowing the step feeds energy into the stiff modes.
    acc_h_ = acc_;
    if (h_last_ > 0 && h != h_last_) acc_h_ = a_ + (h / h_last_) * (acc_ - a_);
    // a_{n+1} = k (alpha_f zdd_n - alpha_m a_n) + k (1 - alpha_f) a_{n+1}.
    bt_lambda_ = k * (alpha_f_ * a_ - alpha_m_ * acc_h_);  // scratch: known part of a_{n+1}
    z_pred_ = z_ + h * v_ + (h * h * (0.5 - beta_)) * acc_h_ + (h * h * beta_) * bt_lambda_;
    v_pred_ = v_ + (h * (1 - gamma_)) * acc_h_ + (h * gamma_) * bt_lambda_;
    s_ = h * h * beta_ * k * (1 - alpha_f_);
    sv_ = h * gamma_ * k * (1 - alpha_f_);
  } else {
    z_pred_ = z_ + h * v_ + (h * h * (0.5 - beta_)) * a_;
    v_pred_ = v_ + (h * (1 - gamma_)) * a_;
    s_ = h * h * beta_;
    sv_ = h * gamma_;
  }
  c_ = w_ * s_;
  // The damping's share of the Newton matrix: d v_{n+1} / d zdd = s_v.
  cd_ = w_ * sv_;
  // A kept matrix serves while c is within 20 % of its own (the last steps
  // shortened to end on the duration, or resized by the error controller): Newton
  // then still contracts by about that fraction, and Newton()'s safeguard
  // catches it when it does not.
  if (kept_.Stale(c_)) fresh = true;
  // Predictor: the acceleration extrapolated linearly from the last two
  // steps (constant on the first step and after Restore()).
  zdd1_ = a_;
  if (h_last_ > 0) zdd1_ += (h / h_last_) * (a_ - a_old_);
  lambda1_ = lambda_;
  StepStats st = Newton(fresh, settings_.reuse_factorization);
  if (!st.converged) return st;
  KeepPreviousState();
  acc_old_.swap(acc_);
  g_old_.swap(g_);
  z_ = z1_;
  v_ = v_pred_ + sv_ * zdd1_;
  if (ga) {
    const double k = 1 / (1 - alpha_m_);
    acc_ = k * (alpha_f_ * a_old_ - alpha_m_ * acc_h_ + (1 - alpha_f_) * zdd1_);
  } else {
    acc_ = zdd1_;
  }
  a_ = zdd1_;
  lambda_ = lambda1_;
  h_old_ = h_last_;
  h_last_ = h;
  // g_{n+1} from the converged evaluation (forces and Jacobian at z_{n+1}).
  g_ = bt_lambda_ - f_;
  t_old_ = t_;
  t_ += h;
  return st;
}

void GeneralizedAlphaStepper::PlaceIterate() {
  z1_ = z_pred_ + s_ * zdd1_;
  model_->ToFull(z1_, &q_);
  if (model_->has_damping()) v1_ = v_pred_ + sv_ * zdd1_;
}

double GeneralizedAlphaStepper::EvaluateResidual(bool assemble, bool with_floor) {
  double force_size;
  if (assemble) {
    LoadMass();
    force_size = Forces(v1_, &f_, &solver_.a(), c_, cd_, nullptr);
  } else {
    force_size = Forces(v1_, &f_, nullptr, 0, 0, with_floor ? &floor_ : nullptr);
  }
  model_->Constraints(q_, &phi_, &jac_);
  // R = M zdd + w (Phi_z^T lambda - f) + (1 - w) g_n.
  auto r = rhs_.head(n_);
  if (with_floor) {
    abs_terms_.setZero();
    model_->mass().MultiplyWithAbs(zdd1_.data(), r.data(), abs_terms_.data());
  } else {
    model_->mass().Multiply(zdd1_.data(), r.data());
  }
  // The cables' added mass beyond M (CableAddedMass): its force -D zdd
  // moves to the inertia side, and D joins M in the Newton matrix.
  if (model_->has_added_mass_correction()) {
    added_.setZero();
    model_->AddedMassCorrection(q_, zdd1_, &added_, assemble ? &solver_.a() : nullptr, 1.0);
    r -= added_;
  }
  const double inertia = r.lpNorm<Eigen::Infinity>();
  bt_lambda_.setZero();
  jac_.AddTransposeMultiply(lambda1_.data(), bt_lambda_.data());
  const double scale =
      std::max({inertia, w_ * force_size, w_ * bt_lambda_.lpNorm<Eigen::Infinity>(),
                (1 - w_) * g_.lpNorm<Eigen::Infinity>(), 1e-300});
  r += w_ * (bt_lambda_ - f_);
  if (w_ != 1) r += (1 - w_) * g_;
  if (m_ > 0) rhs_.tail(m_) = phi_ / s_;
  return scale;
}

void GeneralizedAlphaStepper::ComputeFloor(bool with_floor) {
  // floor = w roundoff(f) + rounding of the other terms summed into R
  // (the forces once more for their bound, unless it came with them).
  if (!with_floor) {
    Forces(v1_, &f_floor_, nullptr, 0, 0, &floor_);
    abs_terms_.setZero();
    model_->mass().AddAbsMultiply(zdd1_.data(), abs_terms_.data());
  }
  jac_.AddAbsTransposeMultiply(lambda1_.data(), abs_terms_.data(), w_);
  floor_ = w_ * floor_ + kSumRounding * (abs_terms_ + (1 - w_) * g_.cwiseAbs());
}

bool GeneralizedAlphaStepper::FactorMatrix(bool assembled, StepStats* st) {
  SkylineLdlt& a = solver_.a();
  if (!assembled) {
    LoadMass();
    Forces(v1_, &f_, &a, c_, cd_, nullptr);
    if (model_->has_added_mass_correction()) {
      added_.setZero();
      model_->AddedMassCorrection(q_, zdd1_, &added_, &a, 1.0);
    }
  }
  if (m_ > 0) model_->AddConstraintHessian(q_, lambda1_, c_, &a);
  return FactorNewtonMatrix(&solver_, jac_, c_, &kept_, st);
}

double GeneralizedAlphaStepper::ApplyCorrection() {
  zdd1_ += dx_.head(n_);
  if (m_ > 0) lambda1_ += dx_.tail(m_) / w_;
  return s_ * dx_.head(n_).lpNorm<Eigen::Infinity>();
}

}  // namespace cablesim
