#ifndef CABLESIM_ENGINE_RUN_STATIC_RUN_H_
#define CABLESIM_ENGINE_RUN_STATIC_RUN_H_

// STATIC analysis (the load path to equilibrium, a frame per load step)
// and a dynamic run's start from static equilibrium
// (solver.initial_state STATIC).

#include "engine/model/multibody_model.h"
#include "engine/output/results.h"
#include "engine/run/frame_recorder.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"

namespace cablesim {

void RunStatic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
               FrameRecorder* rec, RunSummary* summary);

// solver.initial_state STATIC: moves the model's initial state to the
// static equilibrium under the full gravity and loads (the load path of
// STATIC analysis, without its frames), solved to the rounding floor of the
// forces (newton_tolerance 1e-12) so that the motion starting there stays
// at rest to about a nanometre. Its Newton iterations count in the run's.
// False, with the summary failed at t = 0, when there is no equilibrium.
bool StartFromEquilibrium(MultibodyModel* model, const SolverSettings& settings,
                          const RunControl& control, RunSummary* summary);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_STATIC_RUN_H_
