#include "engine/run/simulation.h"
#include "engine/scene/integrator_traits.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <limits>
#include <memory>

#include "absl/strings/str_format.h"
#include "engine/steppers/implicit_euler_stepper.h"
#include "engine/analysis/modal_solver.h"
#include "engine/model/multibody_model.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/analysis/static_solver.h"
#include "engine/steppers/make_stepper.h"
#include "engine/steppers/stepper.h"

namespace cablesim {
namespace {

using Clock = std::chrono::steady_clock;

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
    if (model_->shape()) model_->NodePositions(q_, &frame_.nodes);
    frame_.energy = model_->Energy(q_, qd_, load_factor, &frame_.energy_parts);
    frame_.energy.damped = Damped(t);
    frame_.has_contact = model_->has_contact();
    frame_.angular_momentum = model_->AngularMomentum(q_, qd_);
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
  // last accepted step's end (AdvanceDamping) to the state in q_, qd_ at t.
  double Damped(double t) const {
    if (!model_->has_damping()) return 0;
    const double power = model_->DampingPower(q_, qd_);
    return damped_ + 0.5 * (t - damped_t_) * (damped_power_ + power);
  }
  // Moves the start of that rule to an accepted step's end (t, z, v).
  void AdvanceDamping(double t, const Eigen::VectorXd& z, const Eigen::VectorXd& v) {
    if (!model_->has_damping()) return;
    model_->SetTime(t);  // the damping power of waves depends on it
    model_->ToFull(z, &q_);
    model_->RateToFull(v, &qd_);
    damped_ = Damped(t);
    damped_t_ = t;
    damped_power_ = model_->DampingPower(q_, qd_);
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
};

// Sums the work of torques, time-varying loads and moving supports over
// accepted steps, for the energy balance (MultibodyModel::
// AccumulateExternalWork); nothing in a scene without them.
class ExternalWork {
 public:
  explicit ExternalWork(MultibodyModel* model) : model_(model) {
    model->ResetExternalWork();
    if (!model->has_external_work()) return;
    before_.setZero(model->coordinates());
    after_.setZero(model->coordinates());
    lambda_before_.setZero(model->multipliers());
  }
  void Before(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda) {
    if (!model_->has_external_work()) return;
    model_->ToFull(z, &before_);
    t_before_ = t;
    lambda_before_ = lambda;
  }
  void After(const Eigen::VectorXd& z, double t, const Eigen::VectorXd& lambda,
             double load_factor) {
    if (!model_->has_external_work()) return;
    model_->ToFull(z, &after_);
    model_->AccumulateExternalWork(before_, after_, t_before_, t, lambda_before_, lambda,
                                   load_factor);
  }

