#include "engine/run/coupling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/model/multibody_model.h"
#include "engine/output/results.h"
#include "engine/run/static_run.h"
#include "engine/steppers/make_stepper.h"
#include "engine/steppers/stepper.h"

namespace cablesim {
namespace {

// The probe names the session adds at its coupled points (a name no scene
// can give: scene probe names are letters, digits, '_', '-' and '.').
std::string CouplingProbeName(int joint) { return absl::StrCat("coupled point#", joint); }

// Linear from a at t0 to b at t1, continued with the same slope past t1
// so that the rate at t1 (a step's end) is the step's; constant a when
// t1 <= t0.
TimeFunction Segment(double t0, double t1, double a, double b) {
  if (t1 <= t0) return TimeFunction::Constant(a);
  return TimeFunction::Table({t0, t1, 2 * t1 - t0}, {a, b, 2 * b - a});
}

// The rotation taking orientation q0 to q1 the shortest way, as an axis
// (unit; z when there is none) and an angle in [0, pi].
std::pair<Eigen::Vector3d, double> StepRotation(const Eigen::Quaterniond& q0,
                                                const Eigen::Quaterniond& q1) {
  Eigen::Quaterniond d = q1 * q0.conjugate();
  if (d.w() < 0) d.coeffs() *= -1;
  const double s = d.vec().norm();
  if (s < 1e-300) return {Eigen::Vector3d::UnitZ(), 0.0};
  return {d.vec() / s, 2 * std::atan2(s, d.w())};
}

}  // namespace

struct CouplingSession::State {
  Scene scene;
  MultibodyModel model;
  ModelInfo info;
  std::vector<int> probe;  // per coupled point: its position probe
  std::vector<int> first_node;  // per cable: its first node in info.node_s
};

CouplingSession::CouplingSession() = default;
CouplingSession::~CouplingSession() = default;

absl::StatusOr<std::unique_ptr<CouplingSession>> CouplingSession::Open(const Scene& input) {
  if (input.solver.analysis != Analysis::kDynamic) {
    return absl::InvalidArgumentError(
        "solver.analysis: a coupling session runs a DYNAMIC scene");
  }
  Scene scene = input;
  AddCoupledBodyDrivers(&scene);  // (a scene not read through convert/)
  std::vector<int> joints;
  std::vector<Body> bodies;
  const int scene_joints = static_cast<int>(scene.joints.size());
  for (int j = 0; j < scene_joints; ++j) {
    const JointSpec& joint = scene.joints[j];
    if (!joint.coupled) continue;
    scene.probes.push_back(ProbeSpec{CouplingProbeName(j), joint.a});
    if (!joint.coupled_rotation) {
      joints.push_back(j);
      continue;
    }
    Body b;
    b.body = joint.a.body;
    b.joint = j;
    // The joints that hold cables or other bodies to it, each with a probe
    // at its point on this body.
    for (int k = 0; k < scene_joints; ++k) {
      const JointSpec& other = scene.joints[k];
      if (k == j || other.type == JointType::kSlide) continue;
      const Attachment* at = other.a.body == b.body ? &other.a
                             : other.b.body == b.body ? &other.b
                                                      : nullptr;
      if (at == nullptr) continue;
      b.joints.push_back(k);
      b.probes.push_back(static_cast<int>(scene.probes.size()));
      scene.probes.push_back(
          ProbeSpec{absl::StrCat("coupled body#", b.body, " joint#", k), *at});
    }
    bodies.push_back(std::move(b));
  }
  if (joints.empty() && bodies.empty()) {
    return absl::InvalidArgumentError(
        "joints: no coupled support (a joint to ground with coupled: true) and no coupled "
        "body (bodies[i].coupled: true)");
  }
  // A coupled body's force is the sum of its joints' reactions.
  if (!bodies.empty()) scene.output.reactions = true;
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene);
  if (!built.ok()) return built.status();
  std::unique_ptr<CouplingSession> session(new CouplingSession());
  session->s_ = std::make_unique<State>(State{std::move(scene), std::move(*built), {}, {}, {}});
  State& s = *session->s_;
  s.info = s.model.Info();
  session->joints_ = joints;
  const int n = static_cast<int>(joints.size());
  const auto& names = s.info.probe_names;
  for (int i = 0; i < n; ++i) {
    const std::string name = CouplingProbeName(joints[i]);
    const auto& forces = s.info.force_probe_names;
    s.probe.push_back(static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin()));
    const auto f = std::find(forces.begin(), forces.end(), name);
    if (f == forces.end()) {
      return absl::InternalError(absl::StrCat("joints[", joints[i], "]: no force probe"));
    }
    session->force_probe_.push_back(static_cast<int>(f - forces.begin()));
  }
  int node = 0;
  for (int c : s.info.cable_nodes) {
    s.first_node.push_back(node);
    node += c;
  }
  // Where the scene places the coupled points and bodies.
  Eigen::VectorXd q(s.model.coordinates()), zero = Eigen::VectorXd::Zero(s.model.coordinates());
  s.model.ToFull(s.model.initial_z(), &q);
  std::vector<ProbeSample> probes;
  s.model.Probes(q, zero, zero, &probes);
  for (int i = 0; i < n; ++i) session->p0_.push_back(probes[s.probe[i]].position_m);
  const PrescribedMotion* motion = s.model.prescribed_motion();
  for (Body& b : bodies) {
    const std::string name = CouplingProbeName(b.joint);
    b.centre_probe = static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
    b.p0 = probes[b.centre_probe].position_m;
    const Eigen::Matrix3d r = s.model.BodyRotation(q, b.body);
    b.q0 = Eigen::Quaterniond(r).normalized();
    for (int p : b.probes) b.reach = std::max(b.reach, (probes[p].position_m - b.p0).norm());
    for (int k = 0; motion != nullptr && k < static_cast<int>(motion->turning().size()); ++k) {
      const PrescribedMotion::TurningRow& row = motion->turning()[k];
      if (row.joint != b.joint) continue;
      b.rows.push_back(k);
      b.normal_body.push_back(r.transpose() * row.n0);
    }
    if (b.rows.empty()) {
      return absl::InternalError(
          absl::StrCat("bodies[", b.body, "].coupled: its driver has no turning rows"));
    }
    CoupledBodyKinematics pose;
    pose.position = b.p0;
    pose.orientation = b.q0;
    session->pose_.push_back(pose);
  }
  session->bodies_ = std::move(bodies);
  const int nb = session->coupled_bodies();
  session->body_force_.assign(nb, Eigen::Vector3d::Zero());
  session->body_moment_ = session->mean_body_force_ = session->mean_body_moment_ =
      session->body_force_;
  session->x_ = session->p0_;
  session->forces_.assign(n, Eigen::Vector3d::Zero());
  session->mean_forces_ = session->forces_;
  double jump = std::numeric_limits<double>::infinity();
  for (const CableSpec& c : s.scene.cables)
    jump = std::min(jump, c.length_m / std::max(1, c.elements));
  session->max_jump_m_ = jump;
  return session;
}

