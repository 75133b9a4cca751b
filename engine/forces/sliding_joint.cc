#include "engine/forces/sliding_joint.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace cablesim {
namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
}  // namespace

using Eigen::Vector3d;
using Eigen::VectorXd;

SlidingJoint::SlidingJoint(int dim, std::vector<Segment> segments, int body_coord,
                           int body_stride, const Vector3d& point, double stiffness,
                           double friction, double stick_velocity, double s_start)
    : dim_(dim),
      segments_(std::move(segments)),
      body_coord_(body_coord),
      body_stride_(body_stride),
      stiffness_(stiffness),
      friction_(friction),
      stick_velocity_(stick_velocity),
      length_(segments_.back().s0 + segments_.back().length),
      s_(s_start) {
  // x = r_c + p_x e1 + p_y e2 (+ p_z e3); planar e2 = perp(u) = (-u_y, u_x).
  for (int d = 0; d < dim_; ++d) p_(d, d) = 1;
  if (dim_ == 2) {
    p_(0, 2) = point.x();
    p_(1, 3) = point.x();
    p_(0, 3) = -point.y();
    p_(1, 2) = point.y();
  } else {
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) p_(d, 3 + 3 * k + d) = point(k);
  }
}

void SlidingJoint::ShapeAt(double s, Shape* sh) const {
  int k = seg_;
  while (k > 0 && s < segments_[k].s0) --k;
  while (k + 1 < static_cast<int>(segments_.size()) && s > segments_[k + 1].s0) ++k;
  seg_ = k;
  sh->seg = k;
  const double l = segments_[k].length, xi = (s - segments_[k].s0) / l;
  const double x2 = xi * xi, x3 = x2 * xi;
  // MODEL.md section 1, and their derivatives in s = s0 + xi l.
  sh->n[0] = 1 - 3 * x2 + 2 * x3;
  sh->n[1] = l * (xi - 2 * x2 + x3);
  sh->n[2] = 3 * x2 - 2 * x3;
  sh->n[3] = l * (x3 - x2);
  sh->n1[0] = (-6 * xi + 6 * x2) / l;
  sh->n1[1] = 1 - 4 * xi + 3 * x2;
  sh->n1[2] = (6 * xi - 6 * x2) / l;
  sh->n1[3] = 3 * x2 - 2 * xi;
  sh->n2[0] = (-6 + 12 * xi) / (l * l);
  sh->n2[1] = (-4 + 6 * xi) / l;
  sh->n2[2] = (6 - 12 * xi) / (l * l);
  sh->n2[3] = (6 * xi - 2) / l;
}

Vector3d SlidingJoint::Interpolate(const VectorXd& q, const Shape& sh, const double* w) const {
  Vector3d r = Vector3d::Zero();
  const int c = segments_[sh.seg].first_coord;
  for (int a = 0; a < 4; ++a)
    for (int d = 0; d < dim_; ++d) r(d) += w[a] * q(c + a * dim_ + d);
  return r;
}

Vector3d SlidingJoint::Point(const VectorXd& q) const {
  Vector3d x = Vector3d::Zero();
  for (int k = 0; k < body_stride_; ++k) x += p_.col(k) * q(body_coord_ + k);
  return x;
}

void SlidingJoint::Locate(const VectorXd& q) const {
  const Vector3d x = Point(q);
  Shape sh;
  double s = std::clamp(s_, 0.0, length_);
  double last_move = 0;
  for (int it = 0; it < 50; ++it) {
    ShapeAt(s, &sh);
    const Vector3d d = Interpolate(q, sh, sh.n) - x;
    const Vector3d r1 = Interpolate(q, sh, sh.n1), r2 = Interpolate(q, sh, sh.n2);
    const double f1 = r1.dot(d), f2 = r1.squaredNorm() + r2.dot(d);
    const double l = segments_[sh.seg].length;
    // Newton where the distance is convex in s, else a half element downhill.
    double step = f2 > 0 ? -f1 / f2 : (f1 > 0 ? -0.5 : 0.5) * l;
    step = std::clamp(step, -l, l);
    const double next = std::clamp(s + step, 0.0, length_);
    // To the last bits of s: a tangential error ds leaves a force k |r'| ds
    // along the cable, and k is large.
    const double moved = std::abs(next - s);
    s = next;
    if (moved <= 4 * kEps * length_ || (moved < 1e-6 * l && it > 0 && moved >= 0.5 * last_move))
      break;
    last_move = moved;
  }
  s_ = s;
  ShapeAt(s, &sh);
}

