#ifndef CABLESIM_ENGINE_RUN_COUPLING_H_
#define CABLESIM_ENGINE_RUN_COUPLING_H_

// A coupling session: a host program (a vessel or platform simulator, a
// wind-turbine code) drives a scene's coupled supports (JointSpec::coupled)
// step by step and gets back the forces the cables and bodies exert on
// them. The protocol is that of an explicit co-simulation:
//
//   Open(scene)                 the model, built and checked
//   Initialize(x0, v0)          the coupled points where the host has them
//                               at t = 0; the scene's static equilibrium
//                               there when solver.initial_state is STATIC
//                               (else x0 must be the scene's points); the
//                               initial velocity is projected onto the
//                               points' velocities v0 (as for a prescribed
//                               motion that starts moving)
//   Step(t1, x1, v1)            advances from the session's time t0 to t1
//                               with the scene's own steps (solver.step,
//                               the last shortened so that the sub-steps
//                               fill [t0, t1] evenly), the coupled points
//                               moving linearly from x0 to x1: their
//                               velocity inside the step is (x1 - x0) /
//                               (t1 - t0), consistent with the positions;
//                               v1 is checked (finite) but the motion is
//                               the positions' (a host's velocity that
//                               disagrees would break the constraint)
//   forces()                    at the session's time: the force [N] the
//                               scene exerts on each coupled point (minus
//                               the support's reaction, from the Lagrange
//                               multipliers of its rows), world axes
//
// A sub-step that fails is halved (down to solver.max_step_halvings); when
// it still fails, Step returns an error and the session is failed: every
// later Step says so (nothing goes silently past a failed step). Bad input
// (wrong count, a non-finite value, a time that does not advance, a jump
// larger than max_jump_m) returns InvalidArgument naming the argument and
// leaves the session as it was.
//
// Coupled bodies (BodySpec::coupled, 6 degrees of freedom) are driven the
// same way: the host gives each one's pose (its centre of mass, and its
// orientation as a unit quaternion whose rotation's columns are the body's
// axes in the world: absolute, the scene's pose is body_scene_orientation)
// and velocity and angular velocity; inside a coupling step the centre
// moves linearly and the orientation turns about the fixed axis of
// q1 q0^-1 at a constant rate (slerp: the shortest way, a constant
// angular velocity in world axes). The session returns the force and the
// moment (about the centre, world axes) that the cables and bodies joined
// to it exert on it, at the step's end and as the step's mean (impulse
// over the step), as for the points.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/scene/scene.h"

namespace cablesim {

// A coupled body's kinematics as the host gives them.
struct CoupledBodyKinematics {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // centre of mass [m]
  // (w, x, y, z) unit; R(q)'s columns are the body's axes in the world.
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();          // [m/s]
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world axes [rad/s]
};

class CouplingSession {
 public:
  ~CouplingSession();
  CouplingSession(const CouplingSession&) = delete;
  CouplingSession& operator=(const CouplingSession&) = delete;

  // Builds the model of `scene` (DYNAMIC only, with at least one coupled
  // support or body). InvalidArgument naming the field otherwise.
  static absl::StatusOr<std::unique_ptr<CouplingSession>> Open(const Scene& scene);

  // The coupled supports, in scene order of their joints.
  int coupled_points() const { return static_cast<int>(joints_.size()); }
  int coupled_joint(int i) const { return joints_[i]; }
  // Where the scene places coupled point i [m].
  const Eigen::Vector3d& scene_position(int i) const { return p0_[i]; }

  // The coupled bodies, in scene order: their body index, their driver
  // joint, and their pose in the scene.
  int coupled_bodies() const { return static_cast<int>(bodies_.size()); }
  int coupled_body(int i) const { return bodies_[i].body; }
  int coupled_body_joint(int i) const { return bodies_[i].joint; }
  const Eigen::Vector3d& body_scene_position(int i) const { return bodies_[i].p0; }
  const Eigen::Quaterniond& body_scene_orientation(int i) const { return bodies_[i].q0; }

  // `bodies`: one per coupled body (none when the scene has none).
  absl::Status Initialize(const std::vector<Eigen::Vector3d>& x,
                          const std::vector<Eigen::Vector3d>& v,
                          const std::vector<CoupledBodyKinematics>& bodies = {});
  absl::Status Step(double t_end, const std::vector<Eigen::Vector3d>& x,
                    const std::vector<Eigen::Vector3d>& v,
                    const std::vector<CoupledBodyKinematics>& bodies = {});

