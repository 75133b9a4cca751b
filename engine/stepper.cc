#include "engine/stepper.h"

#include "engine/generalized_alpha_stepper.h"
#include "engine/implicit_euler_stepper.h"

namespace cablesim {

std::unique_ptr<Stepper> MakeStepper(MultibodyModel* model, const SolverSettings& settings) {
  switch (settings.integrator) {
    case Integrator::kGeneralizedAlpha:
      return std::make_unique<GeneralizedAlphaStepper>(
          model, settings, GeneralizedAlphaStepper::Variant::kGeneralizedAlpha);
    case Integrator::kHht:
      return std::make_unique<GeneralizedAlphaStepper>(model, settings,
                                                       GeneralizedAlphaStepper::Variant::kHht);
    case Integrator::kImplicitEuler:
      break;
  }
  return std::make_unique<ImplicitEulerStepper>(model, settings);
}

}  // namespace cablesim