 private:
  MultibodyModel* model_;
  Eigen::VectorXd before_, after_, lambda_before_;
  double t_before_ = 0;
};

// Every scene conserves its total energy plus the work done against damping
// (gravity and constant loads are potential; the work of torques,
// time-varying loads and moving supports is counted in the total,
// MultibodyModel::Energy), so a rise of that sum by more than this
// fraction of the largest energy term is the stepper going unstable (the
// second-order steppers can, on stiff nonlinear cables at large steps): the
// run stops and says so rather than deliver it.
constexpr double kEnergyRiseLimit = 0.05;
// Steps that took at least this many Newton iterations have their energy
// checked against that limit before they are accepted.
constexpr int kEnergyCheckNewton = 4;

void Fail(RunSummary* s, double t, const std::string& reason) {
  s->status = "failed";
  s->failure_time_s = t;
  s->error = reason;
}

// Checks the caller's stop request and step limit before a step attempt;
// false (with the summary filled in) means stop now.
bool MayStep(const RunControl& control, double t, RunSummary* s) {
  if (control.should_stop && control.should_stop()) {
    s->status = "cancelled";
    s->error = absl::StrFormat("stopped by the caller at t = %.9g", t);
    return false;
  }
  if (control.max_steps > 0 && s->steps + s->rejected_steps >= control.max_steps) {
    Fail(s, t, absl::StrFormat("step limit of %d step attempts reached at t = %.9g",
                               control.max_steps, t));
    return false;
  }
  return true;
}

// Step-size factor of the error controller: the usual safety factor 0.9 on
// err^(-1/k) (k the power of h in the local error), bounded to [0.2, 2] so
// that one estimate never moves the step far (Hairer, Norsett and Wanner,
// Solving ODEs I, section II.4).
double StepFactor(double err, int k) {
  if (!(err > 0)) return 2.0;
  return std::clamp(0.9 * std::pow(err, -1.0 / k), 0.2, 2.0);
}

void RunDynamic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
                FrameRecorder* rec, RunSummary* summary) {
  std::unique_ptr<Stepper> stepper_owner = MakeStepper(model, settings);
  Stepper& stepper = *stepper_owner;
  std::string reason;
  if (!stepper.Initialize(&reason)) {
    Fail(summary, 0, reason);
    return;
  }
  ExternalWork external_work(model);
  model->SetTime(0);
  rec->AdvanceDamping(0, stepper.z(), stepper.v());
  if (absl::Status s = rec->Emit(0, 1, stepper.z(), &stepper.v(), &stepper.a(), &stepper.lambda());
      !s.ok()) {
    summary->status = "cancelled";
    summary->error = std::string(s.message());
    return;
  }
  const double h_nominal = settings.step_s;
  const double h_min = std::ldexp(h_nominal, -settings.max_step_halvings);
  const double interval =
      settings.output_interval_s > 0 ? settings.output_interval_s : settings.step_s;
  const double duration = settings.duration_s;
  const long frames = std::max(1L, std::lround(std::ceil(duration / interval - 1e-9)));
  double t = 0;
  double h = h_nominal;
  int successes = 0;
  // Fixed steps: the time reached counted in ticks of h_min (every step is
  // h_nominal / 2^k, a whole number of ticks), so that whether t is on a
  // step's grid is decided exactly, however many steps rounding had to
  // accumulate over.
  // t itself is the time of the last anchor (the start, a frame it was
  // snapped to, or a step that was not a whole number of ticks) plus the
  // ticks since, so it carries one rounding, not the sum of every step's.
  int64_t tick = 0, tick_anchor = 0;
  double t_anchor = 0;
  auto ticks_of = [h_min](double step) { return std::llround(step / h_min); };
  // Rises of the total energy below this are rounding (a scene at rest).
  const double energy_floor = model->energy_roundoff();
  // Backward Euler never raises the energy; the second-order steppers may.
  const bool check_steps = !TraitsOf(settings.integrator).never_raises_energy;
  summary->min_step_s = settings.adaptive ? std::numeric_limits<double>::infinity() : h_nominal;
  // Steps of h (the last one or two shortened to end on the duration);
  // frames between step ends are interpolated (dense output), so asking
  // for frames never changes the steps. Over a step from (z0, v0, a0) to
  // (z1, v1, a1) of length d, at theta = (t - t0) / d: positions by the
  // cubic Hermite interpolant of z0, v0, z1, v1 (its error, O(d^4), is
  // below the second-order steppers' O(d^2)), velocities by its
  // derivative, accelerations linearly between a0 and a1. A frame's
  // energies and constraint violation are those of that interpolated state.
  const int n = static_cast<int>(stepper.z().size());
  Eigen::VectorXd z_0 = stepper.z(), v_0 = stepper.v(), a_0 = stepper.a();
  Eigen::VectorXd z_i(n), v_i(n), a_i(n);
  // Multipliers (the forces of moving supports) linearly between steps.
  Eigen::VectorXd lambda_0 = stepper.lambda(), lambda_i(lambda_0.size());
  auto frame_time = [&](long k) { return std::min(duration, k * interval); };
  auto Interpolate = [&](double th, double d, const Stepper& s) {
    const double th2 = th * th, th3 = th2 * th;
    const double h00 = 2 * th3 - 3 * th2 + 1, h10 = th3 - 2 * th2 + th, h01 = -2 * th3 + 3 * th2,
                 h11 = th3 - th2;
    const double d00 = 6 * th2 - 6 * th, d10 = 3 * th2 - 4 * th + 1, d01 = -d00,
                 d11 = 3 * th2 - 2 * th;
    z_i = h00 * z_0 + (h10 * d) * v_0 + h01 * s.z() + (h11 * d) * s.v();
    v_i = (d00 / d) * z_0 + d10 * v_0 + (d01 / d) * s.z() + d11 * s.v();
    a_i = (1 - th) * a_0 + th * s.a();
    lambda_i = (1 - th) * lambda_0 + th * s.lambda();
  };
  // The energy guard on a state the stepper reached (a step's end): false
  // (with the summary failed) when its energy rose beyond the limit.
  // A winch does work that is not summed (MultibodyModel::winches): no
  // energy guard there.
  const bool guard_energy = model->winches() == 0;
  auto EnergyHolds = [&](const EnergySample& e, double t_state) {
    if (!guard_energy) return true;
    const double rise = e.total + e.damped - summary->energy_initial;
    const double scale = std::max({rec->energy_scale(), std::abs(e.kinetic),
                                   std::abs(e.potential), std::abs(e.axial) + std::abs(e.bending)});
    if (rise > kEnergyRiseLimit * scale + energy_floor) {
      Fail(summary, t_state,
           absl::StrFormat("the total energy rose by %.3g J (more than %g %% of the largest "
                           "energy term, %.3g J) by t = %.9g s: the stepper is unstable at this "
                           "step; use a smaller solver.step, adaptive steps or a smaller "
                           "rho_infinity",
                           rise, 100 * kEnergyRiseLimit, scale, t_state));
      return false;
    }
    return true;
  };
  // Delivers the evaluated frame; `guard`: it is a step's end state, whose
  // energy is checked first. An interpolated frame is not guarded: its
  // energy carries the interpolant's error (the stretch modes of a stiff
  // cable oscillate within a step and a cubic does not follow them), which
  // is not the stepper's; the step's end state that follows it is guarded.
  auto CheckAndDeliver = [&](double tf, bool guard = true) {
    if (guard && !EnergyHolds(rec->frame().energy, tf)) return false;
    if (absl::Status st = rec->Deliver(/*reached=*/guard); !st.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(st.message());
      return false;
    }
    return true;
  };
  long next_frame = 1;
  while (next_frame <= frames) {
    // A frame already reached (a duration within rounding of the last).
    if (const double tf = frame_time(next_frame); tf - t <= 1e-12 * std::max(1.0, tf)) {
      model->SetTime(tf);
      rec->Evaluate(tf, 1, stepper.z(), &stepper.v(), &stepper.a(), &stepper.lambda());
      if (!CheckAndDeliver(tf)) return;
      ++next_frame;
      continue;
    }
    if (!MayStep(control, t, summary)) return;
    const double remaining = duration - t;
    // The last steps: one or two equal ones that end on the duration; when
    // what is left is a whole number of steps to rounding, whole steps (the
    // frame at the end snaps t onto the duration).
    const double left = remaining / h;
    const bool whole =
        left >= 0.5 && std::abs(left - std::round(left)) <= 1e-9 * std::max(1.0, left);
    const double h_try =
        remaining < 2 * h && !whole ? remaining / std::ceil(left - 1e-9) : h;
    z_0 = stepper.z();
    v_0 = stepper.v();
    a_0 = stepper.a();
    lambda_0 = stepper.lambda();
    external_work.Before(stepper.z(), t, stepper.lambda());
    const auto st = stepper.Step(h_try);
    summary->newton_iterations += st.newton_iterations;
    summary->linear_iterations += st.linear_iterations;
    summary->factorizations += st.factorizations;
    summary->direct_fallbacks += st.direct_fallbacks;
    summary->linear_solves += st.linear_solves;
    summary->inexact_linear_solves += st.inexact_solves;
    summary->max_linear_residual = std::max(summary->max_linear_residual, st.max_linear_residual);
    if (st.converged && check_steps && guard_energy &&
        st.newton_iterations >= kEnergyCheckNewton) {
      // A step Newton found hard may have landed on a spurious root (an
      // element folded through itself: Green-Lagrange strain does not see
      // it); its energy says so. Take it back and halve the step.
      const EnergySample e = rec->StateEnergy(t + h_try, stepper.z(), stepper.v());
      const double scale =
          std::max({rec->energy_scale(), std::abs(e.kinetic), std::abs(e.potential),
                    std::abs(e.axial) + std::abs(e.bending)});
      if (e.total + e.damped - summary->energy_initial >
          kEnergyRiseLimit * scale + energy_floor) {
        stepper.Restore();
        ++summary->rejected_steps;
        successes = 0;
        h = h_try / 2;
        if (h < h_min * (1 - 1e-12)) {
          Fail(summary, t + h_try,
               absl::StrFormat("step from t = %.9g s raises the total energy by %.3g J down to "
                               "h = %.3g s: the stepper is unstable here; use a smaller "
                               "rho_infinity",
                               t, e.total + e.damped - summary->energy_initial, h_try));
          return;
        }
        continue;
      }
    }
    if (st.converged && settings.adaptive) {
      // Adaptive steps: accept when the local error estimate meets the
      // tolerance, and choose the next step from it either way.
      const double err = stepper.LocalErrorNorm(h_try, settings.tolerance_m,
                                                settings.relative_tolerance);
      const double factor = StepFactor(err, TraitsOf(settings.integrator).local_error_order);
      if (!(err <= 1)) {
        stepper.Restore();
        ++summary->rejected_steps;
        h = h_try * factor;
        if (h < h_min * (1 - 1e-12)) {
          Fail(summary, t + h_try,
               absl::StrFormat("step from t = %.9g s cannot meet the tolerance: the local "
                               "error estimate is %.3g times the tolerance at h = %.3g s, the "
                               "smallest step allowed is %.3g s",
                               t, err, h_try, h_min));
          return;
        }
        continue;
      }
      h = std::min(h_try * factor, stepper.stable_step());
    }
    if (st.converged) {
      const double t0 = t;
      if (!settings.adaptive && h_try == h) {
        tick += ticks_of(h_try);
        t = t_anchor + static_cast<double>(tick - tick_anchor) * h_min;
      } else {
        t += h_try;  // adaptive, or the last steps shortened to end on the duration
        t_anchor = t;
        tick_anchor = tick;
      }
      external_work.After(stepper.z(), t, stepper.lambda(), 1);
      ++summary->steps;
      summary->min_step_s = std::min(summary->min_step_s, h_try);
      summary->max_step_s = std::max(summary->max_step_s, h_try);
      summary->max_newton_residual = std::max(summary->max_newton_residual, st.residual);
      summary->max_residual_floor = std::max(summary->max_residual_floor, st.residual_floor);
      summary->end_time_s = t;
      // After a run of good steps, go back up towards the nominal step, at
      // a time on the doubled step's grid (a multiple of 2 h), so that steps
      // return to the nominal grid and the frames on it are step ends again
      // rather than interpolated.
      if (!settings.adaptive && h < h_nominal && ++successes >= 4 &&
          h_try == h && tick % (2 * ticks_of(h)) == 0) {
        h = std::min(h_nominal, 2 * h);
        successes = 0;
      }
      // Every frame this step reached: the step's end state where the
      // frame is its end (within 1e-6 of the step, which also keeps t on
      // the frames' grid), otherwise interpolated (dense output).
      bool end_checked = false;
      while (next_frame <= frames) {
        const double tf = frame_time(next_frame);
        const bool at_end = std::abs(tf - t) <= 1e-6 * h_try;
        if (!at_end && tf > t) break;
        if (at_end) {
          t = tf;
          t_anchor = tf;
          tick_anchor = tick;
          model->SetTime(tf);
          rec->Evaluate(tf, 1, stepper.z(), &stepper.v(), &stepper.a(), &stepper.lambda());
        } else {
          // The step's end is guarded before any frame inside it goes out.
          if (!end_checked) {
            model->SetTime(t);
            const EnergySample end = rec->StateEnergy(t, stepper.z(), stepper.v());
            if (!EnergyHolds(end, t)) return;
            rec->NoteReachedState(end);
            end_checked = true;
          }
          Interpolate((tf - t0) / h_try, h_try, stepper);
          model->SetTime(tf);
          rec->Evaluate(tf, 1, z_i, &v_i, &a_i, &lambda_i);
        }
        if (!CheckAndDeliver(tf, /*guard=*/at_end)) return;
        ++next_frame;
      }
      rec->AdvanceDamping(t, stepper.z(), stepper.v());
      summary->end_time_s = t;
      continue;
    }
    ++summary->rejected_steps;
    successes = 0;
    h = h_try / 2;
    if (h < h_min * (1 - 1e-12)) {
      Fail(summary, t + h_try,
           absl::StrFormat("step from t = %.9g s failed %d times down to h = %.3g s: %s", t,
                           settings.max_step_halvings + 1, h_try, st.reason));
      return;
    }
  }
}

void RunStatic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
               FrameRecorder* rec, RunSummary* summary) {
  StaticSolver solver(model, settings);
  // Statics is the equilibrium at t = 0: moving supports at their start,
  // time-varying loads at their value there (scaled by the load factor).
  model->SetTime(0);
  ExternalWork external_work(model);
  auto on_increment = [&](const Eigen::VectorXd& z0, const Eigen::VectorXd& z1, double alpha) {
    // Moving supports do not move at t = 0: their work is 0 (lambda unused).
    external_work.Before(z0, 0, solver.lambda());
    external_work.After(z1, 0, solver.lambda(), alpha);
  };
  auto on_target = [&](double alpha) {
    if (absl::Status s = rec->Emit(alpha, alpha, solver.z(), nullptr, nullptr, &solver.lambda());
        !s.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(s.message());
      return false;
    }
    return true;
  };
  FollowLoadPath(&solver, settings, control, summary, "", on_increment, on_target);
}

