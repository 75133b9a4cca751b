#include "engine/static_solver.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace cablesim {

StaticSolver::StaticSolver(MultibodyModel* model, const SolverSettings& settings)
    : model_(model), settings_(settings) {
  n_ = model->dofs();
  m_ = model->multipliers();
  solver_.Resize(model->envelope(), model->jacobian_pattern());
  z_ = model->initial_z();
  lambda_.setZero(m_);
  z1_.setZero(n_);
  lambda1_.setZero(m_);
  q_.setZero(model->coordinates());
  f_.setZero(n_);
  phi_.setZero(m_);
  rhs_.setZero(n_ + m_);
  dx_.setZero(n_ + m_);
  bt_l_.setZero(n_);
}

StaticSolver::IncrementStats StaticSolver::Solve(double alpha) {
  IncrementStats st;
  const double tol = settings_.newton_tolerance;
  z1_ = z_;
  lambda1_ = lambda_;
  double last_increment = 0;
  // Statics takes more Newton iterations than a time step: it starts from
  // the previous equilibrium, not from a predictor one step away.
  const int max_it = std::max(settings_.max_newton_iterations, 50);
  for (int it = 0; it <= max_it; ++it) {
    model_->ToFull(z1_, &q_);
    SkylineLdlt& a = solver_.a();
    a.SetZero();
    const double force_size = model_->NetForce(q_, alpha, &f_, &a, 1.0);
    model_->Constraints(q_, &phi_, &solver_.b());
    bt_l_.setZero();
    solver_.b().AddTransposeMultiply(lambda1_.data(), bt_l_.data());
    // R = -f + Phi_z^T lambda.
    auto r = rhs_.head(n_);
    const double scale = std::max({force_size, bt_l_.lpNorm<Eigen::Infinity>(), 1e-300});
    r = bt_l_ - f_;
    if (m_ > 0) rhs_.tail(m_) = phi_;
    const double zscale = 1 + z1_.lpNorm<Eigen::Infinity>();
    const double res = r.lpNorm<Eigen::Infinity>() / scale;
    const double viol = m_ > 0 ? phi_.lpNorm<Eigen::Infinity>() : 0.0;
    if (!std::isfinite(res)) {
      st.reason = "the residual is not finite";
      return st;
    }
    const double floor = model_->force_roundoff() / scale;  // rounding level
    if (it > 0 && last_increment <= tol * zscale && res <= tol + floor &&
        viol <= tol * zscale) {
      st.converged = true;
      st.residual = res;
      break;
    }
    if (it == max_it) {
      st.reason = absl::StrFormat(
          "Newton did not converge in %d iterations (increment %.3g, relative residual %.3g)",
          it, last_increment, res);
      return st;
    }
    if (m_ > 0) {
      model_->AddConstraintHessian(q_, lambda1_, 1.0, &a);
      // Bodies have no stiffness: only the constraints hold them, so A alone
      // is singular. The augmented Lagrangian gamma B^T B, with gamma the
      // size of A's diagonal, makes it definite without changing the answer.
      double diag = 0;
      for (int j = 0; j < n_; ++j) diag = std::max(diag, std::abs(a.values()[a.Slot(j, j)]));
      solver_.Augment(diag > 0 ? diag : 1.0);
    }
    if (!solver_.Prepare()) {
      st.reason = "the tangent stiffness has a non-finite pivot";
      return st;
    }
    rhs_ = -rhs_;
    const auto ls = solver_.Solve(settings_.linear_solver, rhs_, settings_.linear_tolerance,
                                  std::max(settings_.max_linear_iterations, 1000), &dx_);
    ++st.newton_iterations;
    st.linear_iterations += ls.iterations;
    st.max_linear_residual = std::max(st.max_linear_residual, ls.relative_residual);
    if (!(ls.relative_residual <= 1e-6)) {
      st.reason = absl::StrFormat(
          "the linear solve did not converge (true relative residual %.3g): the tangent "
          "stiffness is singular or nearly so (is the scene a mechanism?)",
          ls.relative_residual);
      return st;
    }
    z1_ += dx_.head(n_);
    if (m_ > 0) lambda1_ += dx_.tail(m_);
    last_increment = dx_.head(n_).lpNorm<Eigen::Infinity>();
    if (!std::isfinite(last_increment) || last_increment > 1e6 * zscale) {
      st.reason = "Newton diverged";
      return st;
    }
  }
  z_ = z1_;
  lambda_ = lambda1_;
  return st;
}

}  // namespace cablesim