absl::Status CouplingSession::CheckBodies(const std::vector<CoupledBodyKinematics>& bodies) const {
  const int n = coupled_bodies();
  if (static_cast<int>(bodies.size()) != n) {
    return absl::InvalidArgumentError(
        absl::StrFormat("bodies: %d coupled bodies given, the scene has %d",
                        static_cast<int>(bodies.size()), n));
  }
  const bool planar = s_->model.dimension() == 2;
  for (int i = 0; i < n; ++i) {
    const CoupledBodyKinematics& b = bodies[i];
    const std::pair<const char*, const Eigen::Vector3d*> vectors[] = {
        {"position", &b.position}, {"velocity", &b.velocity},
        {"angular_velocity", &b.angular_velocity}};
    for (const auto& [name, v] : vectors) {
      for (int d = 0; d < 3; ++d) {
        if (!std::isfinite((*v)(d))) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "bodies[%d].%s.%c: must be finite (got %g)", i, name, "xyz"[d], (*v)(d)));
        }
      }
    }
    const Eigen::Vector4d q(b.orientation.w(), b.orientation.x(), b.orientation.y(),
                            b.orientation.z());
    for (int d = 0; d < 4; ++d) {
      if (!std::isfinite(q(d))) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d].orientation.%c: must be finite (got %g)", i, "wxyz"[d], q(d)));
      }
    }
    if (std::abs(q.norm() - 1) > 1e-6) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "bodies[%d].orientation: must be a unit quaternion (|q| = %.9g; normalise it)", i,
          q.norm()));
    }
    if (planar) {
      const Eigen::Vector3d p0 = bodies_[i].p0;
      if (std::abs(b.position.z() - p0.z()) > 1e-9) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d].position.z: the scene is planar: the body stays at z = %g", i, p0.z()));
      }
      if (std::abs(b.orientation.x()) > 1e-9 || std::abs(b.orientation.y()) > 1e-9) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d].orientation: the scene is planar: the body turns about z only", i));
      }
    }
  }
  return absl::OkStatus();
}

