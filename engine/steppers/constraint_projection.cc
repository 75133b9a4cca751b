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
  w_.setZero(n_, m_);
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
  w_.setZero();
  for (int r = 0; r < m_; ++r) {
    for (int k = jac_.row_start[r]; k < jac_.row_start[r + 1]; ++k)
      w_(jac_.col[k], r) += jac_.value[k];
    mass_->Solve(w_.col(r).data());
  }
  for (int c = 0; c < m_; ++c) jac_.Multiply(w_.col(c).data(), s_.col(c).data());
  // Symmetric in exact arithmetic: average the rounding away.
  for (int c = 0; c < m_; ++c)
    for (int r = c + 1; r < m_; ++r) s_(r, c) = s_(c, r) = 0.5 * (s_(r, c) + s_(c, r));
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
    dz_.noalias() = w_ * x_;
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
  v->noalias() -= w_ * x_;
}

void ConstraintProjection::ConsistentAcceleration(const Eigen::VectorXd& v, Eigen::VectorXd* a,
                                                  Eigen::VectorXd* lambda) {
  model_->RateToFull(v, &qd_);
  model_->ConstraintGamma(q_, qd_, &gamma_);
  jac_.Multiply(a->data(), phi_.data());
  phi_ -= gamma_;
  *lambda = s_ldlt_.solve(phi_);
  a->noalias() -= w_ * *lambda;
}

}  // namespace cablesim
