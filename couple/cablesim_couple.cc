// libcablesim_couple: the C interface (cablesim_couple.h) over the engine's
// CouplingSession (engine/run/coupling.h). No gRPC: the scene file is read
// by convert/ (protobuf JSON or text format) and the rest is the engine.

#include "couple/cablesim_couple.h"

#include <cmath>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "couple/couple_internal.h"
#include "engine/run/coupling.h"

struct CableSimSystemImpl {
  std::unique_ptr<cablesim::CouplingSession> session;
  // The coupled bodies' kinematics for the next Init or Step.
  std::vector<cablesim::CoupledBodyKinematics> bodies;
};

namespace {

thread_local std::string last_error;

int Error(int code, std::string message) {
  last_error = std::move(message);
  return code;
}

int FromStatus(const absl::Status& s) {
  if (s.ok()) {
    last_error.clear();
    return CABLESIM_OK;
  }
  const std::string message(s.message());
  if (absl::IsInvalidArgument(s)) return Error(CABLESIM_INVALID_ARGUMENT, message);
  if (absl::IsFailedPrecondition(s)) return Error(CABLESIM_WRONG_STATE, message);
  return Error(CABLESIM_STEP_FAILED, message);
}

std::vector<Eigen::Vector3d> Points(const double* v, int n) {
  std::vector<Eigen::Vector3d> out(n);
  for (int i = 0; i < n; ++i) out[i] = Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  return out;
}

using Args = std::initializer_list<std::pair<const void*, const char*>>;

// The pointer arguments (named) of a call are not null.
int CheckNonNull(Args args) {
  for (const auto& [p, name] : args) {
    if (p == nullptr) return Error(CABLESIM_INVALID_ARGUMENT, absl::StrCat(name, ": null"));
  }
  return CABLESIM_OK;
}

// Checks the system and the pointer arguments of a call.
int Check(CableSimSystem sys, Args args) {
  if (sys == nullptr || sys->session == nullptr) {
    return Error(CABLESIM_INVALID_ARGUMENT, "sys: null (CableSim_Create failed?)");
  }
  return CheckNonNull(args);
}

// The coupled points' arrays may be NULL when there are none.
int CheckPointArrays(CableSimSystem sys, Args args) {
  return sys->session->coupled_points() == 0 ? CABLESIM_OK : CheckNonNull(args);
}

// `index` (the argument `name`) is below `count` (of `what`).
int CheckIndex(unsigned int index, int count, const char* name, const char* what) {
  if (index >= static_cast<unsigned int>(count)) {
    return Error(CABLESIM_INVALID_ARGUMENT, absl::StrFormat("%s: %u is not %s (the scene has %d)",
                                                            name, index, what, count));
  }
  return CABLESIM_OK;
}

int CheckBody(CableSimSystem sys, unsigned int body) {
  return CheckIndex(body, sys->session->coupled_bodies(), "body", "a coupled body");
}

int CheckFinite(const double* v, int n, const char* name) {
  for (int d = 0; d < n; ++d) {
    if (!std::isfinite(v[d])) {
      return Error(CABLESIM_INVALID_ARGUMENT,
                   absl::StrFormat("%s[%d]: must be finite (got %g)", name, d, v[d]));
    }
  }
  return CABLESIM_OK;
}

int CheckLine(CableSimSystem sys, unsigned int line) {
  return CheckIndex(line, sys->session->cables(), "line", "a line");
}

int CheckNode(unsigned int node, unsigned int line, size_t nodes) {
  if (node >= nodes) {
    return Error(CABLESIM_INVALID_ARGUMENT,
                 absl::StrFormat("node: %u is not a node of line %u (it has %d)", node, line,
                                 static_cast<int>(nodes)));
  }
  return CABLESIM_OK;
}

}  // namespace

namespace cablesim::couple {

CableSimSystem CreateFromProto(const v1::Scene& proto, const std::string& source) {
  try {
    absl::StatusOr<Scene> scene = SceneFromProto(proto);
    if (!scene.ok()) {
      Error(CABLESIM_INVALID_SCENE, absl::StrCat(source, ": ", scene.status().message()));
      return nullptr;
    }
    auto session = CouplingSession::Open(*scene);
    if (!session.ok()) {
      Error(CABLESIM_INVALID_SCENE, absl::StrCat(source, ": ", session.status().message()));
      return nullptr;
    }
    last_error.clear();
    auto* sys = new CableSimSystemImpl{std::move(*session), {}};
    for (int i = 0; i < sys->session->coupled_bodies(); ++i) {
      cablesim::CoupledBodyKinematics b;
      b.position = sys->session->body_scene_position(i);
      b.orientation = sys->session->body_scene_orientation(i);
      sys->bodies.push_back(b);
    }
    return sys;
  } catch (const std::exception& e) {
    Error(CABLESIM_INVALID_SCENE, absl::StrCat(source, ": ", e.what()));
    return nullptr;
  }
}

void SetError(const std::string& message) { last_error = message; }

}  // namespace cablesim::couple

