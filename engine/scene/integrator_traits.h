#ifndef CABLESIM_ENGINE_SCENE_INTEGRATOR_TRAITS_H_
#define CABLESIM_ENGINE_SCENE_INTEGRATOR_TRAITS_H_

// Every fact about a time integrator that code outside its stepper needs,
// in one table: its name in scene files, its orders, what scenes it takes,
// which solver settings apply to it. The stepper factory
// (engine/steppers/make_stepper.cc) is the only other place that lists the
// integrators. A new stepper adds one row here (docs/development.md).
//
// It lives with the scene (the lowest layer) because the scene checks in
// convert/, the model builder (ModelBuilder::CheckIntegratorFits) and the
// run loop all read it; none of them may include the steppers.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"

namespace cablesim {

struct IntegratorTraits {
  Integrator integrator;
  std::string_view name;  // the scene-file spelling, what the summary reports
  // Global order of accuracy in positions at a fixed step.
  int order;
  // The power of h in the local error estimate (order + 1 for the one-step
  // methods here; DORMAND_PRINCE's embedded estimate is of its fifth-order
  // solution), for the adaptive step-size controller.
  int local_error_order;
  // The order of the frames between step ends (cubic Hermite dense output
  // caps it at 4), used by the Richardson error estimate.
  int frame_order;
  // No Newton iteration: the constant mass matrix is factored once and
  // every step costs force evaluations only. Such steppers take no
  // winches (the mass must be constant), and the Newton and linear-solver
  // settings do not apply to them.
  bool is_explicit;
  // Takes winches (a mass that changes with time).
  bool takes_winches;
  // solver.rho_infinity applies (the alpha family).
  bool has_rho_infinity;
  // Smallest rho_infinity it accepts (HHT's alpha is limited to [-1/3, 0]).
  double min_rho_infinity;
  // Its Newton matrix can be kept across iterations and steps
  // (solver.reuse_factorization applies), and whether that is the default.
  bool keeps_newton_matrix;
  bool reuses_matrix_by_default;
  // Never raises the energy (backward Euler): the per-step energy guard is
  // not needed.
  bool never_raises_energy;
  // Takes constraint rows (bodies' axes, joints between parts, moving
  // supports): every implicit stepper, and CENTRAL_DIFFERENCE by RATTLE
  // (central_difference_stepper.h); DORMAND_PRINCE integrates unconstrained
  // motion only.
  bool takes_constraint_rows = true;
};

inline constexpr std::array<IntegratorTraits, 6> kIntegratorTraits = {{
    // integrator, name, order, local, frames, explicit, winches, rho, rho_min, keep, reuse, no-rise,
    // rows (default true)
    {Integrator::kImplicitEuler, "IMPLICIT_EULER", 1, 2, 1, false, true, false, 0.0, false, false,
     true},
    {Integrator::kGeneralizedAlpha, "GENERALIZED_ALPHA", 2, 3, 2, false, true, true, 0.0, true,
     true, false},
    {Integrator::kHht, "HHT", 2, 3, 2, false, true, true, 0.5, true, true, false},
    // Energy-momentum needs a constant mass for its energy statement.
    {Integrator::kEnergyMomentum, "ENERGY_MOMENTUM", 2, 3, 2, false, false, false, 0.0, true,
     false, false},
    // Fifth order at its steps; frames between steps are cubic Hermite.
    {Integrator::kDormandPrince, "DORMAND_PRINCE", 5, 5, 4, true, false, false, 0.0, false, false,
     false, false},
    {Integrator::kCentralDifference, "CENTRAL_DIFFERENCE", 2, 3, 2, true, false, false, 0.0, false,
     false, false, true},
}};

// The row of `integrator` (every enumerator has one; checked in
// tests/stepper_conformance_test.cc).
constexpr const IntegratorTraits& TraitsOf(Integrator integrator) {
  for (const IntegratorTraits& t : kIntegratorTraits)
    if (t.integrator == integrator) return t;
  return kIntegratorTraits[0];
}

// The scene-file spelling, e.g. "HHT" (what the summary reports).
constexpr std::string_view IntegratorName(Integrator integrator) {
  return TraitsOf(integrator).name;
}

// The names of the integrators whose row satisfies `pred`, in the table's
// order, as "A, B or C" (the alternatives an error message offers).
template <typename Pred>
std::string IntegratorNames(Pred pred) {
  std::vector<std::string_view> names;
  for (const IntegratorTraits& t : kIntegratorTraits)
    if (pred(t)) names.push_back(t.name);
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) out += i + 1 == names.size() ? " or " : ", ";
    out += names[i];
  }
  return out;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_INTEGRATOR_TRAITS_H_