// Forwards frames and keeps every probe position (for the error estimate).
class ProbeRecordingSink : public FrameSink {
 public:
  explicit ProbeRecordingSink(FrameSink* next) : next_(next) {}
  absl::Status OnStart(const ModelInfo& info) override {
    return next_ ? next_->OnStart(info) : absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    times_.push_back(frame.t);
    for (const ProbeSample& p : frame.probes) positions_.push_back(p.position_m);
    return next_ ? next_->OnFrame(frame) : absl::OkStatus();
  }
  const std::vector<double>& times() const { return times_; }
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }

 private:
  FrameSink* next_;
  std::vector<double> times_;
  std::vector<Eigen::Vector3d> positions_;
};

// The error estimate of a DYNAMIC run (solver.error_estimate): a companion
// run of the same model, with half the step (fixed steps) or tolerances 32
// times tighter (adaptive steps), compared frame by frame at the probes.
// Fixed steps: Richardson extrapolation for a method of order p,
// e(h) ~ |x_h - x_{h/2}| 2^p / (2^p - 1). Adaptive: the companion is much
// more accurate, so the difference itself is the estimate.
void EstimateError(MultibodyModel* model, const SolverSettings& settings,
                   const RunControl& control, const ProbeRecordingSink& main,
                   RunSummary* summary) {
  const auto start = Clock::now();
  summary->has_error_estimate = true;
  SolverSettings companion = settings;
  companion.error_estimate = false;
  // The order of the frames (DORMAND_PRINCE is fifth order at its steps, but
  // frames between steps are cubic Hermite, fourth order).
  const int order = TraitsOf(settings.integrator).frame_order;
  double factor = 1;
  if (settings.adaptive) {
    companion.tolerance_m /= 32;
    companion.relative_tolerance /= 32;
    summary->error_estimate_method =
        "difference to a companion run with tolerance and relative_tolerance / 32";
  } else {
    companion.step_s /= 2;
    companion.max_step_halvings += 1;  // the same smallest step
    factor = std::ldexp(1.0, order) / (std::ldexp(1.0, order) - 1);
    summary->error_estimate_method = absl::StrFormat(
        "Richardson extrapolation against a companion run at half the step (order %d: "
        "%.4g times the difference)",
        order, factor);
  }
  ProbeRecordingSink recorded(nullptr);
  RunSummary companion_summary;
  FrameRecorder recorder(model, &recorded, &companion_summary);
  // The caller's stop request and step limit apply to the companion too.
  RunDynamic(model, companion, control, &recorder, &companion_summary);
  summary->error_estimate_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (companion_summary.status != "ok") {
    summary->error_estimate_method += " (the companion run failed: " + companion_summary.error + ")";
    return;
  }
  if (recorded.times().size() != main.times().size() ||
      recorded.positions().size() != main.positions().size()) {
    summary->error_estimate_method += " (the companion run's frames differ)";
    return;
  }
  double worst = 0;
  for (size_t i = 0; i < main.positions().size(); ++i)
    worst = std::max(worst, (main.positions()[i] - recorded.positions()[i]).norm());
  if (!std::isfinite(worst)) {
    summary->error_estimate_method += " (not finite)";
    return;
  }
  summary->error_estimate_m = factor * worst;
}