  bool initialized() const { return stepper_ != nullptr; }
  bool failed() const { return !failure_.empty(); }
  double time() const { return t_; }
  // Forces on the coupled points at time() [N] (zero before Initialize).
  const std::vector<Eigen::Vector3d>& forces() const { return forces_; }
  // The forces' mean over the last coupling step [N]: their impulse over
  // the step (the sub-steps' end forces, each times its sub-step) divided
  // by the step. It carries the impulse that starts each coupling step,
  // when the points' velocity changes and the lines' mass next to them
  // takes it in the first sub-step, which the end forces miss: a host
  // that integrates the impulse exchanges momentum exactly.
  const std::vector<Eigen::Vector3d>& mean_forces() const { return mean_forces_; }
  // Per coupled body: the force [N] and the moment [N m] (about its
  // centre, world axes) the cables and bodies joined to it exert on it, at
  // time() and as the mean over the last coupling step (as mean_forces).
  const std::vector<Eigen::Vector3d>& body_forces() const { return body_force_; }
  const std::vector<Eigen::Vector3d>& body_moments() const { return body_moment_; }
  const std::vector<Eigen::Vector3d>& mean_body_forces() const { return mean_body_force_; }
  const std::vector<Eigen::Vector3d>& mean_body_moments() const { return mean_body_moment_; }
  // The work the host has done on the scene since Initialize [J]: per
  // coupling step, minus the mean forces returned times the points'
  // displacements, and minus the mean moments times the bodies' rotation
  // vectors (exact for the motion inside the step, whose velocity and
  // angular velocity are constant, given those means).
  double host_work() const { return host_work_; }
  // The scene's mechanical energy now [J] (kinetic, gravity, strain,
  // seabed: MultibodyModel::Energy without the external work), without the
  // coupled bodies' kinetic and gravity energy (the host's), and the work
  // done against damping since Initialize [J] (the trapezoidal rule on the
  // damping power over the sub-steps). For the balance
  //   host_work() = energy() - energy at Initialize + dissipated()
  // up to the integrator's own dissipation and the quadrature of the
  // means (docs/coupling.md, "Energy at the fairleads").
  double energy() const;
  double dissipated() const { return dissipated_; }
  // The largest jump of a coupled point in one coupling step [m]: the
  // shortest cable element it holds (a longer jump is an input error; the
  // host's step is too long for the lines). Settable.
  double max_jump_m() const { return max_jump_m_; }
  void set_max_jump_m(double m) { max_jump_m_ = m; }
  // Internal steps taken and rejected so far, and the Newton iterations.
  long steps() const { return steps_; }
  long rejected_steps() const { return rejected_; }

  // The cables: count, names, and per cable the nodes' positions [m] and
  // axial forces [N], EA (|r'| - 1) from the slope r' there (negative in
  // compression).
  int cables() const;
  const std::string& cable_name(int c) const;
  int cable_nodes(int c) const;
  std::vector<Eigen::Vector3d> NodePositions(int c) const;
  std::vector<double> NodeTensions(int c) const;

 private:
  struct State;
  CouplingSession();
  absl::Status CheckPoints(const std::vector<Eigen::Vector3d>& x,
                           const std::vector<Eigen::Vector3d>& v) const;
  absl::Status CheckBodies(const std::vector<CoupledBodyKinematics>& bodies) const;
  void SetMotion(double t0, double t1, const std::vector<Eigen::Vector3d>& d0,
                 const std::vector<Eigen::Vector3d>& d1);
  // The bodies' laws from poses `from` at t0 to `to` at t1 (t1 <= t0: held
  // at `from` turning at its angular velocity, for Initialize).
  void SetBodyMotion(double t0, double t1, const std::vector<CoupledBodyKinematics>& from,
                     const std::vector<CoupledBodyKinematics>& to);
  void UpdateForces();
  double DampingPower() const;

  struct Body {
    int body = 0, joint = 0;
    Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
    Eigen::Quaterniond q0 = Eigen::Quaterniond::Identity();
    double reach = 0;  // the farthest joint point from the centre [m]
    // Its driver's turning rows (indices into PrescribedMotion::turning)
    // and their normals in body axes.
    std::vector<int> rows;
    std::vector<Eigen::Vector3d> normal_body;
    // The joints that join it to cables or bodies, and their probes (the
    // joint's point on this body).
    std::vector<int> joints, probes;
    int centre_probe = 0;  // its driver's probe
  };
  std::vector<Body> bodies_;
  std::vector<CoupledBodyKinematics> pose_;  // the bodies' last poses
  std::vector<Eigen::Vector3d> body_force_, body_moment_, mean_body_force_, mean_body_moment_;
  double host_work_ = 0, dissipated_ = 0;

  std::unique_ptr<State> s_;
  std::unique_ptr<class Stepper> stepper_;
  std::vector<int> joints_;
  std::vector<Eigen::Vector3d> p0_, x_, forces_, mean_forces_;
  std::vector<int> force_probe_;  // per coupled point: its force probe
  double t_ = 0;
  double max_jump_m_ = 0;
  long steps_ = 0, rejected_ = 0;
  std::string failure_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_COUPLING_H_