absl::Status CouplingSession::CheckPoints(const std::vector<Eigen::Vector3d>& x,
                                          const std::vector<Eigen::Vector3d>& v) const {
  const size_t n = joints_.size();
  if (x.size() != n) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "x: %d coupled points given, the scene has %d", static_cast<int>(x.size()),
        static_cast<int>(n)));
  }
  if (v.size() != n) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "xd: %d coupled velocities given, the scene has %d coupled points",
        static_cast<int>(v.size()), static_cast<int>(n)));
  }
  for (size_t i = 0; i < n; ++i) {
    for (int d = 0; d < 3; ++d) {
      if (!std::isfinite(x[i](d))) {
        return absl::InvalidArgumentError(
            absl::StrFormat("x[%d].%c: must be finite (got %g)", static_cast<int>(i), "xyz"[d],
                            x[i](d)));
      }
      if (!std::isfinite(v[i](d))) {
        return absl::InvalidArgumentError(
            absl::StrFormat("xd[%d].%c: must be finite (got %g)", static_cast<int>(i), "xyz"[d],
                            v[i](d)));
      }
    }
    if (s_->model.dimension() == 2 && std::abs(x[i](2) - p0_[i](2)) > 1e-9) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "x[%d].z: the scene is planar: the point stays at z = %g", static_cast<int>(i),
          p0_[i](2)));
    }
  }
  return absl::OkStatus();
}

void CouplingSession::SetMotion(double t0, double t1, const std::vector<Eigen::Vector3d>& d0,
                                const std::vector<Eigen::Vector3d>& d1) {
  PrescribedMotion* motion = s_->model.prescribed_motion();
  const auto& rows = motion->moving();
  for (int r = 0; r < static_cast<int>(rows.size()); ++r) {
    const auto it = std::find(joints_.begin(), joints_.end(), rows[r].joint);
    if (it == joints_.end()) continue;  // a prescribed support, or a body's driver
    const int i = static_cast<int>(it - joints_.begin());
    const int axis = rows[r].axis;
    motion->SetMotion(r, Segment(t0, t1, d0[i](axis), d1[i](axis)));
  }
}

void CouplingSession::SetBodyMotion(double t0, double t1,
                                    const std::vector<CoupledBodyKinematics>& from,
                                    const std::vector<CoupledBodyKinematics>& to) {
  PrescribedMotion* motion = s_->model.prescribed_motion();
  const auto& rows = motion->moving();
  for (int i = 0; i < coupled_bodies(); ++i) {
    const Body& b = bodies_[i];
    const Eigen::Vector3d d0 = from[i].position - b.p0;
    const Eigen::Vector3d d1 = t1 > t0 ? Eigen::Vector3d(to[i].position - b.p0) : d0;
    for (int r = 0; r < static_cast<int>(rows.size()); ++r) {
      if (rows[r].joint != b.joint) continue;
      motion->SetMotion(r, Segment(t0, t1, d0(rows[r].axis), d1(rows[r].axis)));
    }
    // The axes turn about a fixed axis at a constant rate (slerp) from
    // R(q0): each normal n(t) = Rot(axis, angle(t)) R(q0) m, m its body
    // vector. At Initialize (t1 <= t0) they turn at the host's angular
    // velocity, so that the rate at t0 is the host's.
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
    TimeFunction angle = TimeFunction::Constant(0);
    if (t1 > t0) {
      const auto [u, theta] = StepRotation(from[i].orientation, to[i].orientation);
      axis = u;
      angle = Segment(t0, t1, 0, theta);
    } else if (const double w = from[i].angular_velocity.norm(); w > 0) {
      axis = from[i].angular_velocity / w;
      angle = Segment(t0, t0 + 1, 0, w);
    }
    const Eigen::Matrix3d r0 = from[i].orientation.normalized().toRotationMatrix();
    for (size_t k = 0; k < b.rows.size(); ++k)
      motion->SetTurning(b.rows[k], r0 * b.normal_body[k], axis, angle);
  }
}