// solver.initial_state STATIC: moves the model's initial state to the
// static equilibrium under the full gravity and loads (the load path of
// STATIC analysis, without its frames), solved to the rounding floor of the
// forces (newton_tolerance 1e-12) so that the motion starting there stays
// at rest to about a nanometre. Its Newton iterations count in the run's.
// False, with the summary failed at t = 0, when there is no equilibrium.
bool StartFromEquilibrium(MultibodyModel* model, const SolverSettings& settings,
                          const RunControl& control, RunSummary* summary) {
  SolverSettings statics = settings;
  statics.analysis = Analysis::kStatic;
  statics.newton_tolerance = std::min(settings.newton_tolerance, 1e-12);
  StaticSolver solver(model, statics);
  RunSummary path;
  const bool ok = FollowLoadPath(&solver, statics, control, &path,
                                 "solver.initial_state STATIC: ", nullptr, nullptr);
  summary->newton_iterations += path.newton_iterations;
  summary->linear_iterations += path.linear_iterations;
  summary->max_linear_residual = std::max(summary->max_linear_residual, path.max_linear_residual);
  summary->max_residual_floor = std::max(summary->max_residual_floor, path.max_residual_floor);
  if (!ok) {
    summary->status = path.status;
    summary->error = path.error;
    summary->failure_time_s = 0;
    return false;
  }
  model->SetInitialState(solver.z());
  return true;
}

}  // namespace

