#include "engine/run/dynamic_run.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "absl/strings/str_format.h"
#include "engine/run/auto_integrator.h"
#include "engine/run/dense_output.h"
#include "engine/run/energy_guard.h"
#include "engine/run/external_work.h"
#include "engine/run/step_control.h"
#include "engine/scene/integrator_traits.h"
#include "engine/steppers/make_stepper.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

void RunDynamic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
                FrameRecorder* rec, RunSummary* summary, JointRelease* release) {
  if (release != nullptr) {
    if (absl::Status s = release->Start(model); !s.ok()) {
      Fail(summary, 0, std::string(s.message()));
      return;
    }
  }
  // Viscoelastic lines start from the first state with their dashpots at
  // rest (ViscoelasticHistory); each accepted step is committed below.
  // Their dashpots are integrated over implicit steps only (scenes are
  // refused otherwise, naming solver.integrator; this guards callers that
  // build settings by hand).
  if (model->has_viscoelastic() && (TraitsOf(settings.integrator).is_explicit ||
                                    settings.integrator == Integrator::kEnergyMomentum)) {
    Fail(summary, 0,
         absl::StrFormat("%s does not apply to a scene with viscoelastic cables (use "
                         "IMPLICIT_EULER, GENERALIZED_ALPHA or HHT)",
                         IntegratorName(settings.integrator)));
    return;
  }
  model->StartViscoelastic(model->initial_z(), model->initial_time());
  // The stepper's settings: the scene's, with the stepper AUTO runs now.
  SolverSettings stepping = settings;
  std::unique_ptr<Stepper> stepper = MakeStepper(model, stepping);
  // AUTO, adaptive steps, while HHT is on trial: the central-difference
  // stepper it replaced, resumed (Stepper::Restart) if the trial loses.
  std::unique_ptr<Stepper> parked;
  std::string reason;
  if (!stepper->Initialize(&reason)) {
    Fail(summary, 0, reason);
    return;
  }
  summary->integrator_segments.push_back(
      {std::string(IntegratorName(stepping.integrator)), 0, 0,
       settings.auto_integrator ? summary->integrator_reason : "named by the scene"});
  ExternalWork external_work(model);
  model->SetTime(0);
  rec->AdvanceDamping(0, stepper->z(), stepper->v());
  if (absl::Status s = rec->Emit(0, 1, stepper->z(), &stepper->v(), &stepper->a(), &stepper->lambda());
      !s.ok()) {
    summary->status = "cancelled";
    summary->error = std::string(s.message());
    return;
  }
  // Strain energy the scene starts with: a start far from equilibrium (a
  // deck's or a hand-drawn polyline, a kink) releases it in the first steps.
  const double strain_initial_j = rec->frame().energy.axial + rec->frame().energy.bending;
  const double h_nominal = settings.step_s;
  const double h_min = std::ldexp(h_nominal, -settings.max_step_halvings);
  const double interval =
      settings.output_interval_s > 0 ? settings.output_interval_s : settings.step_s;
  const double duration = settings.duration_s;
  const long frames = std::max(1L, std::lround(std::ceil(duration / interval - 1e-9)));
  double t = 0;
  double h = h_nominal;
  int successes = 0;
  // Adaptive steps: Newton's own limit on the step. The error estimate
  // alone lets the step double until Newton fails (its iterations spent,
  // the step halved, doubled again...: the OC4 mooring at tolerance 1 m
  // rejected 372 steps for 469 accepted, 55 iterations each). After a step
  // whose Newton failed, steps stay below 0.8 of the failed one; the cap
  // rises by 1.25 after every kCapProbe accepted steps, so a scene that
  // softens gets its long steps back. A step that took kSlowNewton
  // iterations or more does not lengthen the next.
  constexpr int kCapProbe = 10, kSlowNewton = 10;
  double newton_cap = std::numeric_limits<double>::infinity();
  // Takes the last step back: the stepper's state, and the damping power
  // the recorder evaluated at its end (not a state of the run).
  auto TakeBack = [&] {
    stepper->Restore();
    rec->DropEndStep();
  };
  // Step attempts so far, and the end state's energy the guard evaluated
  // before accepting attempt guarded_attempt (reused by its frames).
  long attempt = 0, guarded_attempt = -1;
  EnergySample guarded_end;
  // The time of the last state the energy guard checked and passed [s].
  double guard_passed_t = 0;
  int since_cap = 0;
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
  // Backward Euler never raises the energy; the second-order steppers may.
  bool check_steps = !TraitsOf(stepping.integrator).never_raises_energy;
  summary->min_step_s = settings.adaptive ? std::numeric_limits<double>::infinity() : h_nominal;
  // Steps of h (the last one or two shortened to end on the duration);
  // frames between step ends are interpolated (DenseOutput). A frame's
  // energies and constraint violation are those of that interpolated state.
  DenseOutput dense(*stepper);
  auto frame_time = [&](long k) { return std::min(duration, k * interval); };
  // The energy guard on a state the stepper reached (a step's end): false
  // (with the summary failed) when its energy rose beyond the limit.
  // A winch's work is summed as a moving support's (MultibodyModel::
  // ExternalPower), so the guard holds on winch scenes too. Rises below the
  // model's energy rounding are a scene at rest.
  const EnergyGuard guard(true, summary->energy_initial, model->energy_roundoff());
  // A start as given that stores most of the largest energy term as
  // strain is likely not an equilibrium the scene meant (a MoorDyn deck's
  // points, a polyline's kink): an energy failure says how to start from one.
  auto AppendStartHint = [&](double scale, std::string* error) {
    if (settings.initial_state == InitialState::kAsGiven && strain_initial_j > 0.5 * scale) {
      absl::StrAppendFormat(
          error,
          "; the run started from the scene's points as given, which store %.3g J of strain "
          "energy: if they are not an equilibrium, solver.initial_state: STATIC starts from one",
          strain_initial_j);
    }
  };
  auto EnergyHolds = [&](const EnergySample& e, double t_state) {
    if (guard.Fails(e, rec->energy_scale())) {
      const double rise = guard.Rise(e), scale = EnergyGuard::Scale(e, rec->energy_scale());
      std::string error =
          absl::StrFormat("the total energy rose by %.3g J (more than %g %% of the largest "
                          "energy term, %.3g J) by t = %.9g s: the stepper is unstable at this "
                          "step; use a smaller solver.step, adaptive steps or a smaller "
                          "rho_infinity",
                          rise, 100 * EnergyGuard::kRiseLimit, scale, t_state);
      AppendStartHint(scale, &error);
      Fail(summary, t_state, error);
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
  // Line failure (JointRelease): at a state the run reached, the joints
  // whose time has come or whose force exceeds their breaking load let go;
  // the stepper restarts on the rebuilt model from that state. False (the
  // summary failed) when it cannot.
  auto LetGo = [&](double t_state) {
    if (release == nullptr) return true;
    absl::StatusOr<bool> let = release->LetGo(model, t_state, 1e-9 * h_nominal, stepper->z(),
                                              stepper->v(), stepper->lambda(),
                                              &summary->releases);
    if (!let.ok()) {
      Fail(summary, t_state, std::string(let.status().message()));
      return false;
    }
    if (!*let) return true;
    parked.reset();  // built on the model before the release
    stepper = MakeStepper(model, stepping);
    std::string why;
    if (!stepper->Initialize(&why)) {
      Fail(summary, t_state,
           absl::StrFormat("after a joint let go at t = %.9g s: %s", t_state, why));
      return false;
    }
    return true;
  };
  if (!LetGo(0)) return;
  // AUTO's change of stepper at the state the stepper holds (time t):
  // `next` (already started at that state, or null: made and started
  // here). False (the summary failed) when it cannot start.
  int64_t hht_steps = 0, next_explicit_try = 64;
  // A stepper of `to` started at the state the stepper holds (time
  // t_state), or null with the reason in `failed`.
  auto StartAt = [&](Integrator to, double t_state,
                     std::string* failed) -> std::unique_ptr<Stepper> {
    model->SetInitialState(stepper->z(), stepper->v(), model->external_work(), t_state);
    SolverSettings trial = stepping;
    trial.integrator = to;
    std::unique_ptr<Stepper> next = MakeStepper(model, trial);
    if (!next->Initialize(failed)) return nullptr;
    return next;
  };
  auto SwitchTo = [&](Integrator to, std::unique_ptr<Stepper> next, const std::string& why,
                      double t_state) {
    if (next == nullptr) {
      std::string failed;
      next = StartAt(to, t_state, &failed);
      if (next == nullptr) {
        Fail(summary, t_state,
             absl::StrFormat("AUTO could not change to %s at t = %.9g s: %s",
                             std::string(IntegratorName(to)), t_state, failed));
        return false;
      }
    }
    stepping.integrator = to;
    stepper = std::move(next);
    check_steps = !TraitsOf(to).never_raises_energy;
    hht_steps = 0;
    summary->integrator_segments.push_back(
        {std::string(IntegratorName(to)), t_state, 0, why});
    return true;
  };
  const bool may_switch = settings.auto_integrator && settings.auto_may_switch;
  const bool ran_explicit = TraitsOf(stepping.integrator).is_explicit;
  // AUTO with adaptive steps: over windows of accepted steps, the cost
  // model (auto_integrator.h) weighs the stepper that runs against the
  // other. On CENTRAL_DIFFERENCE the step HHT would take is the step the
  // error controller allows, h / sqrt(err) without the stable step's cap:
  // its estimate, h^2/6 (a - a_old), grows as h^2 where the undamped stiff
  // modes ring (HHT damps them), so this is the optimistic guess for HHT,
  // and HHT's own window below corrects it with its real steps and Newton
  // iterations (on the spatial pendulum at 1e-3 m, h err^(-1/3) guessed
  // 2e-3 s for HHT's 4.5e-3 s). On HHT the explicit steps are the window's
  // time over the stable step of a trial start (or one per HHT step where
  // that is shorter), and HHT's cost its own Newton iterations. The windows
  // double each time, whichever stepper runs, so that a scene at the edge
  // pays a logarithmic number of trial starts and changes.
  const bool adaptive_switch = may_switch && settings.adaptive;
  struct CostWindow {
    int64_t accepted = 0, attempts = 0;
    int64_t capped = 0;  // explicit steps held by the stable step
    double time = 0, newton = 0;
    double h_accurate = 0;  // the last step's h err^(-1/3)
  } window;
  int64_t window_length = kFirstCostWindow;       // the next window, accepted steps
  int64_t explicit_window = kFirstCostWindow;     // the next explicit one after a trial
  if (settings.adaptive) h = std::min(h, stepper->stable_step());
  // A step cut to end on a release time leaves the fixed steps' grid; the
  // step after it ends where the uncut step would have (grid_end), so that
  // the frames on the grid stay step ends.
  double grid_end = -1;
  long next_frame = 1;
  while (next_frame <= frames) {
    // A frame already reached (a duration within rounding of the last).
    if (const double tf = frame_time(next_frame); tf - t <= 1e-12 * std::max(1.0, tf)) {
      model->SetTime(tf);
      rec->Evaluate(tf, 1, stepper->z(), &stepper->v(), &stepper->a(), &stepper->lambda());
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
    double h_try = remaining < 2 * h && !whole ? remaining / std::ceil(left - 1e-9) : h;
    const double h_step = h_try;  // a failed step halves this, not a cut
    if (release != nullptr) {
      if (grid_end > t && grid_end - t < h_try) h_try = grid_end - t;
      if (const double until = release->NextTime() - t; until < h_try * (1 - 1e-9)) {
        if (!settings.adaptive) grid_end = t + h_try;
        h_try = until;
      }
    }
    dense.BeginStep(*stepper);
    external_work.Before(stepper->z(), t, stepper->lambda(), &stepper->v());
    const auto st = stepper->Step(h_try);
    if (model->stop_requested()) {  // the step was cut short (StopPoll)
      TakeBack();
      summary->status = "cancelled";
      summary->error = absl::StrFormat("stopped by the caller during the step from t = %.9g", t);
      return;
    }
    summary->newton_iterations += st.newton_iterations;
    if (adaptive_switch) {
      ++window.attempts;
      window.newton += st.newton_iterations;
    }
    summary->linear_iterations += st.linear_iterations;
    summary->factorizations += st.factorizations;
    summary->direct_fallbacks += st.direct_fallbacks;
    summary->linear_solves += st.linear_solves;
    summary->inexact_linear_solves += st.inexact_solves;
    summary->max_linear_residual = std::max(summary->max_linear_residual, st.max_linear_residual);
    ++attempt;
    // The guard looks at a converged step before accepting it when Newton
    // found it hard, and when a frame needs its end state's energy anyway
    // (a frame's guard could only fail the run, not halve the step: with
    // a faster Newton a step that was halved failed the run instead).
    const bool reaches_frame =
        next_frame <= frames && frame_time(next_frame) <= t + h_try * (1 + 1e-6);
    if (st.converged && check_steps && guard.enabled() &&
        (st.newton_iterations >= EnergyGuard::kCheckAfterNewtonIterations || reaches_frame)) {
      // A step Newton found hard may have landed on a spurious root (an
      // element folded through itself: Green-Lagrange strain does not see
      // it); its energy says so. Take it back and halve the step.
      rec->EndStep(t + h_try, stepper->z(), stepper->v(), attempt);
      const EnergySample e = rec->StateEnergy(t + h_try, stepper->z(), stepper->v());
      guarded_end = e;
      guarded_attempt = attempt;
      if (guard.Fails(e, rec->energy_scale())) {
        TakeBack();
        ++summary->rejected_steps;
        // A rise that the step's start already shows built up over the
        // steps since the last one checked (the guard checks a step only
        // where Newton needed kCheckAfterNewtonIterations or a frame ends
        // it): halving this one cannot take it back, so the run stops
        // here and says where the rise happened (measured on the chain of
        // tests/energy_guard_test.cc: risen by 4.3e8 J at 1.88 ms since the
        // check at 1.15 ms; each halving of the step there failed again).
        if (const EnergySample start = rec->StateEnergy(t, stepper->z(), stepper->v());
            guard.Fails(start, rec->energy_scale())) {
          const double scale = EnergyGuard::Scale(start, rec->energy_scale());
          std::string error = absl::StrFormat(
              "the total energy had risen by %.3g J (more than %g %% of the largest energy "
              "term, %.3g J) between t = %.9g s, the last state checked, and t = %.9g s, in "
              "steps the guard does not check one by one (fewer than %d Newton iterations, no "
              "frame at their end): the stepper was unstable there or its damped work "
              "inexact; use a smaller solver.step (or, with adaptive steps, "
              "solver.tolerance) or a smaller rho_infinity",
              guard.Rise(start), 100 * EnergyGuard::kRiseLimit, scale, guard_passed_t, t,
              EnergyGuard::kCheckAfterNewtonIterations);
          AppendStartHint(scale, &error);
          Fail(summary, t, error);
          return;
        }
        successes = 0;
        h = h_step / 2;
        summary->smallest_cut_step_s = std::min(summary->smallest_cut_step_s, h);
        if (h < h_min * (1 - 1e-12)) {
          std::string error =
              absl::StrFormat("step from t = %.9g s raises the total energy by %.3g J down to "
                              "h = %.3g s: the stepper is unstable here; use a smaller "
                              "rho_infinity",
                              t, guard.Rise(e), h_try);
          AppendStartHint(EnergyGuard::Scale(e, rec->energy_scale()), &error);
          Fail(summary, t + h_try, error);
          return;
        }
        continue;
      }
    }
    // Every run's error estimate of a converged step: the stepper's
    // embedded local error (one pass over the unknowns), absolute [m] and
    // against the tolerance. Without a relative tolerance the ratio is the
    // estimate over the tolerance, to the last bit (a division by a
    // positive constant is monotone), so one pass serves both. Computed
    // once per step: AUTO's check below needs it before acceptance.
    double error_m = -1, error_ratio = 0;
    auto EstimateStepError = [&] {
      error_m = stepper->LocalErrorNorm(h_try, 1, 0);
      error_ratio = settings.relative_tolerance == 0
                        ? error_m / settings.error_tolerance_m
                        : stepper->LocalErrorNorm(h_try, settings.error_tolerance_m,
                                                  settings.relative_tolerance);
    };
    // AUTO: an explicit step whose error estimate exceeds the run's
    // tolerance is taken back, and HHT goes on from the step's start.
    if (st.converged && may_switch && !settings.adaptive &&
        TraitsOf(stepping.integrator).is_explicit) {
      EstimateStepError();
      const double ratio = error_ratio;
      if (!(ratio <= 1)) {
        TakeBack();
        // Tries back to central difference start again at 64 HHT steps
        // after a long explicit stretch (the choice was right); after a
        // short one they stay spaced out (the scene is at the edge).
        const bool long_stretch =
            summary->integrator_segments.back().steps >= 4 * next_explicit_try;
        if (!SwitchTo(Integrator::kHht, nullptr,
                      absl::StrFormat("CENTRAL_DIFFERENCE's local error estimate was %.3g times "
                                      "the tolerance (%g m) in the step from t = %.9g s: the "
                                      "scene stiffened beyond its stable step, or the step is "
                                      "too long for its accuracy",
                                      ratio, settings.error_tolerance_m, t),
                      t))
          return;
        if (long_stretch) next_explicit_try = 64;
        continue;
      }
    }
    if (st.converged && settings.adaptive) {
      // Adaptive steps: accept when the local error estimate meets the
      // tolerance, and choose the next step from it either way.
      const double err = stepper->LocalErrorNorm(h_try, settings.tolerance_m,
                                                settings.relative_tolerance);
      const double factor = StepFactor(err, TraitsOf(stepping.integrator).local_error_order);
      if (!(err <= 1)) {
        TakeBack();
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
      if (adaptive_switch) {
        ++window.accepted;
        window.time += h_try;
        const int k = TraitsOf(Integrator::kHht).local_error_order;
        window.h_accurate =
            err > 0 ? std::min(duration, h_try * 0.9 * std::pow(err, -1.0 / k)) : duration;
        if (TraitsOf(stepping.integrator).is_explicit && h_try >= 0.999 * stepper->stable_step())
          ++window.capped;
      }
      // (A step cut to end on a release time keeps the step planned before.)
      const double grow =
          st.newton_iterations >= kSlowNewton ? std::min(factor, 1.0) : factor;
      if (std::isfinite(newton_cap) && ++since_cap >= kCapProbe) {
        newton_cap *= 1.25;
        since_cap = 0;
      }
      h = std::min({h_try < h_step ? h_step : h_try * grow, stepper->stable_step(), newton_cap});
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
      external_work.After(stepper->z(), t, stepper->lambda(), 1, &stepper->v());
      if (error_m < 0) EstimateStepError();
      summary->local_error_estimate_m = std::max(summary->local_error_estimate_m, error_m);
      summary->accumulated_error_estimate_m += error_m;
      summary->local_error_ratio = std::max(summary->local_error_ratio, error_ratio);
      ++summary->steps;
      ++summary->integrator_segments.back().steps;
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
      bool end_checked = false, checked_at_frame = false;
      rec->EndStep(t, stepper->z(), stepper->v(), attempt);
      while (next_frame <= frames) {
        const double tf = frame_time(next_frame);
        const bool at_end = std::abs(tf - t) <= 1e-6 * h_try;
        if (!at_end && tf > t) break;
        if (at_end) {
          t = tf;
          t_anchor = tf;
          tick_anchor = tick;
          model->SetTime(tf);
          rec->Evaluate(tf, 1, stepper->z(), &stepper->v(), &stepper->a(), &stepper->lambda());
        } else {
          // The step's end is guarded before any frame inside it goes out.
          if (!end_checked) {
            model->SetTime(t);
            const EnergySample end = guarded_attempt == attempt
                                         ? guarded_end
                                         : rec->StateEnergy(t, stepper->z(), stepper->v());
            if (!EnergyHolds(end, t)) return;
            rec->NoteReachedState(end);
            end_checked = true;
          }
          dense.Interpolate((tf - t0) / h_try, h_try, *stepper);
          model->SetTime(tf);
          rec->Evaluate(tf, 1, dense.z(), &dense.v(), &dense.a(), &dense.lambda());
        }
        if (!CheckAndDeliver(tf, /*guard=*/at_end)) return;
        checked_at_frame = checked_at_frame || at_end;
        ++next_frame;
      }
      if (guarded_attempt == attempt || end_checked || checked_at_frame) guard_passed_t = t;
      rec->AdvanceDamping(t, stepper->z(), stepper->v());
      // After the step's frames and damped work, which read the step's law.
      model->CommitViscoelastic(stepper->z(), t);
      summary->end_time_s = t;
      if (grid_end >= 0 && t >= grid_end - 1e-9 * h_nominal) grid_end = -1;
      if (!LetGo(t)) return;
      if (adaptive_switch && parked != nullptr && window.accepted >= kTrialSteps) {
        // HHT's trial is over: its cost per second of the run (its Newton
        // iterations at the step its last error estimate allows) against
        // central difference's (one unit per stable step).
        const CostWindow w = window;
        window = CostWindow{};
        const double newton = w.newton / static_cast<double>(w.accepted);
        const double implicit_rate = kNewtonIterationCost * newton / w.h_accurate;
        const double explicit_rate = 1 / parked->stable_step();
        if (explicit_rate * kSwitchMargin < implicit_rate &&
            parked->Restart(stepper->z(), stepper->v(), t)) {
          if (!SwitchTo(Integrator::kCentralDifference, std::move(parked),
                        absl::StrFormat("AUTO's cost model at t = %.9g s: HHT on trial took %.3g "
                                        "Newton iterations a step at steps of about %.3g s "
                                        "(%.4g units/s), CENTRAL_DIFFERENCE's stable step %.3g s "
                                        "(%.4g units/s)",
                                        t, newton, w.h_accurate, implicit_rate,
                                        1 / explicit_rate, explicit_rate),
                        t))
            return;
          h = std::min(h, stepper->stable_step());
          explicit_window *= kTrialSpacing;
          window_length = explicit_window;
        } else {
          parked.reset();
          window_length = 2 * kFirstCostWindow;
        }
      } else if (adaptive_switch && parked == nullptr && window.accepted >= window_length) {
        const CostWindow w = window;
        window = CostWindow{};
        window_length *= 2;
        if (TraitsOf(stepping.integrator).is_explicit) {
          // Held by its stable step over most of the window: the accuracy
          // would allow longer steps, which HHT may take. CENTRAL_DIFFERENCE's
          // own estimate cannot say how long (the undamped stiff modes ring
          // in it, HHT damps them: h err^(-1/3) guessed 0.5 to 2 times HHT's
          // steps on the pendulums, 0.1 times on the 1,000-element rope), so
          // HHT is tried for kTrialSteps steps, from that guess.
          if (2 * w.capped >= w.accepted) {
            std::string failed;
            if (std::unique_ptr<Stepper> next = StartAt(Integrator::kHht, t, &failed)) {
              parked = std::move(stepper);
              if (!SwitchTo(Integrator::kHht, std::move(next),
                            absl::StrFormat("AUTO's cost model at t = %.9g s: CENTRAL_DIFFERENCE's "
                                            "stable step (%.3g s) held %d of its last %d steps; "
                                            "HHT on trial for %d steps",
                                            t, parked->stable_step(), static_cast<int>(w.capped),
                                            static_cast<int>(w.accepted), kTrialSteps),
                            t))
                return;
              // From the step the accuracy may allow, not from the stable
              // step it would double up from.
              h = std::max(h, w.h_accurate);
            }
          }
        } else {
          const double newton_per_step = w.newton / static_cast<double>(w.accepted);
          model->SetInitialState(stepper->z(), stepper->v(), model->external_work(), t);
          std::string why;
          std::unique_ptr<Stepper> trial = TryExplicit(model, stepping, &why);
          if (trial != nullptr) {
            const double explicit_steps =
                std::max(static_cast<double>(w.accepted), w.time / trial->stable_step());
            const CostEstimate c =
                EstimateCosts(explicit_steps, static_cast<double>(w.accepted), newton_per_step);
            if (c.explicit_cost * kSwitchMargin < c.implicit_cost) {
              if (!SwitchTo(Integrator::kCentralDifference, std::move(trial),
                            absl::StrFormat("AUTO's cost model at t = %.9g s: over the last %.4g "
                                            "s HHT took %d steps and %d Newton iterations (%.4g "
                                            "units), where CENTRAL_DIFFERENCE would take about "
                                            "%.4g steps (%.4g units)",
                                            t, w.time, static_cast<int>(w.accepted),
                                            static_cast<int>(w.newton), c.implicit_cost,
                                            explicit_steps, c.explicit_cost),
                            t))
                return;
              h = std::min(h, stepper->stable_step());
              // HHT had won its trial (an optimistic guess of its step) and
              // lost over its window: the next trial comes kTrialSpacing
              // times further off too, or the two alternate every window
              // (the pendulum with a body at 1e-6 m: 180 changes in 2 s,
              // HHT two thirds of the steps, 1.7 times the cost of staying
              // explicit).
              explicit_window *= kTrialSpacing;
              window_length = explicit_window;
            }
          }
        }
      }
      // AUTO: HHT back to CENTRAL_DIFFERENCE once the scene admits it.
      // Only a run that was explicit before tries (one that started on HHT
      // because the step was beyond the stable step is not expected to
      // soften that far, and a trial start would touch its model's caches).
      if (may_switch && !settings.adaptive && ran_explicit &&
          !TraitsOf(stepping.integrator).is_explicit && h == h_nominal &&
          ++hht_steps >= next_explicit_try) {
        next_explicit_try *= 2;
        hht_steps = 0;
        model->SetInitialState(stepper->z(), stepper->v(), model->external_work(), t);
        std::string why;
        std::unique_ptr<Stepper> trial = TryExplicit(model, stepping, &why);
        if (trial != nullptr &&
            !SwitchTo(Integrator::kCentralDifference, std::move(trial),
                      absl::StrFormat("solver.step (%g s) is within CENTRAL_DIFFERENCE's stable "
                                      "step again at t = %.9g s (h omega_max < 2)",
                                      h_nominal, t),
                      t))
          return;
      }
      continue;
    }
    ++summary->rejected_steps;
    successes = 0;
    h = h_step / 2;
    if (settings.adaptive) {
      newton_cap = 0.8 * h_try;
      since_cap = 0;
    }
    summary->smallest_cut_step_s = std::min(summary->smallest_cut_step_s, h);
    if (h < h_min * (1 - 1e-12)) {
      Fail(summary, t + h_try,
           absl::StrFormat("step from t = %.9g s failed %d times down to h = %.3g s: %s", t,
                           settings.max_step_halvings + 1, h_try, st.reason));
      return;
    }
  }
}

}  // namespace cablesim
