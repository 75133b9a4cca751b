#include "convert/scene/sections.h"

#include <algorithm>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "convert/scene_from_proto.h"
#include "convert/solver_applicability.h"
#include "engine/scene/integrator_traits.h"

namespace cablesim::scene_convert {
namespace {

// Relative tolerance of the comparisons between solver times.
constexpr double kTimeTolerance = 1e-9;
constexpr double kDefaultStep = 1e-3;
constexpr double kMaxFrames = 1e7;
constexpr int kDefaultLoadSteps = 10;
constexpr int kMaxLoadSteps = 100000;
constexpr double kDefaultNewtonTolerance = 1e-8;
constexpr double kMaxTolerance = 1e-2;
constexpr int kDefaultMaxNewtonIterations = 25;
constexpr int kMaxNewtonIterations = 1000;
constexpr int kDefaultMaxStepHalvings = 12;
constexpr int kMaxStepHalvings = 40;
constexpr double kDefaultLinearTolerance = 1e-10;
constexpr int kDefaultMaxLinearIterations = 200;
constexpr int kMaxLinearIterations = 100000;
// MODAL: the engine also bounds modes by the scene's degrees of freedom.
constexpr int kMaxModes = 100000;

// Fixed steps without solver.tolerance: the local error estimate is held to
// this fraction of the scene's size (SceneSize). 1 % of the size in one
// step: the estimate is the largest over every unknown and step (slopes
// and stiff axial modes included), so a tighter default flagged most
// sample scenes, whose results are checked against references
// (docs/honest-runs.md has the figures).
constexpr double kDefaultRelativeErrorTolerance = 1e-2;
// AUTO without solver.step: the local error tolerance of its adaptive
// steps, relative to the scene's size (SceneSize), when the scene gives no
// solver.tolerance.
constexpr double kDefaultAutoStepRelativeTolerance = 1e-4;

// A tolerance in (0, kMaxTolerance].
absl::Status CheckTolerance(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value > 0 && value <= kMaxTolerance)) {
    return Invalid(path,
                   absl::StrCat("must be in (0, ", Num(kMaxTolerance), "] (got ", Num(value), ")"));
  }
  return absl::OkStatus();
}

// The first Newton or linear-solver setting `s` gives (the settings only an
// implicit step uses), or nullptr.
const char* NewtonSettingGiven(const v1::Solver& s) {
  for (const auto& [has, field] :
       {std::pair{s.has_newton_tolerance(), "solver.newton_tolerance"},
        std::pair{s.has_max_newton_iterations(), "solver.max_newton_iterations"},
        std::pair{s.has_linear_tolerance(), "solver.linear_tolerance"},
        std::pair{s.has_max_linear_iterations(), "solver.max_linear_iterations"},
        std::pair{s.preconditioner() != v1::Solver::PRECONDITIONER_UNSPECIFIED,
                  "solver.preconditioner"},
        std::pair{s.accept_inexact_solves(), "solver.accept_inexact_solves"}}) {
    if (has) return field;
  }
  return nullptr;
}

// The scene's size for the default error tolerance [m]: its longest
// cable, at least 1 m.
double SceneSize(const v1::Scene& proto) {
  double size = 1;
  for (const v1::Cable& c : proto.cables()) size = std::max(size, c.length());
  return size;
}

}  // namespace

