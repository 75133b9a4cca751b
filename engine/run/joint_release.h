#ifndef CABLESIM_ENGINE_RUN_JOINT_RELEASE_H_
#define CABLESIM_ENGINE_RUN_JOINT_RELEASE_H_

// Line failure in a dynamic run (JointSpec::release_time_s,
// breaking_load_n): a PIN or FIXED joint lets go at a given time, or at the
// end of the first accepted step whose reaction force |F| on the joint
// exceeds its breaking load (detection to within one step).
//
// How: the model is rebuilt from the scene with the joint marked released
// (ModelBuilder makes no rows for it; its name and reaction columns stay
// and read 0), the state is carried over through full coordinates (q and
// qdot are continuous, so is every energy: releasing a joint does no work
// at the instant), the external work done so far is carried over, and the
// stepper restarts (Stepper::Initialize finds the new consistent
// acceleration; the acceleration and the multipliers jump at a release).
// A joint that may let go is kept as constraint rows even without
// output.reactions, so that its multipliers are its force.
//
// The rebuilt model replaces the run's model in place, so that every
// object holding a pointer to it (FrameRecorder, ExternalWork) follows.
// Start() puts the scene's own model back before a run (the error
// estimate's companion run starts from the same model as the main run).

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/model/multibody_model.h"
#include "engine/output/results.h"
#include "engine/scene/scene.h"

namespace cablesim {

class JointRelease {
 public:
  // Whether any joint of the scene may let go.
  static bool Wanted(const Scene& scene);

  explicit JointRelease(const Scene& scene) : scene_(scene) {}

  // Before a dynamic run on `model`: the first call records the model's
  // initial state; later calls, after joints let go in an earlier run,
  // rebuild the scene's model and give it that initial state again.
  absl::Status Start(MultibodyModel* model);

  // The earliest release time still pending (infinity: none).
  double NextTime() const;

  // At a state the run reached at time t (full unknowns z, rates v,
  // multipliers lambda of `model`): lets go every joint whose release time
  // has come (within `time_tolerance` [s]) or whose force exceeds its
  // breaking load, appending one event per joint to `events`, and rebuilds
  // the model. Returns whether any joint let go (the caller then restarts
  // its stepper on the model's initial state, which is this one); an error
  // when the rebuild fails.
  absl::StatusOr<bool> LetGo(MultibodyModel* model, double t, double time_tolerance,
                             const Eigen::VectorXd& z, const Eigen::VectorXd& v,
                             const Eigen::VectorXd& lambda,
                             std::vector<JointReleaseEvent>* events);

 private:
  // The reaction force [N] on side a of every scene joint at a state, into
  // forces_ (0 for joints without rows).
  void JointForces(const MultibodyModel& model, const Eigen::VectorXd& z,
                   const Eigen::VectorXd& lambda);

  Scene scene_;  // released joints marked
  bool started_ = false;
  bool rebuilt_ = false;  // the model in use is not the scene's own
  Eigen::VectorXd z0_, v0_;
  std::vector<Eigen::Vector3d> forces_, moments_;
  Eigen::VectorXd q_, qdot_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_JOINT_RELEASE_H_