struct PreparedModel {
  Scene scene;
  MultibodyModel model;
  ModelInfo info;
  int modes = 0;  // MODAL: the modes to compute
  double build_seconds = 0;
  bool used = false;
};

PreparedRun::PreparedRun() = default;
PreparedRun::PreparedRun(PreparedRun&&) noexcept = default;
PreparedRun& PreparedRun::operator=(PreparedRun&&) noexcept = default;
PreparedRun::~PreparedRun() = default;
const ModelInfo& PreparedRun::info() const { return model_->info; }
bool PreparedRun::used() const { return model_->used; }

absl::StatusOr<PreparedRun> Prepare(const Scene& scene,
                                    const std::function<bool()>& should_stop) {
  const auto start = Clock::now();
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene, should_stop);
  if (!built.ok()) return built.status();
  int modes = 0;
  if (scene.solver.analysis == Analysis::kModal) {
    absl::StatusOr<int> count = ModalSolver::ModeCount(*built, scene.solver);
    if (!count.ok()) return count.status();
    modes = *count;
  }
  PreparedRun prepared;
  ModelInfo info = built->Info();
  prepared.model_.reset(new PreparedModel{scene, std::move(*built), std::move(info), modes,
                                          std::chrono::duration<double>(Clock::now() - start).count(),
                                          false});
  return prepared;
}

