#ifndef CABLESIM_ENGINE_RUN_FRAME_RECORDER_H_
#define CABLESIM_ENGINE_RUN_FRAME_RECORDER_H_

// FrameRecorder: evaluates a state into a Frame (probes, energy and its
// parts, support forces, shape, constraint violation), keeps energy.damped
// (the dissipated power integrated over accepted steps) and the summary's
// frame-level figures, and delivers frames to the caller's sink.

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "engine/model/multibody_model.h"
#include "engine/output/results.h"

namespace cablesim {

// Tracks the frame-level quantities of the summary.
class FrameRecorder {
 public:
  FrameRecorder(MultibodyModel* model, FrameSink* sink, RunSummary* summary)
      : model_(model), sink_(sink), summary_(summary) {
    q_.setZero(model->coordinates());
    qd_.setZero(model->coordinates());
    qdd_.setZero(model->coordinates());
    phi_.setZero(model->multipliers());
  }

  // Evaluates the frame at a state without delivering it (frame()).
  // `lambda`: the multipliers, for the forces of moving supports.
  void Evaluate(double t, double load_factor, const Eigen::VectorXd& z, const Eigen::VectorXd* v,
                const Eigen::VectorXd* a, const Eigen::VectorXd* lambda = nullptr) {
    model_->ToFull(z, &q_);
    if (v) model_->RateToFull(*v, &qd_);
    if (a) model_->RateToFull(*a, &qdd_);
    frame_.t = t;
    model_->Probes(q_, qd_, qdd_, &frame_.probes);
    if (lambda) {
      model_->ProbeForces(q_, *lambda, &frame_.support_forces);
    } else {
      // No multipliers at hand: the columns stay, with 0 (a row keeps its size).
      frame_.support_forces.assign(model_->force_probe_count(), Eigen::Vector3d::Zero());
    }
    if (model_->reactions()) model_->Reactions(q_, lambda, &frame_.reactions);
    if (model_->tension()) {
      // With rates, the cables' material damping is part of the tension.
      model_->Tensions(q_, load_factor, &frame_.probe_tensions, &frame_.node_tensions,
                       v ? &qd_ : nullptr);
    }
    if (model_->orientation()) model_->Orientations(q_, qd_, &frame_.body_orientation);
    frame_.joint_released = model_->joint_released();
    if (model_->bending_moment()) {
      model_->BendingMoments(q_, load_factor, &frame_.probe_bending_moments,
                             v ? &qd_ : nullptr);
    }
    if (model_->shape()) model_->NodePositions(q_, &frame_.nodes);
    frame_.energy = model_->Energy(q_, qd_, load_factor, &frame_.energy_parts);
    frame_.energy.damped = Damped(t);
    frame_.has_contact = model_->has_contact();
    if (sink_ != nullptr && sink_->wants_angular_momentum())
      frame_.angular_momentum = model_->AngularMomentum(q_, qd_);
    // (A joint that let go, JointRelease, leaves the model fewer rows.)
    if (phi_.size() != model_->multipliers()) phi_.setZero(model_->multipliers());
    model_->Constraints(q_, &phi_, nullptr);
    frame_.constraint_violation = phi_.size() ? phi_.lpNorm<Eigen::Infinity>() : 0.0;
  }
  const Frame& frame() const { return frame_; }

  // Energy of a state at time t, without evaluating or delivering a frame.
  EnergySample StateEnergy(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v) {
    model_->SetTime(t);  // the damping power of waves depends on it
    model_->ToFull(z, &q_);
    model_->RateToFull(v, &qd_);
    EnergySample e = model_->Energy(q_, qd_, 1.0);
    e.damped = Damped(t);
    return e;
  }

