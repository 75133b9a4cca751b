#include "convert/solver_applicability.h"

#include <functional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

// One rule: `field` is refused when the scene gives it (`given`) and it
// does not apply to the run (`applies` false); `why` says to what it does
// apply, given the run (for the analysis' name).
struct Rule {
  const char* field;
  std::function<bool(const v1::Solver&)> given;
  std::function<bool(const SolverSettings&)> applies;
  std::function<std::string(const SolverSettings&)> why;
};

bool Dynamic(const SolverSettings& s) { return s.analysis == Analysis::kDynamic; }

std::string DynamicOnly(const SolverSettings& s) {
  return absl::StrCat("applies to DYNAMIC analysis only (solver.analysis is ",
                      std::string(AnalysisName(s.analysis)), ")");
}

const std::vector<Rule>& Rules() {
  static const std::vector<Rule>* rules = new std::vector<Rule>{
      // Not refused: step, output_interval, integrator, rho_infinity and
      // reuse_factorization with STATIC or MODAL. They do nothing there, but
      // switching a dynamic scene's analysis to STATIC or MODAL, keeping its
      // solver section, is how its equilibrium or modes are had (the tests
      // and tutorials do it); refusing them would break that.
      // The static solve (STATIC, MODAL, initial_state STATIC) always uses
      // the BLOCK preconditioner and never accepts an inexact solve; these
      // two configure the time steps' Newton solves only.
      {"solver.preconditioner",
       [](const v1::Solver& p) {
         return p.preconditioner() != v1::Solver::PRECONDITIONER_UNSPECIFIED;
       },
       Dynamic,
       [](const SolverSettings& s) {
         return DynamicOnly(s) + "; the static solve always uses BLOCK";
       }},
      {"solver.accept_inexact_solves", [](const v1::Solver& p) { return p.accept_inexact_solves(); },
       Dynamic,
       [](const SolverSettings& s) {
         return DynamicOnly(s) + "; the static solve never accepts an inexact solve";
       }},
      // The load path to equilibrium.
      {"solver.load_steps", [](const v1::Solver& p) { return p.has_load_steps(); },
       [](const SolverSettings& s) {
         return !Dynamic(s) || s.initial_state == InitialState::kStatic;
       },
       [](const SolverSettings&) {
         return std::string(
             "applies to STATIC and MODAL analysis and to solver.initial_state STATIC (the load "
             "path to equilibrium); this DYNAMIC run starts AS_GIVEN");
       }},
  };
  return *rules;
}

}  // namespace

absl::Status CheckSolverSettingsApply(const v1::Solver& proto, const SolverSettings& settings) {
  for (const Rule& rule : Rules()) {
    if (rule.given(proto) && !rule.applies(settings)) {
      return absl::InvalidArgumentError(absl::StrCat(rule.field, ": ", rule.why(settings)));
    }
  }
  return absl::OkStatus();
}

}  // namespace cablesim