extern "C" {

CableSimSystem CableSim_Create(const char* scene_file) {
  if (scene_file == nullptr) {
    Error(CABLESIM_INVALID_ARGUMENT, "scene_file: null");
    return nullptr;
  }
  try {
    absl::StatusOr<cablesim::v1::Scene> proto = cablesim::ReadSceneFile(scene_file);
    if (!proto.ok()) {
      Error(CABLESIM_INVALID_SCENE, std::string(proto.status().message()));
      return nullptr;
    }
    return cablesim::couple::CreateFromProto(*proto, scene_file);
  } catch (const std::exception& e) {
    Error(CABLESIM_INVALID_SCENE, absl::StrCat(scene_file, ": ", e.what()));
    return nullptr;
  }
}

int CableSim_NCoupledDOF(CableSimSystem sys, unsigned int* n) {
  if (int rc = Check(sys, {{n, "n"}}); rc != CABLESIM_OK) return rc;
  *n = 3u * static_cast<unsigned int>(sys->session->coupled_points());
  return FromStatus(absl::OkStatus());
}

int CableSim_Init(CableSimSystem sys, const double* x, const double* xd) {
  if (int rc = Check(sys, {}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckPointArrays(sys, {{x, "x"}, {xd, "xd"}}); rc != CABLESIM_OK) return rc;
  const int n = sys->session->coupled_points();
  return FromStatus(sys->session->Initialize(Points(x, n), Points(xd, n), sys->bodies));
}

int CableSim_Step(CableSimSystem sys, const double* x, const double* xd, double* f, double* t,
                  double* dt) {
  if (int rc = Check(sys, {{t, "t"}, {dt, "dt"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckPointArrays(sys, {{x, "x"}, {xd, "xd"}, {f, "f"}}); rc != CABLESIM_OK)
    return rc;
  cablesim::CouplingSession& s = *sys->session;
  if (!std::isfinite(*dt) || !(*dt > 0)) {
    return Error(CABLESIM_INVALID_ARGUMENT,
                 absl::StrFormat("dt: must be finite and > 0 (got %g)", *dt));
  }
  if (!std::isfinite(*t) || std::abs(*t - s.time()) > 1e-9 * std::max(1.0, std::abs(*t))) {
    return Error(CABLESIM_INVALID_ARGUMENT,
                 absl::StrFormat("t: must be the system's time %.9g s (got %.9g s)", s.time(),
                                 *t));
  }
  const int n = s.coupled_points();
  if (int rc = FromStatus(s.Step(*t + *dt, Points(x, n), Points(xd, n), sys->bodies));
      rc != CABLESIM_OK)
    return rc;
  *t = s.time();
  if (n == 0) return CABLESIM_OK;
  return CableSim_GetMeanForces(sys, f);
}

int CableSim_GetForces(CableSimSystem sys, double* f) {
  if (int rc = Check(sys, {{f, "f"}}); rc != CABLESIM_OK) return rc;
  const cablesim::CouplingSession& s = *sys->session;
  for (int i = 0; i < s.coupled_points(); ++i)
    for (int d = 0; d < 3; ++d) f[3 * i + d] = s.forces()[i](d);
  return FromStatus(absl::OkStatus());
}

int CableSim_GetMeanForces(CableSimSystem sys, double* f) {
  if (int rc = Check(sys, {{f, "f"}}); rc != CABLESIM_OK) return rc;
  const cablesim::CouplingSession& s = *sys->session;
  for (int i = 0; i < s.coupled_points(); ++i)
    for (int d = 0; d < 3; ++d) f[3 * i + d] = s.mean_forces()[i](d);
  return FromStatus(absl::OkStatus());
}

int CableSim_GetNumberLines(CableSimSystem sys, unsigned int* n) {
  if (int rc = Check(sys, {{n, "n"}}); rc != CABLESIM_OK) return rc;
  *n = static_cast<unsigned int>(sys->session->cables());
  return FromStatus(absl::OkStatus());
}

int CableSim_GetLineNumberNodes(CableSimSystem sys, unsigned int line, unsigned int* n) {
  if (int rc = Check(sys, {{n, "n"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckLine(sys, line); rc != CABLESIM_OK) return rc;
  *n = static_cast<unsigned int>(sys->session->cable_nodes(static_cast<int>(line)));
  return FromStatus(absl::OkStatus());
}

int CableSim_GetLineNodePos(CableSimSystem sys, unsigned int line, unsigned int node,
                            double pos[3]) {
  if (int rc = Check(sys, {{pos, "pos"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckLine(sys, line); rc != CABLESIM_OK) return rc;
  const auto r = sys->session->NodePositions(static_cast<int>(line));
  if (int rc = CheckNode(node, line, r.size()); rc != CABLESIM_OK) return rc;
  for (int d = 0; d < 3; ++d) pos[d] = r[node](d);
  return FromStatus(absl::OkStatus());
}

int CableSim_GetLineTension(CableSimSystem sys, unsigned int line, unsigned int node,
                            double* tension) {
  if (int rc = Check(sys, {{tension, "tension"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckLine(sys, line); rc != CABLESIM_OK) return rc;
  const auto t = sys->session->NodeTensions(static_cast<int>(line));
  if (int rc = CheckNode(node, line, t.size()); rc != CABLESIM_OK) return rc;
  *tension = t[node];
  return FromStatus(absl::OkStatus());
}

int CableSim_NCoupledBodies(CableSimSystem sys, unsigned int* n) {
  if (int rc = Check(sys, {{n, "n"}}); rc != CABLESIM_OK) return rc;
  *n = static_cast<unsigned int>(sys->session->coupled_bodies());
  return FromStatus(absl::OkStatus());
}

int CableSim_GetBodyScenePose(CableSimSystem sys, unsigned int body, double pos[3],
                              double q[4]) {
  if (int rc = Check(sys, {{pos, "pos"}, {q, "q"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckBody(sys, body); rc != CABLESIM_OK) return rc;
  const Eigen::Vector3d& p = sys->session->body_scene_position(static_cast<int>(body));
  const Eigen::Quaterniond& o = sys->session->body_scene_orientation(static_cast<int>(body));
  for (int d = 0; d < 3; ++d) pos[d] = p(d);
  q[0] = o.w(), q[1] = o.x(), q[2] = o.y(), q[3] = o.z();
  return FromStatus(absl::OkStatus());
}

int CableSim_SetBodyKinematics(CableSimSystem sys, unsigned int body, const double pos[3],
                               const double q[4], const double vel[3], const double omega[3]) {
  if (int rc = Check(sys, {{pos, "pos"}, {q, "q"}, {vel, "vel"}, {omega, "omega"}});
      rc != CABLESIM_OK)
    return rc;
  if (int rc = CheckBody(sys, body); rc != CABLESIM_OK) return rc;
  if (int rc = CheckFinite(pos, 3, "pos"); rc != CABLESIM_OK) return rc;
  if (int rc = CheckFinite(q, 4, "q"); rc != CABLESIM_OK) return rc;
  if (int rc = CheckFinite(vel, 3, "vel"); rc != CABLESIM_OK) return rc;
  if (int rc = CheckFinite(omega, 3, "omega"); rc != CABLESIM_OK) return rc;
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1) > 1e-6) {
    return Error(CABLESIM_INVALID_ARGUMENT,
                 absl::StrFormat("q: must be a unit quaternion (w, x, y, z) (|q| = %.9g)", norm));
  }
  cablesim::CoupledBodyKinematics& b = sys->bodies[body];
  b.position = Eigen::Vector3d(pos[0], pos[1], pos[2]);
  b.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  b.velocity = Eigen::Vector3d(vel[0], vel[1], vel[2]);
  b.angular_velocity = Eigen::Vector3d(omega[0], omega[1], omega[2]);
  return FromStatus(absl::OkStatus());
}

namespace {
int BodyForces(CableSimSystem sys, unsigned int body, double force[3], double moment[3],
               bool mean) {
  if (int rc = Check(sys, {{force, "force"}, {moment, "moment"}}); rc != CABLESIM_OK) return rc;
  if (int rc = CheckBody(sys, body); rc != CABLESIM_OK) return rc;
  const cablesim::CouplingSession& s = *sys->session;
  const Eigen::Vector3d& f = (mean ? s.mean_body_forces() : s.body_forces())[body];
  const Eigen::Vector3d& m = (mean ? s.mean_body_moments() : s.body_moments())[body];
  for (int d = 0; d < 3; ++d) force[d] = f(d), moment[d] = m(d);
  return FromStatus(absl::OkStatus());
}
}  // namespace

int CableSim_GetBodyForces(CableSimSystem sys, unsigned int body, double force[3],
                           double moment[3]) {
  return BodyForces(sys, body, force, moment, /*mean=*/true);
}

int CableSim_GetBodyEndForces(CableSimSystem sys, unsigned int body, double force[3],
                              double moment[3]) {
  return BodyForces(sys, body, force, moment, /*mean=*/false);
}

int CableSim_GetHostWork(CableSimSystem sys, double* work) {
  if (int rc = Check(sys, {{work, "work"}}); rc != CABLESIM_OK) return rc;
  *work = sys->session->host_work();
  return FromStatus(absl::OkStatus());
}

int CableSim_GetEnergy(CableSimSystem sys, double* energy, double* dissipated) {
  if (int rc = Check(sys, {{energy, "energy"}, {dissipated, "dissipated"}}); rc != CABLESIM_OK)
    return rc;
  *energy = sys->session->energy();
  *dissipated = sys->session->dissipated();
  return FromStatus(absl::OkStatus());
}

int CableSim_GetTime(CableSimSystem sys, double* t) {
  if (int rc = Check(sys, {{t, "t"}}); rc != CABLESIM_OK) return rc;
  *t = sys->session->time();
  return FromStatus(absl::OkStatus());
}

int CableSim_Close(CableSimSystem sys) {
  delete sys;
  last_error.clear();
  return CABLESIM_OK;
}

const char* CableSim_ErrorMessage(void) { return last_error.c_str(); }

}  // extern "C"
