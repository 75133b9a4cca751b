#ifndef CABLESIM_ENGINE_STEPPERS_MAKE_STEPPER_H_
#define CABLESIM_ENGINE_STEPPERS_MAKE_STEPPER_H_

// The stepper factory: the one file that knows every stepper class.

#include <memory>

#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/steppers/stepper.h"

namespace cablesim {

// The stepper `settings.integrator` names, for `model` (which must outlive it).
std::unique_ptr<Stepper> MakeStepper(MultibodyModel* model, const SolverSettings& settings);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_MAKE_STEPPER_H_