void CouplingSession::UpdateForces() {
  Eigen::VectorXd q(s_->model.coordinates());
  s_->model.ToFull(stepper_->z(), &q);
  std::vector<Eigen::Vector3d> support;
  s_->model.ProbeForces(q, stepper_->lambda(), &support);
  // The support's force on the point is minus the point's force on it.
  for (size_t i = 0; i < joints_.size(); ++i) forces_[i] = -support[force_probe_[i]];
  if (bodies_.empty()) return;
  // A body's joints: the reaction on side a (and for FIXED its moment
  // about the joint's point), minus it when the body is side b.
  std::vector<JointReaction> reactions;
  s_->model.Reactions(q, &stepper_->lambda(), &reactions);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(q.size());
  std::vector<ProbeSample> probes;
  s_->model.Probes(q, zero, zero, &probes);
  for (int i = 0; i < coupled_bodies(); ++i) {
    const Body& b = bodies_[i];
    const Eigen::Vector3d centre = probes[b.centre_probe].position_m;
    Eigen::Vector3d f = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < b.joints.size(); ++k) {
      const JointSpec& joint = s_->scene.joints[b.joints[k]];
      const double sign = joint.a.body == b.body ? 1.0 : -1.0;
      const Eigen::Vector3d fk = sign * reactions[b.joints[k]].force;
      f += fk;
      m += sign * reactions[b.joints[k]].moment +
           (probes[b.probes[k]].position_m - centre).cross(fk);
    }
    body_force_[i] = f;
    body_moment_[i] = m;
  }
}

double CouplingSession::DampingPower() const {
  if (!s_->model.has_dissipated_power() || stepper_ == nullptr) return 0;
  Eigen::VectorXd q(s_->model.coordinates()), qd(s_->model.coordinates());
  s_->model.ToFull(stepper_->z(), &q);
  s_->model.RateToFull(stepper_->v(), &qd);
  return s_->model.DampingPower(q, qd);
}

double CouplingSession::energy() const {
  Eigen::VectorXd q(s_->model.coordinates()), qd(s_->model.coordinates());
  s_->model.ToFull(stepper_ ? stepper_->z() : s_->model.initial_z(), &q);
  if (stepper_) {
    s_->model.RateToFull(stepper_->v(), &qd);
  } else {
    qd.setZero();
  }
  EnergyParts parts;
  EnergySample e = s_->model.Energy(q, qd, 1.0, &parts);
  // (No external work is summed in a session: potential is gravity's and
  // the constant loads'; but the viscoelastic lines' stiffness updates
  // are, and stay: they are the lines' own.)
  double total = e.total + s_->model.external_work() - s_->model.viscoelastic_work();
  for (const Body& b : bodies_) total -= parts.bodies[b.body].kinetic + parts.bodies[b.body].gravity;
  return total;
}