absl::StatusOr<ModelInfo> DescribeModel(const Scene& scene,
                                        const std::function<bool()>& should_stop) {
  absl::StatusOr<PreparedRun> prepared = Prepare(scene, should_stop);
  if (!prepared.ok()) return prepared.status();
  return prepared->info();
}

absl::StatusOr<RunSummary> RunScene(const Scene& scene, FrameSink* sink,
                                    const RunControl& control) {
  const auto start = Clock::now();
  absl::StatusOr<PreparedRun> prepared = Prepare(scene, control.should_stop);
  if (absl::IsCancelled(prepared.status())) {
    RunSummary stopped;
    stopped.status = "cancelled";
    stopped.error = std::string(prepared.status().message());
    stopped.analysis = std::string(AnalysisName(scene.solver.analysis));
    stopped.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return stopped;
  }
  if (!prepared.ok()) return prepared.status();
  return RunPrepared(&*prepared, sink, control);
}

absl::StatusOr<RunSummary> RunPrepared(PreparedRun* prepared, FrameSink* sink,
                                       const RunControl& control) {
  if (prepared->model_ == nullptr || prepared->model_->used)
    return absl::FailedPreconditionError("a prepared model runs once; prepare it again");
  const auto start = Clock::now();
  PreparedModel& p = *prepared->model_;
  p.used = true;
  MultibodyModel& model = p.model;
  const Scene& scene = p.scene;
  RunSummary summary;
  summary.info = p.info;
  const SolverSettings& settings = scene.solver;
  summary.analysis = std::string(AnalysisName(settings.analysis));
  const int modes = p.modes;
  summary.integrator = std::string(IntegratorName(settings.integrator));
  summary.linear_solver = std::string(LinearSolverName(settings.linear_solver));
  summary.linear_solver_used = std::string(LinearSolverName(
      SaddlePointSolver::Resolve(settings.linear_solver, model.dofs(), model.multipliers())));
  summary.adaptive = settings.adaptive;
  if (TraitsOf(settings.integrator).has_rho_infinity)
    summary.rho_infinity = settings.rho_infinity;
  const bool estimate = settings.analysis == Analysis::kDynamic && settings.error_estimate;
  ProbeRecordingSink recording(sink);
  FrameSink* out = estimate ? &recording : sink;
  if (absl::Status s = out->OnStart(summary.info); !s.ok()) return s;
  FrameRecorder recorder(&model, out, &summary);
  if (settings.analysis == Analysis::kStatic) {
    RunStatic(&model, settings, control, &recorder, &summary);
  } else if (settings.analysis == Analysis::kModal) {
    RunModalAnalysis(&model, settings, modes, control, sink, &summary);
  } else if (settings.initial_state == InitialState::kStatic &&
             !StartFromEquilibrium(&model, settings, control, &summary)) {
    // The summary says why; no frame was delivered.
  } else {
    RunDynamic(&model, settings, control, &recorder, &summary);
    if (!std::isfinite(summary.min_step_s)) summary.min_step_s = 0;
    if (estimate) {
      if (summary.status == "ok") {
        EstimateError(&model, settings, control, recording, &summary);
      } else {
        summary.has_error_estimate = true;
        summary.error_estimate_method = "none: the run did not finish";
      }
    }
  }
  if (settings.analysis == Analysis::kDynamic)
    summary.energy_dissipated =
        summary.energy_initial - summary.energy_final - summary.energy_damped;
  summary.wall_seconds =
      p.build_seconds + std::chrono::duration<double>(Clock::now() - start).count();
  return summary;
}

}  // namespace cablesim
