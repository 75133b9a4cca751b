#include "engine/steppers/constraint_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"
#include "engine/constraints/constraint.h"

namespace cablesim {

ConstraintProjection::ConstraintProjection(MultibodyModel* model, const SkylineLdlt* mass)
    : model_(model), mass_(mass), n_(model->dofs()), m_(model->multipliers()),
      jac_(model->jacobian_pattern()), s_ldlt_(model->multipliers()) {
  y_.setZero(n_, m_);
  from_.assign(m_, n_);
  for (int r = 0; r < m_; ++r)
    for (int k = jac_.row_start[r]; k < jac_.row_start[r + 1]; ++k)
      from_[r] = std::min(from_[r], jac_.col[k]);
  s_.setZero(m_, m_);
  q_.setZero(model->coordinates());
  qd_.setZero(model->coordinates());
  phi_.setZero(m_);
  x_.setZero(m_);
  gamma_.setZero(m_);
  dz_.setZero(n_);
}

bool ConstraintProjection::Rebuild(const Eigen::VectorXd& z) {
  model_->ToFull(z, &q_);
  model_->Constraints(q_, &phi_, &jac_);
  for (int r = 0; r < m_; ++r) {
    double* y = y_.col(r).data();
    std::fill(y + std::min(from_[r], n_), y + n_, 0.0);
    for (int k = jac_.row_start[r]; k < jac_.row_start[r + 1]; ++k) y[jac_.col[k]] += jac_.value[k];
    mass_->ForwardSolve(y, from_[r]);
  }
  for (int c = 0; c < m_; ++c) {
    for (int r = c; r < m_; ++r) {
      double acc = 0;
      const double* yr = y_.col(r).data();
      const double* yc = y_.col(c).data();
      for (int i = std::max(from_[r], from_[c]); i < n_; ++i) acc += yr[i] * yc[i] / mass_->pivot(i);
      s_(r, c) = s_(c, r) = acc;
    }
  }
  if (!s_.allFinite()) return false;
  s_ldlt_.compute(s_);
  return s_ldlt_.info() == Eigen::Success;
}

bool ConstraintProjection::ProjectPositions(double h, Eigen::VectorXd* z1,
                                            Eigen::VectorXd* v_half, std::string* reason) {
  double previous = std::numeric_limits<double>::infinity();
  for (int it = 0; it <= kMaxIterations; ++it) {
    model_->ToFull(*z1, &q_);
    model_->Constraints(q_, &phi_, nullptr);
    const double err = phi_.lpNorm<Eigen::Infinity>();
    const double scale = 1 + z1->lpNorm<Eigen::Infinity>();
    // Converged, or stalled (not halving) within a thousand times the
    // tolerance: what rounding leaves.
    if (err <= kTolerance * scale || (err > 0.5 * previous && err <= 1e3 * kTolerance * scale)) {
      last_residual_ = err;
      return true;
    }
    if (!std::isfinite(err) || it == kMaxIterations) break;
    previous = err;
    x_ = s_ldlt_.solve(phi_);
    ApplyW(x_);
    *z1 -= dz_;
    *v_half -= (1.0 / h) * dz_;
  }
  *reason = absl::StrFormat(
      "the constraint rows could not be held after the explicit step (h = %.3g s: |Phi| = %.3g "
      "after %d projection iterations; likely beyond CENTRAL_DIFFERENCE's stability limit)",
      h, phi_.lpNorm<Eigen::Infinity>(), kMaxIterations);
  return false;
}

void ConstraintProjection::ProjectVelocity(Eigen::VectorXd* v) {
  // phi_ is scratch here: G v + Phi_t.
  jac_.Multiply(v->data(), phi_.data());
  for (const ConstraintFamily* f : model_->constraint_families()) f->AddRate(q_, &phi_);
  x_ = s_ldlt_.solve(phi_);
  ApplyW(x_);
  *v -= dz_;
}

void ConstraintProjection::ConsistentAcceleration(const Eigen::VectorXd& v, Eigen::VectorXd* a,
                                                  Eigen::VectorXd* lambda) {
  model_->RateToFull(v, &qd_);
  model_->ConstraintGamma(q_, qd_, &gamma_);
  jac_.Multiply(a->data(), phi_.data());
  phi_ -= gamma_;
  *lambda = s_ldlt_.solve(phi_);
  ApplyW(*lambda);
  *a -= dz_;
}

void ConstraintProjection::ApplyW(const Eigen::VectorXd& x) {
  dz_.setZero();
  jac_.AddTransposeMultiply(x.data(), dz_.data());
  mass_->Solve(dz_.data());
}

}  // namespace cablesim