absl::Status ConvertSolver(ConversionState* state) {
  const v1::Solver& s = state->proto.solver();
  SolverSettings& out = state->scene.solver;
  CABLESIM_ASSIGN_OR_RETURN(out.analysis, AnalysisFromProto(s.analysis(), "solver.analysis"));
  CABLESIM_ASSIGN_OR_RETURN(out.integrator,
                            IntegratorFromProto(s.integrator(), "solver.integrator"));
  CABLESIM_ASSIGN_OR_RETURN(out.linear_solver,
                            LinearSolverFromProto(s.linear_solver(), "solver.linear_solver"));

  CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.duration", s.duration()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.step", s.step()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.output_interval", s.output_interval()));
  out.step_s = s.has_step() ? s.step() : kDefaultStep;
  CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("solver.step", out.step_s, plausible::kStep));
  out.output_interval_s = s.has_output_interval() ? s.output_interval() : out.step_s;
  CABLESIM_RETURN_IF_ERROR(CheckPositive("solver.output_interval", out.output_interval_s));
  out.duration_s = s.duration();
  CABLESIM_RETURN_IF_ERROR(CheckRange("solver.duration", s.duration(), plausible::kDuration));
  if (out.analysis == Analysis::kDynamic) {
    if (!(s.duration() > 0)) {
      return Invalid("solver.duration", absl::StrCat("must be > 0 for DYNAMIC analysis (got ",
                                                     Num(s.duration()), ")"));
    }
    if (out.duration_s / out.step_s > plausible::kMaxNominalSteps) {
      return Invalid(
          "solver.step",
          absl::StrCat("solver.duration / solver.step is ", Num(out.duration_s / out.step_s),
                       " steps (at most ", Num(plausible::kMaxNominalSteps), ")"));
    }
    if (out.step_s > out.duration_s * (1 + kTimeTolerance)) {
      return Invalid("solver.step",
                     absl::StrCat("must be <= solver.duration (", Num(out.duration_s), "; got ",
                                  Num(out.step_s), ")"));
    }
    if (out.output_interval_s > out.duration_s * (1 + kTimeTolerance)) {
      return Invalid("solver.output_interval",
                     absl::StrCat("must be <= solver.duration (", Num(out.duration_s), "; got ",
                                  Num(out.output_interval_s), ")"));
    }
    if (out.duration_s / out.output_interval_s > kMaxFrames) {
      return Invalid(
          "solver.output_interval",
          absl::StrCat("too many frames (duration / output_interval > ", Num(kMaxFrames), ")"));
    }
  } else {
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("solver.duration", s.duration()));
  }

  // An optional count: the scene's value or the default, then its range.
  const auto count_setting = [](bool has, int value, int fallback, absl::string_view path,
                                int lo, int hi, int* setting) {
    *setting = has ? value : fallback;
    return CheckIntRange(path, *setting, lo, hi);
  };
  CABLESIM_RETURN_IF_ERROR(count_setting(s.has_load_steps(), s.load_steps(), kDefaultLoadSteps,
                                         "solver.load_steps", 1, kMaxLoadSteps, &out.load_steps));
  out.newton_tolerance = s.has_newton_tolerance() ? s.newton_tolerance() : kDefaultNewtonTolerance;
  CABLESIM_RETURN_IF_ERROR(CheckTolerance("solver.newton_tolerance", out.newton_tolerance));
  CABLESIM_RETURN_IF_ERROR(count_setting(
      s.has_max_newton_iterations(), s.max_newton_iterations(), kDefaultMaxNewtonIterations,
      "solver.max_newton_iterations", 1, kMaxNewtonIterations, &out.max_newton_iterations));
  CABLESIM_RETURN_IF_ERROR(count_setting(
      s.has_max_step_halvings(), s.max_step_halvings(), kDefaultMaxStepHalvings,
      "solver.max_step_halvings", 0, kMaxStepHalvings, &out.max_step_halvings));
  out.linear_tolerance = s.has_linear_tolerance() ? s.linear_tolerance() : kDefaultLinearTolerance;
  CABLESIM_RETURN_IF_ERROR(CheckTolerance("solver.linear_tolerance", out.linear_tolerance));
  CABLESIM_RETURN_IF_ERROR(count_setting(
      s.has_max_linear_iterations(), s.max_linear_iterations(), kDefaultMaxLinearIterations,
      "solver.max_linear_iterations", 1, kMaxLinearIterations, &out.max_linear_iterations));
  switch (s.preconditioner()) {
    case v1::Solver::PRECONDITIONER_UNSPECIFIED:
    case v1::Solver::BLOCK:
      out.preconditioner = PreconditionerKind::kBlock;
      break;
    case v1::Solver::JACOBI:
      out.preconditioner = PreconditionerKind::kJacobi;
      break;
    case v1::Solver::NONE:
      out.preconditioner = PreconditionerKind::kNone;
      break;
    default:
      return Invalid("solver.preconditioner", "unknown value");
  }
  out.accept_inexact_solves = s.accept_inexact_solves();
  if (s.has_modes()) {
    if (out.analysis != Analysis::kModal) {
      return Invalid("solver.modes", absl::StrCat("is only for MODAL analysis (solver.analysis is ",
                                                  std::string(AnalysisName(out.analysis)), ")"));
    }
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("solver.modes", s.modes(), 1, kMaxModes));
    out.modes = s.modes();
  }

  const IntegratorTraits& traits = TraitsOf(out.integrator);
  // AUTO_STEPPER, and the default for DYNAMIC runs (an unset integrator).
  out.auto_integrator =
      s.integrator() == v1::AUTO_STEPPER ||
      (s.integrator() == v1::INTEGRATOR_UNSPECIFIED && out.analysis == Analysis::kDynamic);
  if (out.auto_integrator) {
    // The settings that only an implicit stepper uses keep AUTO implicit
    // (rather than be ignored by an explicit one, or refused).
    if (s.has_rho_infinity()) {
      out.auto_keep_implicit = "solver.rho_infinity";
    } else if (s.has_reuse_factorization()) {
      out.auto_keep_implicit = "solver.reuse_factorization";
    } else if (s.linear_solver() == v1::MINRES || s.linear_solver() == v1::GMRES) {
      out.auto_keep_implicit = "solver.linear_solver";
    } else if (const char* field = NewtonSettingGiven(s); field != nullptr) {
      out.auto_keep_implicit = field;
    }
  }
  if (s.has_rho_infinity()) {
    if (!traits.has_rho_infinity) {
      return Invalid("solver.rho_infinity",
                     "applies to GENERALIZED_ALPHA and HHT only (solver.integrator is " +
                         std::string(IntegratorName(out.integrator)) + ")");
    }
    const double lo = traits.min_rho_infinity;
    if (!(s.rho_infinity() >= lo && s.rho_infinity() <= 1)) {
      return Invalid("solver.rho_infinity",
                     absl::StrCat("must be in [", Num(lo), ", 1] for ",
                                  std::string(IntegratorName(out.integrator)), " (got ",
                                  Num(s.rho_infinity()), ")"));
    }
    out.rho_infinity = s.rho_infinity();
  }
  // A viscoelastic line's dashpots are integrated over each step of an
  // implicit stepper (engine/elements/viscoelastic_history.h): the
  // explicit ones would see them at the step's start only, and
  // ENERGY_MOMENTUM's discrete gradient is for a potential.
  if (out.analysis == Analysis::kDynamic && !out.auto_integrator &&
      (traits.is_explicit || out.integrator == Integrator::kEnergyMomentum)) {
    for (size_t c = 0; c < state->scene.cables.size(); ++c) {
      if (state->scene.cables[c].axial_law != AxialLaw::kViscoelastic) continue;
      return Invalid("solver.integrator",
                     absl::StrCat(std::string(IntegratorName(out.integrator)),
                                  " does not apply to cables[", c,
                                  "], whose axial_law is VISCOELASTIC: use IMPLICIT_EULER, "
                                  "GENERALIZED_ALPHA, HHT or AUTO"));
    }
  }
  out.adaptive = s.adaptive();
  out.error_estimate = s.error_estimate();
  // Steppers whose Newton matrix can be kept across iterations and steps
  // (IntegratorTraits::keeps_newton_matrix).
  const bool keeps_matrix = traits.keeps_newton_matrix;
  // Default on for the alpha family, except on a scene whose tangents
  // move with the state (seabed contact, the cables' fluid drag:
  // ReuseCostsNewton, measured in docs/steppers.md); off for
  // ENERGY_MOMENTUM, whose point is conservation: with a kept matrix
  // Newton converges linearly and stops just under its tolerance, and
  // those residuals add up (the 100 s falling pendulum drifted by 2e-5 of
  // its energy with it, 5e-7 without).
  out.reuse_factorization =
      s.has_reuse_factorization() ? s.reuse_factorization() : traits.reuses_matrix_by_default;
  if (!s.has_reuse_factorization() && out.reuse_factorization) {
    out.reuse_factorization_off = ReuseCostsNewton(state->scene);
    if (!out.reuse_factorization_off.empty()) out.reuse_factorization = false;
  }
  if (s.has_reuse_factorization() && s.reuse_factorization() && !keeps_matrix) {
    return Invalid(
        "solver.reuse_factorization",
        "applies to GENERALIZED_ALPHA, HHT and ENERGY_MOMENTUM only (solver.integrator is " +
            std::string(IntegratorName(out.integrator)) + ")");
  }
  // Explicit steppers take no Newton iteration and solve only with the
  // constant mass matrix, factored once: the Newton and linear-solver
  // settings do not apply to them, unless a static solve runs first
  // (analysis STATIC or MODAL, or initial_state STATIC), which uses them.
  const bool static_solve =
      out.analysis != Analysis::kDynamic || s.initial_state() == v1::Solver::STATIC;
  if (traits.is_explicit && !static_solve) {
    const std::string name(IntegratorName(out.integrator));
    const std::string why = "does not apply to " + name +
                            " (explicit: no Newton iteration; it solves only with the constant "
                            "mass matrix, factored once)";
    if (s.linear_solver() == v1::MINRES || s.linear_solver() == v1::GMRES)
      return Invalid("solver.linear_solver", why);
    if (const char* field = NewtonSettingGiven(s); field != nullptr) return Invalid(field, why);
  }
  // The tolerances hold adaptive steps and every DYNAMIC run's error
  // estimate (engine/run/run_warnings.h).
  for (const auto& [has, name] :
       {std::pair{s.has_tolerance(), "solver.tolerance"},
        std::pair{s.has_relative_tolerance(), "solver.relative_tolerance"}}) {
    if (has && out.analysis != Analysis::kDynamic) {
      return Invalid(name, absl::StrCat("applies to DYNAMIC analysis only (solver.analysis is ",
                                        std::string(AnalysisName(out.analysis)), ")"));
    }
  }
  out.strict = s.strict();
  switch (s.initial_state()) {
    case v1::Solver::INITIAL_STATE_UNSPECIFIED:
    case v1::Solver::AS_GIVEN:
      break;
    case v1::Solver::STATIC:
      if (out.analysis != Analysis::kDynamic) {
        return Invalid("solver.initial_state", "STATIC applies to DYNAMIC analysis only");
      }
      out.initial_state = InitialState::kStatic;
      break;
    default:
      return Invalid("solver.initial_state",
                     absl::StrCat("unknown value ", static_cast<int>(s.initial_state()),
                                  " (expected AS_GIVEN or STATIC)"));
  }
  if ((out.adaptive || out.error_estimate) && out.analysis != Analysis::kDynamic) {
    return Invalid(out.adaptive ? "solver.adaptive" : "solver.error_estimate",
                   "applies to DYNAMIC analysis only");
  }
  if (s.has_tolerance()) {
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange("solver.tolerance", s.tolerance(), plausible::kErrorTolerance));
    out.tolerance_m = s.tolerance();
  }
  if (s.has_relative_tolerance()) {
    CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.relative_tolerance", s.relative_tolerance()));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("solver.relative_tolerance", s.relative_tolerance()));
    if (!(s.relative_tolerance() < 1)) {
      return Invalid("solver.relative_tolerance",
                     absl::StrCat("must be < 1 (got ", Num(s.relative_tolerance()), ")"));
    }
    out.relative_tolerance = s.relative_tolerance();
  }
  // AUTO and no step: the step is AUTO's to choose too, so it steps
  // adaptively, held to the scene's tolerance or 1e-4 of the scene's size
  // (a fixed 1 ms step, the old default, ran the OC4 mooring 60 times
  // slower than it needed: docs/steppers.md).
  if (out.auto_integrator && out.analysis == Analysis::kDynamic && !s.has_step() &&
      !out.adaptive) {
    out.adaptive = true;
    out.auto_step = true;
    if (!s.has_tolerance())
      out.tolerance_m = kDefaultAutoStepRelativeTolerance * SceneSize(state->proto);
  }
  // What the run's error estimate is held to: the scene's tolerance, the
  // adaptive controller's default, or for fixed steps a default relative
  // to the scene's size.
  out.error_tolerance_m = s.has_tolerance() || out.adaptive
                              ? out.tolerance_m
                              : kDefaultRelativeErrorTolerance * SceneSize(state->proto);
  // Settings given that would do nothing in this run (a table).
  return CheckSolverSettingsApply(s, out);
}

}  // namespace cablesim::scene_convert