absl::Status CouplingSession::Initialize(const std::vector<Eigen::Vector3d>& x,
                                         const std::vector<Eigen::Vector3d>& v,
                                         const std::vector<CoupledBodyKinematics>& bodies) {
  if (initialized()) return absl::FailedPreconditionError("the session is initialised already");
  if (absl::Status st = CheckPoints(x, v); !st.ok()) return st;
  if (absl::Status st = CheckBodies(bodies); !st.ok()) return st;
  MultibodyModel& model = s_->model;
  const SolverSettings& settings = s_->scene.solver;
  const int n = coupled_points();
  std::vector<Eigen::Vector3d> d(n);
  for (int i = 0; i < n; ++i) d[i] = x[i] - p0_[i];
  const bool statics = settings.initial_state == InitialState::kStatic;
  if (!statics) {
    for (int i = 0; i < n; ++i) {
      if (d[i].norm() > 1e-9 * std::max(1.0, p0_[i].norm())) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "x[%d]: %.6g m from the scene's point (%g, %g, %g); without statics "
            "(solver.initial_state STATIC) the host starts at the scene's points",
            i, d[i].norm(), p0_[i](0), p0_[i](1), p0_[i](2)));
      }
    }
    for (int i = 0; i < coupled_bodies(); ++i) {
      const Body& b = bodies_[i];
      const double turn = StepRotation(b.q0, bodies[i].orientation).second;
      if ((bodies[i].position - b.p0).norm() > 1e-9 * std::max(1.0, b.p0.norm()) || turn > 1e-9) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d]: %.6g m and %.6g rad from the scene's pose; without statics "
            "(solver.initial_state STATIC) the host starts at the scene's poses",
            i, (bodies[i].position - b.p0).norm(), turn));
      }
    }
  }
  // At t = 0 the points move with the host's velocities (the rate of the
  // supports' rows there), so the lines' initial velocity is projected
  // onto them, as for a prescribed motion that starts moving (the velocity
  // right after an inelastic impulse at the supports).
  std::vector<Eigen::Vector3d> d1(n);
  for (int i = 0; i < n; ++i) d1[i] = d[i] + v[i];
  SetMotion(0, 1, d, d1);
  std::vector<CoupledBodyKinematics> moving = bodies;
  for (CoupledBodyKinematics& b : moving) b.position += b.velocity;
  SetBodyMotion(0, 0, bodies, moving);
  // (The centre's velocity: its rows' rate, as the points'.)
  {
    PrescribedMotion* motion = model.prescribed_motion();
    for (int i = 0; i < coupled_bodies(); ++i) {
      for (int r = 0; r < static_cast<int>(motion->moving().size()); ++r) {
        const auto& row = motion->moving()[r];
        if (row.joint != bodies_[i].joint) continue;
        const double a = bodies[i].position(row.axis) - bodies_[i].p0(row.axis);
        motion->SetMotion(r, Segment(0, 1, a, a + bodies[i].velocity(row.axis)));
      }
    }
  }
  model.SetTime(0);
  model.RelaxViscoelastic();  // (statics take the static EA, also on a retry)
  if (!statics) model.SetInitialState(model.initial_z());
  if (statics) {
    RunSummary summary;
    if (!StartFromEquilibrium(&model, settings, RunControl{}, &summary)) {
      failure_ = summary.error;
      return absl::FailedPreconditionError(
          absl::StrCat("no static equilibrium with the host's initial positions: ", summary.error));
    }
  }
  // Viscoelastic lines start with their dashpots at rest; each accepted
  // step is committed in Step.
  model.StartViscoelastic(model.initial_z(), 0);
  std::unique_ptr<Stepper> stepper = MakeStepper(&model, settings);
  std::string reason;
  if (!stepper->Initialize(&reason)) {
    failure_ = reason;
    return absl::FailedPreconditionError(absl::StrCat("the initial state: ", reason));
  }
  stepper_ = std::move(stepper);
  t_ = 0;
  x_ = x;
  pose_ = bodies;
  UpdateForces();
  mean_forces_ = forces_;
  mean_body_force_ = body_force_;
  mean_body_moment_ = body_moment_;
  host_work_ = dissipated_ = 0;
  return absl::OkStatus();
}