void SlidingJoint::Jacobian(const Shape& sh, Local* out,
                            Eigen::Matrix<double, 3, kMaxLocal>* g) const {
  const int ne = 4 * dim_;
  out->n = ne + body_stride_;
  const int c = segments_[sh.seg].first_coord;
  for (int k = 0; k < ne; ++k) out->coord[k] = c + k;
  for (int k = 0; k < body_stride_; ++k) out->coord[ne + k] = body_coord_ + k;
  g->setZero();
  for (int a = 0; a < 4; ++a)
    for (int d = 0; d < dim_; ++d) (*g)(d, a * dim_ + d) = sh.n[a];
  for (int k = 0; k < body_stride_; ++k) g->col(ne + k) = -p_.col(k);
}

double SlidingJoint::Penalty(const VectorXd& q, Local* out, bool tangent) const {
  Locate(q);
  Shape sh;
  ShapeAt(s_, &sh);
  const Vector3d d = Interpolate(q, sh, sh.n) - Point(q);
  const double energy = 0.5 * stiffness_ * d.squaredNorm();
  if (out == nullptr) return energy;
  Eigen::Matrix<double, 3, kMaxLocal> g;
  Jacobian(sh, out, &g);
  const int n = out->n;
  out->force = -stiffness_ * g.leftCols(n).transpose() * d;
  const Vector3d r = Interpolate(q, sh, sh.n);
  out->rounding = 4 * kEps * stiffness_ *
                  (r.lpNorm<Eigen::Infinity>() + (r - d).lpNorm<Eigen::Infinity>() +
                   Interpolate(q, sh, sh.n1).norm() * length_);
  if (!tangent) return energy;
  out->matrix = stiffness_ * g.leftCols(n).transpose() * g.leftCols(n);
  const bool interior = s_ > 0 && s_ < length_;
  if (interior) {
    const Vector3d r1 = Interpolate(q, sh, sh.n1), r2 = Interpolate(q, sh, sh.n2);
    const double fss = stiffness_ * (r1.squaredNorm() + r2.dot(d));
    if (fss > 0) {
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxLocal, 1> gs =
          stiffness_ * g.leftCols(n).transpose() * r1;
      for (int a = 0; a < 4; ++a)
        for (int dd = 0; dd < dim_; ++dd) gs(a * dim_ + dd) += stiffness_ * sh.n1[a] * d(dd);
      out->matrix -= gs * gs.transpose() / fss;
    }
  }
  return energy;
}

double SlidingJoint::Friction(const VectorXd& q, const VectorXd& qdot, Local* out,
                              bool tangent) const {
  Locate(q);
  Shape sh;
  ShapeAt(s_, &sh);
  const Vector3d d = Interpolate(q, sh, sh.n) - Point(q);
  const Vector3d r1 = Interpolate(q, sh, sh.n1);
  const Vector3d t = r1.normalized();
  const double normal = stiffness_ * d.norm();
  Eigen::Matrix<double, 3, kMaxLocal> g;
  Local local;
  Local* o = out ? out : &local;
  Jacobian(sh, o, &g);
  const int n = o->n;
  // v_t = t . (xdot - rdot) = w . qdot_local, w = -G^T t.
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxLocal, 1> w = -g.leftCols(n).transpose() * t;
  double vt = 0;
  for (int k = 0; k < n; ++k) vt += w(k) * qdot(o->coord[k]);
  const double sat = std::tanh(vt / stick_velocity_);
  const double power = friction_ * normal * sat * vt;
  if (out == nullptr) return power;
  out->force = -friction_ * normal * sat * w;
  if (tangent)
    out->matrix = (friction_ * normal * (1 - sat * sat) / stick_velocity_) * w * w.transpose();
  return power;
}

