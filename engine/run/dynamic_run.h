#ifndef CABLESIM_ENGINE_RUN_DYNAMIC_RUN_H_
#define CABLESIM_ENGINE_RUN_DYNAMIC_RUN_H_

// The dynamic run: steps from t = 0 to the duration with the scene's
// stepper (fixed steps halved on failure and grown back on the nominal
// grid, or adaptive steps from the local error estimate), the energy guard
// (EnergyGuard), frames at every output interval (step ends, or
// DenseOutput between them) and the work of external agents.

#include "engine/model/multibody_model.h"
#include "engine/output/results.h"
#include "engine/run/frame_recorder.h"
#include "engine/run/joint_release.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"

namespace cablesim {

// `release` (null: no joint of the scene lets go): line failure, see
// joint_release.h; the model may be replaced in place by a rebuilt one.
void RunDynamic(MultibodyModel* model, const SolverSettings& settings, const RunControl& control,
                FrameRecorder* rec, RunSummary* summary, JointRelease* release = nullptr);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_DYNAMIC_RUN_H_