absl::Status CouplingSession::Step(double t_end, const std::vector<Eigen::Vector3d>& x,
                                   const std::vector<Eigen::Vector3d>& v,
                                   const std::vector<CoupledBodyKinematics>& bodies) {
  if (!initialized()) {
    return absl::FailedPreconditionError(
        failed() ? absl::StrCat("the session failed: ", failure_)
                 : std::string("initialise the session first"));
  }
  if (failed()) {
    return absl::FailedPreconditionError(
        absl::StrFormat("the session failed at t = %.9g s: %s", t_, failure_));
  }
  if (!std::isfinite(t_end)) {
    return absl::InvalidArgumentError(absl::StrFormat("t: must be finite (got %g)", t_end));
  }
  if (!(t_end > t_)) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "t: must be after the session's time %.9g s (got %.9g s): time does not go backwards",
        t_, t_end));
  }
  if (absl::Status st = CheckPoints(x, v); !st.ok()) return st;
  if (absl::Status st = CheckBodies(bodies); !st.ok()) return st;
  const int n = coupled_points(), nb = coupled_bodies();
  std::vector<std::pair<Eigen::Vector3d, double>> turns(nb);
  for (int i = 0; i < nb; ++i) {
    turns[i] = StepRotation(pose_[i].orientation, bodies[i].orientation);
    // Its joint points move at most this far (the centre's move plus the
    // arc of the farthest point).
    const double jump =
        (bodies[i].position - pose_[i].position).norm() + turns[i].second * bodies_[i].reach;
    if (jump > max_jump_m_) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "bodies[%d]: its joint points move up to %.6g m in one coupling step, more than the "
          "%.6g m allowed (the shortest cable element): use a shorter coupling step",
          i, jump, max_jump_m_));
    }
  }
  for (int i = 0; i < n; ++i) {
    const double jump = (x[i] - x_[i]).norm();
    if (jump > max_jump_m_) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "x[%d]: moves %.6g m in one coupling step, more than the %.6g m allowed (the "
          "shortest cable element): use a shorter coupling step",
          i, jump, max_jump_m_));
    }
  }
  const SolverSettings& settings = s_->scene.solver;
  std::vector<Eigen::Vector3d> d0(n), d1(n);
  for (int i = 0; i < n; ++i) {
    d0[i] = x_[i] - p0_[i];
    d1[i] = x[i] - p0_[i];
  }
  const double t0 = t_, dt = t_end - t0;
  SetMotion(t0, t_end, d0, d1);
  SetBodyMotion(t0, t_end, pose_, bodies);
  // Sub-steps: as many scene steps as fill the coupling step, equal.
  const long count = std::max(1L, std::lround(std::ceil(dt / settings.step_s - 1e-9)));
  const double h_nominal = dt / static_cast<double>(count);
  const double h_min = std::ldexp(h_nominal, -settings.max_step_halvings);
  double t = t0, h = h_nominal;
  std::vector<Eigen::Vector3d> impulse(n, Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> body_impulse(nb, Eigen::Vector3d::Zero()),
      angular_impulse(nb, Eigen::Vector3d::Zero());
  double power = DampingPower(), dissipated = 0;
  while (t_end - t > 1e-12 * std::max(1.0, std::abs(t_end))) {
    const double h_try = std::min(h, t_end - t);
    const Stepper::StepStats st = stepper_->Step(h_try);
    if (st.converged) {
      t += h_try;
      ++steps_;
      UpdateForces();
      for (int i = 0; i < n; ++i) impulse[i] += h_try * forces_[i];
      for (int i = 0; i < nb; ++i) {
        body_impulse[i] += h_try * body_force_[i];
        angular_impulse[i] += h_try * body_moment_[i];
      }
      const double p = DampingPower();
      dissipated += 0.5 * h_try * (power + p);
      power = p;
      s_->model.CommitViscoelastic(stepper_->z(), t);
      continue;
    }
    // A step that did not converge leaves the stepper where it was (as in
    // RunDynamic): halve it.
    ++rejected_;
    h = h_try / 2;
    if (h < h_min * (1 - 1e-12)) {
      t_ = t;
      dissipated_ += dissipated;
      failure_ = absl::StrFormat("the step from t = %.9g s failed %d times down to h = %.3g s: %s",
                                 t, settings.max_step_halvings + 1, h_try, st.reason);
      return absl::InternalError(failure_);
    }
  }
  t_ = t_end;
  for (int i = 0; i < n; ++i) {
    mean_forces_[i] = impulse[i] / (t - t0);
    host_work_ -= mean_forces_[i].dot(x[i] - x_[i]);
  }
  for (int i = 0; i < nb; ++i) {
    mean_body_force_[i] = body_impulse[i] / (t - t0);
    mean_body_moment_[i] = angular_impulse[i] / (t - t0);
    host_work_ -= mean_body_force_[i].dot(bodies[i].position - pose_[i].position) +
                  mean_body_moment_[i].dot(turns[i].second * turns[i].first);
  }
  dissipated_ += dissipated;
  x_ = x;
  pose_ = bodies;
  return absl::OkStatus();
}

int CouplingSession::cables() const { return static_cast<int>(s_->info.cable_names.size()); }
const std::string& CouplingSession::cable_name(int c) const { return s_->info.cable_names[c]; }
int CouplingSession::cable_nodes(int c) const { return s_->info.cable_nodes[c]; }

std::vector<Eigen::Vector3d> CouplingSession::NodePositions(int c) const {
  Eigen::VectorXd q(s_->model.coordinates());
  const Eigen::VectorXd& z = stepper_ ? stepper_->z() : s_->model.initial_z();
  s_->model.ToFull(z, &q);
  std::vector<Eigen::Vector3d> all;
  s_->model.NodePositions(q, &all);
  const auto begin = all.begin() + s_->first_node[c];
  return std::vector<Eigen::Vector3d>(begin, begin + s_->info.cable_nodes[c]);
}

std::vector<double> CouplingSession::NodeTensions(int c) const {
  Eigen::VectorXd q(s_->model.coordinates());
  s_->model.ToFull(stepper_ ? stepper_->z() : s_->model.initial_z(), &q);
  // The model's own tension (its axial law, its section force at the
  // nodes, with the material damping once the session steps:
  // MultibodyModel::Tensions), one per node of the cable.
  Eigen::VectorXd qdot;
  if (stepper_) {
    qdot.resize(s_->model.coordinates());
    s_->model.RateToFull(stepper_->v(), &qdot);
  }
  std::vector<double> tension =
      s_->model.CableNodeTensions(q, c, 1.0, stepper_ ? &qdot : nullptr);
  tension.resize(s_->info.cable_nodes[c]);
  return tension;
}

}  // namespace cablesim