  // energy.damped: the trapezoidal rule on the dissipated power from the
  // last accepted step's end (AdvanceDamping) to t. At a step's end the
  // rule itself; inside a step whose end power is known (EndStep), the
  // rule's own interpolant, the power linear between the step's two ends
  // (so a frame between step ends costs no evaluation of the damping, and
  // energy.damped is the same function of time whatever the frames);
  // otherwise the power of the state in q_, qd_ at t.
  double Damped(double t) const {
    if (!model_->has_dissipated_power()) return 0;
    if (t == damped_t_) return damped_;
    if (has_end_) {
      const double h = end_t_ - damped_t_, dt = t - damped_t_;
      // (A frame within 1e-6 of the step from its end is that end, as the
      // run's frame grid takes it: RunDynamic.)
      if (!(t < end_t_ - 1e-6 * h) || !(h > 0))
        return damped_ + 0.5 * dt * (damped_power_ + end_power_);
      return damped_ + dt * (damped_power_ + 0.5 * (dt / h) * (end_power_ - damped_power_));
    }
    const double power = model_->DampingPower(q_, qd_);
    return damped_ + 0.5 * (t - damped_t_) * (damped_power_ + power);
  }
  // The dissipated power at a step's end (t, z, v), evaluated once per
  // step attempt (`attempt`, the caller's count: a second call for the same
  // attempt keeps the first's power), before the step's guard, its frames
  // (Damped) and AdvanceDamping.
  void EndStep(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v, long attempt) {
    if (!model_->has_dissipated_power()) return;
    if (has_end_ && end_attempt_ == attempt) return;
    end_attempt_ = attempt;
    model_->SetTime(t);  // the damping power of waves depends on it
    model_->ToFull(z, &q_);
    model_->RateToFull(v, &qd_);
    end_power_ = model_->DampingPower(q_, qd_);
    end_t_ = t;
    has_end_ = true;
  }
  // Forgets the power EndStep evaluated (the step was taken back).
  void DropEndStep() { has_end_ = false; }
  // Moves the start of that rule to an accepted step's end (t, z, v), with
  // the power EndStep evaluated there when it did.
  void AdvanceDamping(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v) {
    if (!model_->has_dissipated_power()) return;
    double power = end_power_;
    if (!has_end_) {
      model_->SetTime(t);  // the damping power of waves depends on it
      model_->ToFull(z, &q_);
      model_->RateToFull(v, &qd_);
      power = model_->DampingPower(q_, qd_);
    }
    has_end_ = false;
    damped_ += 0.5 * (t - damped_t_) * (damped_power_ + power);
    damped_t_ = t;
    damped_power_ = power;
  }

  // Records the evaluated frame in the summary and delivers it. `reached`:
  // the frame is a state the stepper reached (a step's end, or the start),
  // not one interpolated between steps; only such states enter
  // energy_max_increase and the energy scale (an interpolated state's
  // energy carries the interpolant's error, not the stepper's).
  absl::Status Deliver(bool reached = true) {
    if (summary_->frames == 0) summary_->energy_initial = frame_.energy.total;
    summary_->energy_final = frame_.energy.total;
    summary_->energy_damped = frame_.energy.damped;
    summary_->max_constraint_violation =
        std::max(summary_->max_constraint_violation, frame_.constraint_violation);
    ++summary_->frames;
    if (reached) NoteReachedState(frame_.energy);
    return sink_->OnFrame(frame_);
  }
  // A state the stepper reached, with energy e: its rise and its terms.
  void NoteReachedState(const EnergySample& e) {
    summary_->energy_max_increase = std::max(summary_->energy_max_increase,
                                             e.total + e.damped - summary_->energy_initial);
    energy_scale_ = std::max({energy_scale_, std::abs(e.kinetic), std::abs(e.potential),
                              std::abs(e.axial) + std::abs(e.bending)});
  }

  absl::Status Emit(double t, double load_factor, const Eigen::VectorXd& z,
                    const Eigen::VectorXd* v, const Eigen::VectorXd* a,
                    const Eigen::VectorXd* lambda = nullptr) {
    Evaluate(t, load_factor, z, v, a, lambda);
    return Deliver();
  }

  // Largest energy term seen so far [J].
  double energy_scale() const { return energy_scale_; }

 private:
  MultibodyModel* model_;
  FrameSink* sink_;
  RunSummary* summary_;
  Frame frame_;
  Eigen::VectorXd q_, qd_, qdd_, phi_;
  double energy_scale_ = 0;
  // energy.damped at damped_t_ and the dissipated power there.
  double damped_ = 0, damped_t_ = 0, damped_power_ = 0;
  // The power at the end (end_t_) of the step being recorded (EndStep).
  double end_power_ = 0, end_t_ = 0;
  long end_attempt_ = -1;
  bool has_end_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_FRAME_RECORDER_H_
