#include "engine/run/joint_release.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_format.h"

namespace cablesim {

bool JointRelease::Wanted(const Scene& scene) {
  return std::any_of(scene.joints.begin(), scene.joints.end(),
                     [](const JointSpec& j) { return j.HasRelease(); });
}

absl::Status JointRelease::Start(MultibodyModel* model) {
  if (!started_) {
    started_ = true;
    z0_ = model->initial_z();
    v0_ = model->initial_v();
    return absl::OkStatus();
  }
  if (!rebuilt_) return absl::OkStatus();
  for (JointSpec& joint : scene_.joints) joint.released = false;
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene_);
  if (!built.ok()) return built.status();
  StopPoll* poll = model->stop_poll();
  *model = std::move(*built);
  model->set_stop_poll(poll);
  model->SetInitialState(z0_, v0_, 0, 0);
  rebuilt_ = false;
  return absl::OkStatus();
}

double JointRelease::NextTime() const {
  double next = std::numeric_limits<double>::infinity();
  for (const JointSpec& joint : scene_.joints)
    if (!joint.released && joint.release_time_s >= 0)
      next = std::min(next, joint.release_time_s);
  return next;
}

void JointRelease::JointForces(const MultibodyModel& model, const Eigen::VectorXd& z,
                               const Eigen::VectorXd& lambda) {
  const size_t n = scene_.joints.size();
  forces_.assign(n, Eigen::Vector3d::Zero());
  moments_.assign(n, Eigen::Vector3d::Zero());
  q_.resize(model.coordinates());
  model.ToFull(z, &q_);
  for (const ConstraintFamily* f : model.constraint_families())
    f->AddReactions(q_, lambda, &forces_, &moments_);
}

absl::StatusOr<bool> JointRelease::LetGo(MultibodyModel* model, double t, double time_tolerance,
                                         const Eigen::VectorXd& z, const Eigen::VectorXd& v,
                                         const Eigen::VectorXd& lambda,
                                         std::vector<JointReleaseEvent>* events) {
  bool any = false;
  bool forces_known = false;
  for (size_t j = 0; j < scene_.joints.size(); ++j) {
    JointSpec& joint = scene_.joints[j];
    if (joint.released || !joint.HasRelease()) continue;
    const bool by_time = joint.release_time_s >= 0 && t >= joint.release_time_s - time_tolerance;
    if (!by_time && !(joint.breaking_load_n > 0)) continue;
    if (!forces_known) {
      JointForces(*model, z, lambda);
      forces_known = true;
    }
    const double force = forces_[j].norm();
    const bool by_load = joint.breaking_load_n > 0 && force > joint.breaking_load_n;
    if (!by_time && !by_load) continue;
    joint.released = true;
    any = true;
    events->push_back(JointReleaseEvent{static_cast<int>(j), joint.name, t, force,
                                        by_load ? "breaking_load" : "time"});
  }
  if (!any) return false;
  // The state in full coordinates, which both models share.
  q_.resize(model->coordinates());
  qdot_.resize(model->coordinates());
  model->ToFull(z, &q_);
  model->RateToFull(v, &qdot_);
  const double work = model->external_work();
  StopPoll* poll = model->stop_poll();
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene_);
  if (!built.ok()) {
    return absl::InternalError(absl::StrFormat(
        "joints[%d] let go at t = %.9g s, but the model without it could not be built: %s",
        events->back().joint, t, built.status().message()));
  }
  // The viscoelastic lines' state goes on in the new model (the mesh is
  // the same: a released joint only drops its rows), or restarts at rest
  // if it cannot.
  MultibodyModel old = std::move(*model);
  *model = std::move(*built);
  model->set_stop_poll(poll);
  model->SetTime(t);
  model->SetInitialState(model->Reduce(q_), model->Reduce(qdot_), work, t);
  if (old.has_viscoelastic() && !model->AdoptViscoelastic(old))
    model->StartViscoelastic(model->initial_z(), t);
  rebuilt_ = true;
  return true;
}

}  // namespace cablesim
