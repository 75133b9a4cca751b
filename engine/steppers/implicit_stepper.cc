#include "engine/steppers/implicit_stepper.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"

#include "engine/steppers/newton_convergence.h"

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
  z1_.setZero(n_);
  lambda1_.setZero(m_);
  phi_.setZero(m_);
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

Stepper::StepStats ImplicitStepper::Newton(bool fresh, bool reuse) {
  StepStats st;
  const double tol = settings_.newton_tolerance;
  double last_increment = 0, previous_increment = 0;
  bool previous_at_floor = false;
  // Whether this solve may still finish on the last factored matrix
  // (kFinishOnLastMatrix): false once doing so failed to contract.
  bool may_finish_on_last = finish_on_last_matrix_ && fresh && !reuse;
  for (int it = 0; it <= settings_.max_newton_iterations; ++it) {
    PlaceIterate();
    // A checking iteration follows a correction already below tol: it is
    // expected to be the converged one.
    const bool checking = it > 0 && last_increment <= tol * (1 + z1_.lpNorm<Eigen::Infinity>());
    // The rounding floor is needed where convergence is judged (and for the
    // message of the last iteration), unless the residual is below tol.
    const bool judge = checking || it == settings_.max_newton_iterations;
    // A fresh matrix every iteration (reuse false) stops refreshing once
    // Newton is in its quadratic phase near the solution: the last
    // correction shrank at least kFinishRatio times against the one before
    // and is within kFinishNear of the convergence test's tol (1 + |z|).
    // The matrix of the iterate before then differs from a fresh one by
    // O(correction) (relative), so the corrections still contract about as
    // fast, and the iteration skips the matrix's assembly and its
    // factoring (measured: OC4's three lines, 10 elements, h = 0.75 s:
    // factorizations 2,638 -> 2,046, Newton iterations 2,743 -> 2,853,
    // instructions -9.5 %, fairlead tensions within 5e-10). A correction
    // that did not halve asks for fresh matrices again for the rest of
    // the solve. Convergence is judged as before, on the true residual.
    const bool finish_on_last =
        may_finish_on_last && it >= 2 && last_increment <= kFinishRatio * previous_increment &&
        last_increment <= kFinishNear * tol * (1 + z1_.lpNorm<Eigen::Infinity>());
    // Assemble the Newton matrix with the forces when this iteration will
    // need a fresh one and is not expected to be the converged one.
    const bool assemble = fresh && !checking && !finish_on_last;
    // The forces' rounding bound in the same pass when the last step was
    // accepted at its floor: this one most likely will be too.
    const bool with_floor =
        !assemble && (floor_with_forces_when_judged_ ? judge : checking) && floor_expected_;
    const double scale = EvaluateResidual(assemble, with_floor);
    auto r = rhs_.head(n_);
    NewtonIterate iterate;
    if (!BeginIterate(r, scale, phi_, z1_, last_increment, previous_increment,
                      previous_at_floor, &iterate)) {
      st.reason = NotFiniteReason();
      return st;
    }
    previous_at_floor = false;
    const bool plain = iterate.residual <= tol && iterate.violation <= tol * iterate.zscale;
    if (judge && !(checking && plain)) {
      ComputeFloor(with_floor);
      MeasureResidual(r, floor_, scale, &iterate);
      previous_at_floor = iterate.excess <= tol;
    }
    if (checking && NewtonConverged(iterate, tol)) {
      floor_expected_ = !plain;
      AcceptIterate(iterate, &st);
      return st;
    }
    if (it == settings_.max_newton_iterations) {
      st.reason = NewtonFailure(it, iterate);
      if (reuse) kept_.refresh = true;
      return st;
    }
    if (fresh && !finish_on_last) {
      if (!FactorMatrix(assemble, &st)) return st;
      // Keep this matrix for the next iterations only when asked to.
      fresh = !reuse;
    }
    if (!SolveNewtonSystem(&solver_, settings_, &rhs_, &dx_, &st)) {
      if (reuse) kept_.refresh = true;
      return st;
    }
    const double increment = ApplyCorrection();
    if (!std::isfinite(increment) || increment > 1e6 * iterate.zscale) {
      st.reason = "Newton diverged";
      if (reuse) kept_.refresh = true;
      return st;
    }
    if (finish_on_last && increment > 0.5 * last_increment) may_finish_on_last = false;
    // Safeguard of the kept matrix: slow contraction asks for a fresh one.
    if (reuse && it > 0 && increment > 0.5 * last_increment) fresh = true;
    previous_increment = last_increment;
    last_increment = increment;
  }
  return st;  // not reached: the last iteration returns above
}

std::string ImplicitStepper::NotFiniteReason() const {
  Eigen::VectorXd q(model_->coordinates()), qdot(model_->coordinates());
  model_->ToFull(z1_, &q);
  model_->RateToFull(IterateVelocity(), &qdot);
  const std::string where =
      model_->DescribeNonFinite(q, model_->has_damping() ? &qdot : nullptr, 1.0);
  return where.empty() ? std::string(kNotFiniteResidual)
                       : absl::StrCat(kNotFiniteResidual, ": ", where);
}

double ImplicitStepper::VelocityResidual(const Eigen::VectorXd& v1, const Eigen::VectorXd& f,
                                         double force_size, const SparseRows& jac, double h,
                                         Eigen::VectorXd* mdv, Eigen::VectorXd* bt_mu) {
  *mdv = v1 - v_;
  model_->mass().Multiply(mdv->data(), rhs_.data());
  auto rv = rhs_.head(n_);
  bt_mu->setZero();
  jac.AddTransposeMultiply(lambda1_.data(), bt_mu->data());
  *bt_mu *= h;
  const double scale = std::max({rv.lpNorm<Eigen::Infinity>(), h * force_size,
                                 bt_mu->lpNorm<Eigen::Infinity>(), 1e-300});
  rv += *bt_mu - h * f;
  return scale;
}

void ImplicitStepper::VelocityResidualFloor(const Eigen::VectorXd& v1, const SparseRows& jac,
                                            double h) {
  abs_terms_.setZero();
  model_->mass().AddAbsMultiply(v1.data(), abs_terms_.data());
  model_->mass().AddAbsMultiply(v_.data(), abs_terms_.data());
  jac.AddAbsTransposeMultiply(lambda1_.data(), abs_terms_.data(), h);
  floor_ = h * floor_ + kSumRounding * abs_terms_;
}

}  // namespace cablesim
