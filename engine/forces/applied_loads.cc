#include "engine/forces/applied_loads.h"

#include <cmath>
#include <utility>

#include <Eigen/Geometry>

namespace cablesim {

using Eigen::Vector3d;
using Eigen::VectorXd;

AppliedLoads::AppliedLoads(std::vector<VaryingForce> forces, std::vector<Torque> torques, int dim)
    : forces_(std::move(forces)), torques_(std::move(torques)), dim_(dim) {}

bool AppliedLoads::time_dependent() const {
  if (!forces_.empty()) return true;
  for (const Torque& t : torques_)
    if (t.is_varying) return true;
  return false;
}

void AppliedLoads::SetTime(double t) {
  for (VaryingForce& l : forces_) l.value = Evaluate(l.force, t);
  for (Torque& tl : torques_)
    if (tl.is_varying) tl.torque = tl.base + Evaluate(tl.varying, t);
}

void AppliedLoads::AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
  const double load_factor = s.load_factor;
  const VectorXd& q = *s.q;
  VectorXd& full = *out->full;
  for (const VaryingForce& l : forces_) {
    for (int d = 0; d < dim_; ++d)
      for (const Term& t : l.point[d]) full(t.coord) += load_factor * t.coeff * l.value(d);
  }
  for (const Torque& t : torques_) {
    const int c = t.coord;
    if (dim_ == 2) {
      const double tz = load_factor * t.torque.z();
      full(c + 2) -= tz * q(c + 3);
      full(c + 3) += tz * q(c + 2);
    } else {
      for (int k = 0; k < 3; ++k) {
        const Vector3d e = q.segment<3>(c + 3 + 3 * k);
        full.segment<3>(c + 3 + 3 * k) += 0.5 * load_factor * t.torque.cross(e);
      }
    }
  }
}

void AppliedLoads::AddStepWork(const StepEnds& e, double* work) const {
  const VectorXd& q_before = *e.q_before;
  const VectorXd& q_after = *e.q_after;
  const double load_factor = e.load_factor;
  for (const VaryingForce& l : forces_) {
    const Vector3d mean = 0.5 * (Evaluate(l.force, e.t_before) + Evaluate(l.force, e.t_after));
    for (int d = 0; d < dim_; ++d)
      for (const Term& t : l.point[d])
        *work += load_factor * mean(d) * t.coeff * (q_after(t.coord) - q_before(t.coord));
  }
  for (const Torque& tl : torques_) {
    const Vector3d torque =
        tl.is_varying
            ? Vector3d(tl.base + 0.5 * (Evaluate(tl.varying, e.t_before) +
                                        Evaluate(tl.varying, e.t_after)))
            : tl.torque;
    const int c = tl.coord;
    if (dim_ == 2) {
      // Exact for a constant torque: T_z times the angle turned.
      const Eigen::Vector2d u0 = q_before.segment<2>(c + 2), u1 = q_after.segment<2>(c + 2);
      *work += load_factor * torque.z() *
               std::atan2(u0.x() * u1.y() - u0.y() * u1.x(), u0.dot(u1));
    } else {
      // T . phi with phi the rotation vector of the step (exact when the
      // rotation axis is fixed over the step, second order otherwise).
      Eigen::Matrix3d before, after;
      for (int k = 0; k < 3; ++k) {
        before.col(k) = q_before.segment<3>(c + 3 + 3 * k);
        after.col(k) = q_after.segment<3>(c + 3 + 3 * k);
      }
      const Eigen::AngleAxisd delta(Eigen::Matrix3d(after * before.transpose()));
      *work += load_factor * torque.dot(delta.angle() * delta.axis());
    }
  }
}

std::unique_ptr<AppliedLoads> MakeAppliedLoads(
    const Scene& scene, const std::vector<std::array<std::vector<AppliedLoads::Term>, 3>>& points,
    const std::vector<int>& body_coord, int dim) {
  std::vector<AppliedLoads::VaryingForce> forces;
  std::vector<AppliedLoads::Torque> torques;
  for (size_t i = 0; i < scene.loads.size(); ++i) {
    const LoadSpec& load = scene.loads[i];
    if (!IsZero(load.varying_force_n)) {
      AppliedLoads::VaryingForce v;
      v.point = points[i];
      v.force = load.varying_force_n;
      forces.push_back(std::move(v));
    }
    const bool varying_torque = !IsZero(load.varying_torque_nm);
    if (load.at.body >= 0 && (load.torque_nm.norm() > 0 || varying_torque)) {
      AppliedLoads::Torque t;
      t.coord = body_coord[load.at.body];
      t.torque = t.base = load.torque_nm;
      t.varying = load.varying_torque_nm;
      t.is_varying = varying_torque;
      torques.push_back(std::move(t));
    }
  }
  if (forces.empty() && torques.empty()) return nullptr;
  return std::make_unique<AppliedLoads>(std::move(forces), std::move(torques), dim);
}

}  // namespace cablesim