double SlidingJoint::Gap(const VectorXd& q) const {
  Locate(q);
  Shape sh;
  ShapeAt(s_, &sh);
  return (Interpolate(q, sh, sh.n) - Point(q)).norm();
}

void AddLocalTerms(const SlidingJoint::Local& local, ForceOutput* out) {
  for (int k = 0; k < local.n; ++k) {
    (*out->full)(local.coord[k]) += local.force(k);
    if (out->roundoff)
      (*out->roundoff)(local.coord[k]) += kEps * std::abs(local.force(k)) + local.rounding;
  }
  if (out->matrix)
    out->map.Scatter(local.coord.data(), local.n, local.matrix.data(),
                     static_cast<int>(local.matrix.rows()), out->scale, out->matrix);
}

void SlidingJoints::AddConservative(const ForceState& s, ForceOutput* out) const {
  for (const SlidingJoint& slider : sliders_) {
    SlidingJoint::Local local;
    slider.Penalty(*s.q, &local, out->matrix != nullptr);
    AddLocalTerms(local, out);
    out->size = std::max(out->size, local.force.lpNorm<Eigen::Infinity>());
  }
}

void SlidingJoints::AddDissipative(const ForceState& s, ForceOutput* out) const {
  for (const SlidingJoint& slider : sliders_) {
    if (!slider.has_friction()) continue;
    SlidingJoint::Local local;
    slider.Friction(*s.q, *s.qdot, &local, out->matrix != nullptr);
    AddLocalTerms(local, out);
    out->size = std::max(out->size, local.force.lpNorm<Eigen::Infinity>());
  }
}

double SlidingJoints::StoredEnergy(const ForceState& s) const {
  double energy = 0;
  for (const SlidingJoint& slider : sliders_) energy += slider.Penalty(*s.q, nullptr, false);
  return energy;
}

void SlidingJoints::AddDissipatedPower(const ForceState& s, double* power) const {
  for (const SlidingJoint& slider : sliders_)
    if (slider.has_friction()) *power += slider.Friction(*s.q, *s.qdot, nullptr, false);
}

bool SlidingJoints::dissipates() const {
  for (const SlidingJoint& slider : sliders_)
    if (slider.has_friction()) return true;
  return false;
}

absl::StatusOr<std::unique_ptr<SlidingJoints>> MakeSlidingJoints(
    const Scene& scene, const std::vector<std::vector<SlidingJoint::Segment>>& segments,
    const std::vector<int>& body_coord, int dim, int body_stride, const VectorXd& q0) {
  std::vector<SlidingJoint> sliders;
  for (int ji = 0; ji < static_cast<int>(scene.joints.size()); ++ji) {
    const JointSpec& joint = scene.joints[ji];
    if (joint.type != JointType::kSlide) continue;
    const Attachment& on_cable = joint.a.cable >= 0 ? joint.a : joint.b;
    const Attachment& on_body = joint.a.body >= 0 ? joint.a : joint.b;
    const int cable = on_cable.cable;
    const CableSpec& spec = scene.cables[cable];
    // Default stiffness: the axial stiffness EA / l_e of one element.
    double k = joint.slide.stiffness_n_m;
    if (k == 0) k = spec.youngs_modulus_pa * spec.area_m2 * spec.elements / spec.length_m;
    SlidingJoint slider(dim, segments[cable], body_coord[on_body.body], body_stride,
                        on_body.point_body_m, k, joint.slide.friction,
                        joint.slide.stick_velocity_m_s, on_cable.s_m);
    const double gap = slider.Gap(q0);
    if (gap > 1e-6) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "joints[%d]: the body point is %.6g m from the cable at t = 0 (a sliding joint starts "
          "on its cable)",
          ji, gap));
    }
    sliders.push_back(std::move(slider));
  }
  if (sliders.empty()) return nullptr;
  return std::make_unique<SlidingJoints>(std::move(sliders));
}

}  // namespace cablesim
