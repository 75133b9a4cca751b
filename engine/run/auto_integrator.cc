#include "engine/run/auto_integrator.h"

#include <memory>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/scene/integrator_traits.h"
#include "engine/steppers/make_stepper.h"

namespace cablesim {
namespace {

// Why the scene needs an implicit stepper; empty: it does not.
std::string ImplicitNeed(const MultibodyModel& model, const Scene& scene) {
  const SolverSettings& s = scene.solver;
  if (!s.auto_keep_implicit.empty())
    return absl::StrCat(s.auto_keep_implicit, " is given, which applies to implicit steppers only");
  for (int c = 0; c < static_cast<int>(scene.cables.size()); ++c)
    if (scene.cables[c].winch.enabled)
      return absl::StrFormat("cables[%d] has a winch (a mass that changes with time)", c);
  for (int c = 0; c < static_cast<int>(scene.cables.size()); ++c)
    if (scene.cables[c].axial_law == AxialLaw::kViscoelastic)
      return absl::StrFormat("cables[%d] is viscoelastic (its dashpots' law is integrated over "
                             "each implicit step)", c);
  if (scene.seabed.enabled) return "the seabed's contact stiffens the scene mid-run";
  if (!scene.sheaves.empty()) return "the sheaves' contact stiffens the scene mid-run";
  for (int b = 0; b < static_cast<int>(scene.bodies.size()); ++b)
    if (!scene.bodies[b].contact_points_m.empty())
      return absl::StrFormat("bodies[%d]'s contact points stiffen the scene mid-run", b);
  if (scene.fluid.density_kg_m3 > 0) return "the fluid's loads (drag, waves) are not checked for the explicit steppers' stability";
  return "";
}

// Chooses `chosen`: the reason is its name (integrator_traits.h) and why.
Integrator Choose(Integrator chosen, const std::string& why, std::string* reason) {
  *reason = absl::StrCat(std::string(IntegratorName(chosen)), ": ", why);
  return chosen;
}

// ChooseIntegrator without the note on adaptive steps.
Integrator ChooseStepper(MultibodyModel* model, const Scene& scene, std::string* reason,
                         bool* may_switch) {
  const SolverSettings& s = scene.solver;
  if (may_switch != nullptr) *may_switch = false;
  if (const std::string need = ImplicitNeed(*model, scene); !need.empty()) {
    // The Newton economy chosen from the scene (convert/scene/solver.cc).
    const std::string& fresh = s.reuse_factorization_off;
    return Choose(Integrator::kHht,
                  fresh.empty() || s.reuse_factorization ? need
                                : absl::StrCat(need, "; a fresh Newton matrix every iteration "
                                                     "(solver.reuse_factorization false): ",
                                               fresh),
                  reason);
  }
  if (may_switch != nullptr) *may_switch = true;
  if (s.adaptive) {
    // Measured (docs/honest-runs.md): adaptive DORMAND_PRINCE is held to
    // its stable step (six force evaluations a step) and was 2-7 times
    // slower than adaptive CENTRAL_DIFFERENCE on the two pendulums.
    // Whether the stable step or the accuracy limits the step is known
    // once the controller has run a while: RunDynamic weighs the two by
    // the cost model and may change to HHT (and back).
    return Choose(Integrator::kCentralDifference,
                  absl::StrCat(model->multipliers() > 0
                                   ? absl::StrFormat("no winch, contact or fluid; its %d constraint "
                                                     "rows held by RATTLE",
                                                     model->multipliers())
                                   : std::string("no constraint rows, winch, contact or fluid"),
                               "; adaptive steps hold its error "
                  "(and its stability: a growing mode's error is rejected); the run changes "
                  "to HHT if the cost model finds the stable step makes it costlier"),
                  reason);
  }
  std::string why;
  if (TryExplicit(model, s, &why) == nullptr) {
    return Choose(Integrator::kHht,
                  absl::StrCat(std::string(IntegratorName(Integrator::kCentralDifference)),
                               " does not fit: ", why),
                  reason);
  }
  return Choose(Integrator::kCentralDifference,
                absl::StrFormat("%s, and solver.step "
                                "(%g s) is within its stable step at the initial state "
                                "(h omega_max < 2)",
                                model->multipliers() > 0
                                    ? absl::StrFormat("no winch, contact or fluid; its %d "
                                                      "constraint rows held by RATTLE",
                                                      model->multipliers())
                                    : std::string("no constraint rows, winch, contact or fluid"),
                                s.step_s),
                reason);
}

}  // namespace

std::unique_ptr<Stepper> TryExplicit(MultibodyModel* model, const SolverSettings& settings,
                                     std::string* why) {
  SolverSettings trial = settings;
  trial.integrator = Integrator::kCentralDifference;
  std::unique_ptr<Stepper> stepper = MakeStepper(model, trial);
  const bool fits = stepper->Initialize(why);
  model->SetTime(model->initial_time());
  if (!fits) stepper.reset();
  return stepper;
}

Integrator ChooseIntegrator(MultibodyModel* model, const Scene& scene, std::string* reason,
                            bool* may_switch) {
  const Integrator chosen = ChooseStepper(model, scene, reason, may_switch);
  if (scene.solver.auto_step)
    absl::StrAppendFormat(reason,
                          "; steps adaptive, held to a local error of %g m (solver.step not "
                          "given)",
                          scene.solver.tolerance_m);
  return chosen;
}

}  // namespace cablesim
