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

// Checks the system and the pointer arguments (named) of a call.
int Check(CableSimSystem sys, std::initializer_list<std::pair<const void*, const char*>> args) {
  if (sys == nullptr || sys->session == nullptr) {
    return Error(CABLESIM_INVALID_ARGUMENT, "sys: null (CableSim_Create failed?)");
  }
  for (const auto& [p, name] : args) {
    if (p == nullptr) return Error(CABLESIM_INVALID_ARGUMENT, absl::StrCat(name, ": null"));
  }
  return CABLESIM_OK;
}

int CheckLine(CableSimSystem sys, unsigned int line) {
  const int lines = sys->session->cables();
  if (line >= static_cast<unsigned int>(lines)) {
    return Error(CABLESIM_INVALID_ARGUMENT,
                 absl::StrFormat("line: %u is not a line (the scene has %d)", line, lines));
  }
  return CABLESIM_OK;
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
    return new CableSimSystemImpl{std::move(*session)};
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
  if (int rc = Check(sys, {{x, "x"}, {xd, "xd"}}); rc != CABLESIM_OK) return rc;
  const int n = sys->session->coupled_points();
  return FromStatus(sys->session->Initialize(Points(x, n), Points(xd, n)));
}

int CableSim_Step(CableSimSystem sys, const double* x, const double* xd, double* f, double* t,
                  double* dt) {
  if (int rc = Check(sys, {{x, "x"}, {xd, "xd"}, {f, "f"}, {t, "t"}, {dt, "dt"}});
      rc != CABLESIM_OK)
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
  if (int rc = FromStatus(s.Step(*t + *dt, Points(x, n), Points(xd, n))); rc != CABLESIM_OK)
    return rc;
  *t = s.time();
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
