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
  std::vector<int> joints;
  for (int j = 0; j < static_cast<int>(scene.joints.size()); ++j) {
    if (!scene.joints[j].coupled) continue;
    joints.push_back(j);
    scene.probes.push_back(ProbeSpec{CouplingProbeName(j), scene.joints[j].a});
  }
  if (joints.empty()) {
    return absl::InvalidArgumentError(
        "joints: no coupled support (a joint to ground with coupled: true)");
  }
  absl::StatusOr<MultibodyModel> built = MultibodyModel::Build(scene);
  if (!built.ok()) return built.status();
  std::unique_ptr<CouplingSession> session(new CouplingSession());
  session->s_ = std::make_unique<State>(State{std::move(scene), std::move(*built), {}, {}, {}});
  State& s = *session->s_;
  s.info = s.model.Info();
  session->joints_ = joints;
  const int n = static_cast<int>(joints.size());
  for (int i = 0; i < n; ++i) {
    const std::string name = CouplingProbeName(joints[i]);
    const auto& names = s.info.probe_names;
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
  // Where the scene places the coupled points.
  Eigen::VectorXd q(s.model.coordinates()), zero = Eigen::VectorXd::Zero(s.model.coordinates());
  s.model.ToFull(s.model.initial_z(), &q);
  std::vector<ProbeSample> probes;
  s.model.Probes(q, zero, zero, &probes);
  for (int i = 0; i < n; ++i) session->p0_.push_back(probes[s.probe[i]].position_m);
  session->x_ = session->p0_;
  session->forces_.assign(n, Eigen::Vector3d::Zero());
  session->mean_forces_ = session->forces_;
  double jump = std::numeric_limits<double>::infinity();
  for (const CableSpec& c : s.scene.cables)
    jump = std::min(jump, c.length_m / std::max(1, c.elements));
  session->max_jump_m_ = jump;
  return session;
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
    if (it == joints_.end()) continue;  // a prescribed (not coupled) support
    const int i = static_cast<int>(it - joints_.begin());
    const int axis = rows[r].axis;
    if (t1 <= t0) {
      motion->SetMotion(r, TimeFunction::Constant(d0[i](axis)));
    } else {
      // Linear from d0 at t0 to d1 at t1, continued with the same slope
      // past t1 so that the rate at t1 (a step's end) is the step's.
      const double a = d0[i](axis), b = d1[i](axis);
      motion->SetMotion(r, TimeFunction::Table({t0, t1, 2 * t1 - t0}, {a, b, 2 * b - a}));
    }
  }
}

void CouplingSession::UpdateForces() {
  Eigen::VectorXd q(s_->model.coordinates());
  s_->model.ToFull(stepper_->z(), &q);
  std::vector<Eigen::Vector3d> support;
  s_->model.ProbeForces(q, stepper_->lambda(), &support);
  // The support's force on the point is minus the point's force on it.
  for (size_t i = 0; i < joints_.size(); ++i) forces_[i] = -support[force_probe_[i]];
}

absl::Status CouplingSession::Initialize(const std::vector<Eigen::Vector3d>& x,
                                         const std::vector<Eigen::Vector3d>& v) {
  if (initialized()) return absl::FailedPreconditionError("the session is initialised already");
  if (absl::Status st = CheckPoints(x, v); !st.ok()) return st;
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
  }
  // At t = 0 the points move with the host's velocities (the rate of the
  // supports' rows there), so the lines' initial velocity is projected
  // onto them, as for a prescribed motion that starts moving (the velocity
  // right after an inelastic impulse at the supports).
  std::vector<Eigen::Vector3d> d1(n);
  for (int i = 0; i < n; ++i) d1[i] = d[i] + v[i];
  SetMotion(0, 1, d, d1);
  model.SetTime(0);
  if (!statics) model.SetInitialState(model.initial_z());
  if (statics) {
    RunSummary summary;
    if (!StartFromEquilibrium(&model, settings, RunControl{}, &summary)) {
      failure_ = summary.error;
      return absl::FailedPreconditionError(
          absl::StrCat("no static equilibrium with the host's initial positions: ", summary.error));
    }
  }
  std::unique_ptr<Stepper> stepper = MakeStepper(&model, settings);
  std::string reason;
  if (!stepper->Initialize(&reason)) {
    failure_ = reason;
    return absl::FailedPreconditionError(absl::StrCat("the initial state: ", reason));
  }
  stepper_ = std::move(stepper);
  t_ = 0;
  x_ = x;
  UpdateForces();
  mean_forces_ = forces_;
  return absl::OkStatus();
}

absl::Status CouplingSession::Step(double t_end, const std::vector<Eigen::Vector3d>& x,
                                   const std::vector<Eigen::Vector3d>& v) {
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
  const int n = coupled_points();
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
  // Sub-steps: as many scene steps as fill the coupling step, equal.
  const long count = std::max(1L, std::lround(std::ceil(dt / settings.step_s - 1e-9)));
  const double h_nominal = dt / static_cast<double>(count);
  const double h_min = std::ldexp(h_nominal, -settings.max_step_halvings);
  double t = t0, h = h_nominal;
  std::vector<Eigen::Vector3d> impulse(n, Eigen::Vector3d::Zero());
  while (t_end - t > 1e-12 * std::max(1.0, std::abs(t_end))) {
    const double h_try = std::min(h, t_end - t);
    const Stepper::StepStats st = stepper_->Step(h_try);
    if (st.converged) {
      t += h_try;
      ++steps_;
      UpdateForces();
      for (int i = 0; i < n; ++i) impulse[i] += h_try * forces_[i];
      continue;
    }
    // A step that did not converge leaves the stepper where it was (as in
    // RunDynamic): halve it.
    ++rejected_;
    h = h_try / 2;
    if (h < h_min * (1 - 1e-12)) {
      t_ = t;
      failure_ = absl::StrFormat("the step from t = %.9g s failed %d times down to h = %.3g s: %s",
                                 t, settings.max_step_halvings + 1, h_try, st.reason);
      return absl::InternalError(failure_);
    }
  }
  t_ = t_end;
  x_ = x;
  for (int i = 0; i < n; ++i) mean_forces_[i] = impulse[i] / (t - t0);
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
  // nodes: MultibodyModel::Tensions), one per node of the cable.
  std::vector<double> tension = s_->model.CableNodeTensions(q, c, 1.0);
  tension.resize(s_->info.cable_nodes[c]);
  return tension;
}

}  // namespace cablesim
