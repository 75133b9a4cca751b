#ifndef CABLESIM_ENGINE_CONSTRAINTS_PRESCRIBED_MOTION_H_
#define CABLESIM_ENGINE_CONSTRAINTS_PRESCRIBED_MOTION_H_

// Moving and turning supports as one ConstraintFamily: the time law of
// some JointRows rows (constraint.h).
//
//  - A moving support (a joint to ground whose ground point moves by d(t),
//    JointSpec::motion): its position rows are Phi_i(q, t) = r_i(q) - p_i -
//    d_i(t), so SetTime writes c = c0 - d_i(t) into the row; Phi_t =
//    -d_i'(t), and its part of gamma is -Phi_tt = d_i''(t). The support
//    exerts the force -lambda_i along axis i on what it holds (its
//    reaction, JointRows::AddReactions as every position row's), and does the work W = -(lambda_i0 + lambda_i1) / 2
//    (d_i(t1) - d_i(t0)) over a step (second order).
//  - A turning support (JointSpec::rotation): a direction row n(t) . x = 0,
//    x the D coordinates from full index `coord` (a clamped slope or a body
//    axis), n(t) = R(angle(t)) n0 with R the rotation about the unit
//    `axis`. SetTime writes n(t) into the row's linear coefficients, so the
//    rows' values and Jacobian need nothing else; Phi_t = n' . x, and its
//    part of gamma is -2 n' . xdot - n'' . x. The work of a rheonomic row is
//    int lambda Phi_t dt (since Phi_q qdot = -Phi_t), here W = (lambda_0 +
//    lambda_1) / 2 (n(t1) - n(t0)) . (x0 + x1) / 2 (second order; the
//    moving support's formula is its case Phi_t = -d').

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/constraints/constraint.h"
#include "engine/constraints/joint_rows.h"
#include "engine/scene/time_function.h"

namespace cablesim {

class PrescribedMotion : public ConstraintFamily {
 public:
  // A constraint row of a moving support: c = c0 - motion(t).
  struct MovingRow {
    int row = 0;
    int joint = 0, axis = 0;  // scene joint and component of its motion
    double c0 = 0;
    TimeFunction motion;
    double rate = 0, accel = 0;  // motion' and motion'' at the time set
  };
  // A direction row of a turning support (above).
  struct TurningRow {
    int row = 0;
    int coord = 0;
    int joint = -1;  // the scene joint that turns it
    Eigen::Vector3d n0 = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ();
    TimeFunction angle;
    Eigen::Vector3d n = Eigen::Vector3d::Zero(), rate = Eigen::Vector3d::Zero(),
                    accel = Eigen::Vector3d::Zero();  // n, n', n'' at the time set
    // n at time t (Rodrigues' formula); with `rate` and `accel` not null,
    // also n' = angle' a x n and n'' = angle'' a x n + angle'^2 a x (a x n).
    Eigen::Vector3d Normal(double t, Eigen::Vector3d* rate = nullptr,
                           Eigen::Vector3d* accel = nullptr) const;
  };

  // `rows`: the rows it drives (owned elsewhere, alive as long as this).
  PrescribedMotion(JointRows* rows, std::vector<MovingRow> moving,
                   std::vector<TurningRow> turning, int dim);

  const std::vector<MovingRow>& moving() const { return moving_; }
  // Replaces moving row i's motion (a coupled support's motion, set by the
  // coupling session for each coupling step); SetTime applies it.
  void SetMotion(int i, TimeFunction motion) { moving_[i].motion = std::move(motion); }
  const std::vector<TurningRow>& turning() const { return turning_; }
  // Replaces turning row i's law: n(t) = Rot(axis, angle(t)) n0 (a coupled
  // body's orientation, set by the coupling session for each coupling
  // step: n0 its normal at the step's start, axis and angle(t) the step's
  // rotation); SetTime applies it.
  void SetTurning(int i, const Eigen::Vector3d& n0, const Eigen::Vector3d& axis,
                  TimeFunction angle) {
    turning_[i].n0 = n0;
    turning_[i].axis = axis;
    turning_[i].angle = std::move(angle);
  }

  std::string_view name() const override { return "prescribed_motion"; }
  bool time_dependent() const override { return true; }
  void SetTime(double t) override;
  void AddGamma(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                Eigen::VectorXd* gamma) const override;
  void AddRate(const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const override;
  void AddStepWork(const ConstraintStep& step, double* work) const override;

 private:
  JointRows* rows_;
  std::vector<MovingRow> moving_;
  std::vector<TurningRow> turning_;
  int dim_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_CONSTRAINTS_PRESCRIBED_MOTION_H_
