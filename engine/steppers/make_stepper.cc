#include "engine/steppers/make_stepper.h"

#include "engine/steppers/central_difference_stepper.h"
#include "engine/steppers/dormand_prince_stepper.h"
#include "engine/steppers/energy_momentum_stepper.h"
#include "engine/steppers/generalized_alpha_stepper.h"
#include "engine/steppers/implicit_euler_stepper.h"

namespace cablesim {

std::unique_ptr<Stepper> MakeStepper(MultibodyModel* model, const SolverSettings& settings) {
  switch (settings.integrator) {
    case Integrator::kGeneralizedAlpha:
      return std::make_unique<GeneralizedAlphaStepper>(
          model, settings, GeneralizedAlphaStepper::Variant::kGeneralizedAlpha);
    case Integrator::kHht:
      return std::make_unique<GeneralizedAlphaStepper>(model, settings,
                                                       GeneralizedAlphaStepper::Variant::kHht);
    case Integrator::kEnergyMomentum:
      return std::make_unique<EnergyMomentumStepper>(model, settings);
    case Integrator::kDormandPrince:
      return std::make_unique<DormandPrinceStepper>(model, settings);
    case Integrator::kCentralDifference:
      return std::make_unique<CentralDifferenceStepper>(model, settings);
    case Integrator::kImplicitEuler:
      break;
  }
  return std::make_unique<ImplicitEulerStepper>(model, settings);
}

}  // namespace cablesim
