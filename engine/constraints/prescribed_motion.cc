#include "engine/constraints/prescribed_motion.h"

#include <cmath>
#include <utility>

#include <Eigen/Geometry>

namespace cablesim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

// n . x with x the first D entries of v from index i (a plain loop: GCC
// 12 warns falsely about head(D) of a fixed-size vector).
double DotAt(const Vector3d& n, const VectorXd& v, int i, int D) {
  double sum = 0;
  for (int d = 0; d < D; ++d) sum += n(d) * v(i + d);
  return sum;
}

}  // namespace

Vector3d PrescribedMotion::TurningRow::Normal(double t, Vector3d* rate_out,
                                              Vector3d* accel_out) const {
  const TimeFunction::Value v = angle.Evaluate(t);
  const double c = std::cos(v.f), s = std::sin(v.f);
  const Vector3d n = c * n0 + s * axis.cross(n0) + (1 - c) * axis.dot(n0) * axis;
  if (rate_out != nullptr) {
    const Vector3d an = axis.cross(n);
    *rate_out = v.df * an;
    *accel_out = v.ddf * an + v.df * v.df * axis.cross(an);
  }
  return n;
}

PrescribedMotion::PrescribedMotion(JointRows* rows, std::vector<MovingRow> moving,
                                   std::vector<TurningRow> turning, int dim)
    : rows_(rows), moving_(std::move(moving)), turning_(std::move(turning)), dim_(dim) {}

void PrescribedMotion::SetTime(double t) {
  for (MovingRow& m : moving_) {
    const TimeFunction::Value v = m.motion.Evaluate(t);
    rows_->SetConstant(m.row, m.c0 - v.f);
    m.rate = v.df;
    m.accel = v.ddf;
  }
  for (TurningRow& r : turning_) {
    r.n = r.Normal(t, &r.rate, &r.accel);
    rows_->SetLinear(r.row, r.n, r.coord);
  }
}

void PrescribedMotion::AddGamma(const VectorXd& q, const VectorXd& qdot, VectorXd* gamma) const {
  for (const MovingRow& m : moving_) (*gamma)(m.row) += m.accel;
  for (const TurningRow& r : turning_) {
    (*gamma)(r.row) -=
        2 * DotAt(r.rate, qdot, r.coord, dim_) + DotAt(r.accel, q, r.coord, dim_);
  }
}

void PrescribedMotion::AddRate(const VectorXd& q, VectorXd* phi_t) const {
  for (const MovingRow& m : moving_) (*phi_t)(m.row) -= m.rate;
  for (const TurningRow& r : turning_) (*phi_t)(r.row) += DotAt(r.rate, q, r.coord, dim_);
}

void PrescribedMotion::AddStepWork(const ConstraintStep& step, double* work) const {
  const VectorXd& lambda_before = *step.lambda_before;
  const VectorXd& lambda_after = *step.lambda_after;
  for (const MovingRow& m : moving_) {
    const double lambda = 0.5 * (lambda_before(m.row) + lambda_after(m.row));
    *work -= lambda * (m.motion(step.t_after) - m.motion(step.t_before));
  }
  for (const TurningRow& r : turning_) {
    const double lambda = 0.5 * (lambda_before(r.row) + lambda_after(r.row));
    const Vector3d dn = r.Normal(step.t_after) - r.Normal(step.t_before);
    *work += lambda * 0.5 *
             (DotAt(dn, *step.q_before, r.coord, dim_) + DotAt(dn, *step.q_after, r.coord, dim_));
  }
}

}  // namespace cablesim
