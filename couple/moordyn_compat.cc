// MoorDyn v2's C function names over libcablesim_couple (couple/moordyn/
// MoorDyn2.h says what and in which conventions): a thin map of points and
// lines onto the C interface of cablesim_couple.h, which does the work.

#include "couple/moordyn/MoorDyn2.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_file.h"
#include "couple/cablesim_couple.h"
#include "couple/couple_internal.h"

struct CableSimMoorDynLine {
  CableSimSystem sys = nullptr;
  unsigned int cable = 0;  // 0-based, as cablesim_couple.h counts
  unsigned int id = 0;     // as the host asked for it
};

struct CableSimMoorDynPoint {
  unsigned int id = 0;
  bool coupled = false;
  std::vector<int> members;  // coupled: the coupled supports held there
  double position[3] = {0, 0, 0};
};

struct CableSimMoorDynSystem {
  CableSimSystem sys = nullptr;
  unsigned int supports = 0;  // coupled supports (cablesim_couple.h's points)
  unsigned int bodies = 0;    // coupled bodies (6 DOF each, first)
  // Every point held by a support, by id, and the host's coupled points in
  // its order.
  std::vector<std::unique_ptr<CableSimMoorDynPoint>> owned;
  std::map<unsigned int, CableSimMoorDynPoint*> points;
  std::vector<CableSimMoorDynPoint*> coupled;
  // Line handles by the host's number, and the cable each number names.
  std::map<unsigned int, std::unique_ptr<CableSimMoorDynLine>> lines;
  std::map<unsigned int, unsigned int> cable_of_line;
  std::vector<double> x, xd, f;  // per coupled support
};

namespace {

using cablesim::couple::SetError;

int Fail(int code, const std::string& message) {
  SetError(message);
  return code;
}

int FromCableSim(int rc) {
  switch (rc) {
    case CABLESIM_OK:
      return MOORDYN_SUCCESS;
    case CABLESIM_INVALID_ARGUMENT:
      return MOORDYN_INVALID_INPUT;
    case CABLESIM_INVALID_SCENE:
      return MOORDYN_INVALID_INPUT_FILE;
    case CABLESIM_STEP_FAILED:
      return MOORDYN_NAN_ERROR;
    case CABLESIM_WRONG_STATE:
      return MOORDYN_INVALID_VALUE;
    default:
      return MOORDYN_UNHANDLED_ERROR;
  }
}

// "point12" -> 12; 0 for any other name.
unsigned int PointId(const std::string& name) {
  unsigned int id = 0;
  if (!absl::StartsWith(name, "point") || !absl::SimpleAtoi(name.substr(5), &id)) return 0;
  return id;
}

// Where a cable's end (s = 0 or its length) starts in the scene.
void EndPosition(const cablesim::v1::Scene& scene, const cablesim::v1::Attachment& end,
                 double out[3]) {
  for (const cablesim::v1::Cable& c : scene.cables()) {
    if (c.name() != end.cable()) continue;
    const bool first = end.s() <= 0.5 * c.length();
    if (c.points_size() > 0) {
      const cablesim::v1::Vec3& p = c.points(first ? 0 : c.points_size() - 1);
      out[0] = p.x(), out[1] = p.y(), out[2] = p.z();
      return;
    }
    // A straight cable from `start` along `direction` (unit after scaling).
    const cablesim::v1::Vec3& a = c.start();
    const cablesim::v1::Vec3& d = c.direction();
    const double n = std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z());
    const double l = first || n == 0 ? 0 : c.length() / n;
    out[0] = a.x() + l * d.x(), out[1] = a.y() + l * d.y(), out[2] = a.z() + l * d.z();
    return;
  }
}

int CheckSystem(MoorDyn system) {
  if (system == nullptr || system->sys == nullptr) {
    return Fail(MOORDYN_INVALID_INPUT, "system: null (MoorDyn_Create failed?)");
  }
  return MOORDYN_SUCCESS;
}

// The host's coupled kinematics (3 per point, after 6 per body) to every
// coupled support's.
void Spread(const MoorDyn system, const double* host, std::vector<double>* supports) {
  host += 6 * system->bodies;
  for (size_t i = 0; i < system->coupled.size(); ++i)
    for (int member : system->coupled[i]->members)
      for (int d = 0; d < 3; ++d) (*supports)[3 * member + d] = host[3 * i + d];
}

// MoorDyn's body orientation: R = Rx(roll) Ry(pitch) Rz(yaw) as a
// quaternion (w, x, y, z), and the angular velocity (world axes) of the
// angles' rates: omega = roll' e_x + pitch' Rx e_y + yaw' Rx Ry e_z.
void EulerToQuaternion(const double a[3], const double rates[3], double q[4], double omega[3]) {
  const double c[3] = {std::cos(a[0] / 2), std::cos(a[1] / 2), std::cos(a[2] / 2)};
  const double s[3] = {std::sin(a[0] / 2), std::sin(a[1] / 2), std::sin(a[2] / 2)};
  // qx qy qz, each (cos, sin along its axis), multiplied out.
  q[0] = c[0] * c[1] * c[2] - s[0] * s[1] * s[2];
  q[1] = s[0] * c[1] * c[2] + c[0] * s[1] * s[2];
  q[2] = c[0] * s[1] * c[2] - s[0] * c[1] * s[2];
  q[3] = c[0] * c[1] * s[2] + s[0] * s[1] * c[2];
  const double cr = std::cos(a[0]), sr = std::sin(a[0]), cp = std::cos(a[1]), sp = std::sin(a[1]);
  // Rx e_y = (0, cr, sr); Rx Ry e_z = (sp, -sr cp, cr cp).
  omega[0] = rates[0] + rates[2] * sp;
  omega[1] = rates[1] * cr - rates[2] * sr * cp;
  omega[2] = rates[1] * sr + rates[2] * cr * cp;
}

// Stages the coupled bodies' kinematics of the host's x, xd (6 each, first).
int SetBodies(MoorDyn system, const double* x, const double* xd) {
  for (unsigned int b = 0; b < system->bodies; ++b) {
    double q[4], omega[3];
    EulerToQuaternion(x + 6 * b + 3, xd + 6 * b + 3, q, omega);
    const int rc =
        CableSim_SetBodyKinematics(system->sys, b, x + 6 * b, q, xd + 6 * b, omega);
    if (rc != CABLESIM_OK) {
      // Its message names SetBodyKinematics' arguments: say where they came from.
      SetError(absl::StrCat("x, xd: coupled body ", b, " (degrees of freedom ", 6 * b, " to ",
                            6 * b + 5, "): ", CableSim_ErrorMessage()));
      return rc;
    }
  }
  return CABLESIM_OK;
}

}  // namespace

extern "C" {

MoorDyn MoorDyn_Create(const char* infilename) {
  if (infilename == nullptr) {
    SetError("infilename: null");
    return nullptr;
  }
  try {
    absl::StatusOr<cablesim::v1::Scene> read = cablesim::ReadSceneFile(infilename);
    if (!read.ok()) {
      SetError(std::string(read.status().message()));
      return nullptr;
    }
    cablesim::v1::Scene scene = *read;
    // A deck is read as a STATIC scene (its standalone run); coupled, it
    // runs in time from its static equilibrium.
    // (A coupling session ignores the duration and the frames: the host
    // says how far to go. One frame over a day satisfies their checks.)
    if (scene.solver().analysis() == cablesim::v1::STATIC) {
      cablesim::v1::Solver* solver = scene.mutable_solver();
      solver->set_analysis(cablesim::v1::DYNAMIC);
      solver->set_initial_state(cablesim::v1::Solver::STATIC);
      solver->set_duration(86400);
      solver->set_output_interval(86400);
    }
    auto system = std::make_unique<CableSimMoorDynSystem>();
    // Points: the supports, grouped by name; a deck's are "point<ID>".
    bool all_numbered = true;
    std::map<std::string, CableSimMoorDynPoint*> by_name;
    int support = 0;
    for (const cablesim::v1::Joint& j : scene.joints()) {
      const bool ground = !j.has_b() || (j.b().cable().empty() && j.b().body().empty());
      if (!ground || !j.a().body().empty()) continue;
      const std::string key =
          j.name().empty() ? absl::StrCat("#", system->owned.size() + 1) : j.name();
      CableSimMoorDynPoint*& p = by_name[key];
      if (p == nullptr) {
        system->owned.push_back(std::make_unique<CableSimMoorDynPoint>());
        p = system->owned.back().get();
        p->id = PointId(j.name());
        all_numbered = all_numbered && p->id > 0;
        EndPosition(scene, j.a(), p->position);
      }
      if (j.coupled()) {
        p->coupled = true;
        p->members.push_back(support++);
      }
    }
    // Numbered by their deck IDs, or 1, 2, ... in scene order.
    for (size_t k = 0; k < system->owned.size(); ++k) {
      CableSimMoorDynPoint* p = system->owned[k].get();
      if (!all_numbered) p->id = static_cast<unsigned int>(k + 1);
      system->points[p->id] = p;
    }
    for (const auto& [id, p] : system->points)
      if (p->coupled) system->coupled.push_back(p);
    // Lines: a deck's "line<ID>", otherwise 1, 2, ... in scene order.
    for (int c = 0; c < scene.cables_size(); ++c) {
      unsigned int id = 0;
      const std::string& name = scene.cables(c).name();
      if (!absl::StartsWith(name, "line") || !absl::SimpleAtoi(name.substr(4), &id)) {
        id = static_cast<unsigned int>(c + 1);
      }
      system->cable_of_line[id] = static_cast<unsigned int>(c);
    }
    system->sys = cablesim::couple::CreateFromProto(scene, infilename);
    if (system->sys == nullptr) return nullptr;
    system->supports = static_cast<unsigned int>(support);
    CableSim_NCoupledBodies(system->sys, &system->bodies);
    system->x.assign(3 * support, 0);
    system->xd.assign(3 * support, 0);
    system->f.assign(3 * support, 0);
    return system.release();
  } catch (const std::exception& e) {
    SetError(absl::StrCat(infilename, ": ", e.what()));
    return nullptr;
  }
}

int MoorDyn_NCoupledDOF(MoorDyn system, unsigned int* n) {
  if (int rc = CheckSystem(system); rc != MOORDYN_SUCCESS) return rc;
  if (n == nullptr) return Fail(MOORDYN_INVALID_INPUT, "n: null");
  *n = 6u * system->bodies + 3u * static_cast<unsigned int>(system->coupled.size());
  return MOORDYN_SUCCESS;
}

int MoorDyn_Init(MoorDyn system, const double* x, const double* xd) {
  if (int rc = CheckSystem(system); rc != MOORDYN_SUCCESS) return rc;
  if (x == nullptr) return Fail(MOORDYN_INVALID_INPUT, "x: null");
  if (xd == nullptr) return Fail(MOORDYN_INVALID_INPUT, "xd: null");
  Spread(system, x, &system->x);
  Spread(system, xd, &system->xd);
  if (int rc = SetBodies(system, x, xd); rc != CABLESIM_OK) return FromCableSim(rc);
  const int rc = FromCableSim(CableSim_Init(system->sys, system->x.data(), system->xd.data()));
  if (rc == MOORDYN_SUCCESS) {
    const double* points = x + 6 * system->bodies;
    for (size_t i = 0; i < system->coupled.size(); ++i)
      for (int d = 0; d < 3; ++d) system->coupled[i]->position[d] = points[3 * i + d];
  }
  return rc;
}

int MoorDyn_Step(MoorDyn system, const double* x, const double* xd, double* f, double* t,
                 double* dt) {
  if (int rc = CheckSystem(system); rc != MOORDYN_SUCCESS) return rc;
  if (x == nullptr) return Fail(MOORDYN_INVALID_INPUT, "x: null");
  if (xd == nullptr) return Fail(MOORDYN_INVALID_INPUT, "xd: null");
  if (f == nullptr) return Fail(MOORDYN_INVALID_INPUT, "f: null");
  Spread(system, x, &system->x);
  Spread(system, xd, &system->xd);
  if (int rc = SetBodies(system, x, xd); rc != CABLESIM_OK) return FromCableSim(rc);
  const int rc = FromCableSim(
      CableSim_Step(system->sys, system->x.data(), system->xd.data(), system->f.data(), t, dt));
  if (rc != MOORDYN_SUCCESS) return rc;
  for (unsigned int b = 0; b < system->bodies; ++b)
    CableSim_GetBodyForces(system->sys, b, f + 6 * b, f + 6 * b + 3);
  const double* points = x + 6 * system->bodies;
  double* forces = f + 6 * system->bodies;
  for (size_t i = 0; i < system->coupled.size(); ++i) {
    const CableSimMoorDynPoint& p = *system->coupled[i];
    for (int d = 0; d < 3; ++d) {
      forces[3 * i + d] = 0;
      for (int member : p.members) forces[3 * i + d] += system->f[3 * member + d];
      system->coupled[i]->position[d] = points[3 * i + d];
    }
  }
  return MOORDYN_SUCCESS;
}

int MoorDyn_Close(MoorDyn system) {
  if (system != nullptr) CableSim_Close(system->sys);
  delete system;
  return MOORDYN_SUCCESS;
}

int MoorDyn_GetNumberLines(MoorDyn system, unsigned int* n) {
  if (int rc = CheckSystem(system); rc != MOORDYN_SUCCESS) return rc;
  if (n == nullptr) return Fail(MOORDYN_INVALID_INPUT, "n: null");
  *n = static_cast<unsigned int>(system->cable_of_line.size());
  return MOORDYN_SUCCESS;
}

MoorDynLine MoorDyn_GetLine(MoorDyn system, unsigned int l) {
  if (CheckSystem(system) != MOORDYN_SUCCESS) return nullptr;
  const auto cable = system->cable_of_line.find(l);
  if (cable == system->cable_of_line.end()) {
    SetError(absl::StrFormat("l: there is no line %u (lines are numbered from 1)", l));
    return nullptr;
  }
  std::unique_ptr<CableSimMoorDynLine>& line = system->lines[l];
  if (!line) line.reset(new CableSimMoorDynLine{system->sys, cable->second, l});
  return line.get();
}

int MoorDyn_GetLineNumberNodes(MoorDynLine line, unsigned int* n) {
  if (line == nullptr) return Fail(MOORDYN_INVALID_INPUT, "line: null");
  return FromCableSim(CableSim_GetLineNumberNodes(line->sys, line->cable, n));
}

int MoorDyn_GetLineNodePos(MoorDynLine line, unsigned int i, double pos[3]) {
  if (line == nullptr) return Fail(MOORDYN_INVALID_INPUT, "line: null");
  return FromCableSim(CableSim_GetLineNodePos(line->sys, line->cable, i, pos));
}

int MoorDyn_GetLineNodeTen(MoorDynLine line, unsigned int i, double ten[3]) {
  if (line == nullptr) return Fail(MOORDYN_INVALID_INPUT, "line: null");
  if (ten == nullptr) return Fail(MOORDYN_INVALID_INPUT, "ten: null");
  unsigned int n = 0;
  double tension = 0;
  if (int rc = FromCableSim(CableSim_GetLineTension(line->sys, line->cable, i, &tension));
      rc != MOORDYN_SUCCESS)
    return rc;
  CableSim_GetLineNumberNodes(line->sys, line->cable, &n);
  // The line's direction at node i, from end A towards end B: the chord
  // through its neighbouring nodes (one-sided at the ends).
  const unsigned int before = i > 0 ? i - 1 : i, after = i + 1 < n ? i + 1 : i;
  double a[3], b[3];
  CableSim_GetLineNodePos(line->sys, line->cable, before, a);
  CableSim_GetLineNodePos(line->sys, line->cable, after, b);
  const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int k = 0; k < 3; ++k) ten[k] = length > 0 ? tension * d[k] / length : 0;
  return MOORDYN_SUCCESS;
}

int MoorDyn_GetLineFairTen(MoorDynLine line, double* t) {
  if (line == nullptr) return Fail(MOORDYN_INVALID_INPUT, "line: null");
  if (t == nullptr) return Fail(MOORDYN_INVALID_INPUT, "t: null");
  unsigned int n = 0;
  if (int rc = FromCableSim(CableSim_GetLineNumberNodes(line->sys, line->cable, &n));
      rc != MOORDYN_SUCCESS)
    return rc;
  return FromCableSim(CableSim_GetLineTension(line->sys, line->cable, n - 1, t));
}

int MoorDyn_GetNumberPoints(MoorDyn system, unsigned int* n) {
  if (int rc = CheckSystem(system); rc != MOORDYN_SUCCESS) return rc;
  if (n == nullptr) return Fail(MOORDYN_INVALID_INPUT, "n: null");
  *n = static_cast<unsigned int>(system->points.size());
  return MOORDYN_SUCCESS;
}

MoorDynPoint MoorDyn_GetPoint(MoorDyn system, unsigned int id) {
  if (CheckSystem(system) != MOORDYN_SUCCESS) return nullptr;
  const auto p = system->points.find(id);
  if (p == system->points.end()) {
    SetError(absl::StrFormat(
        "id: there is no point %u held by a support (the deck's Fixed and Vessel points; free "
        "points are not offered)",
        id));
    return nullptr;
  }
  return p->second;
}

int MoorDyn_GetPointPos(MoorDynPoint point, double pos[3]) {
  if (point == nullptr) return Fail(MOORDYN_INVALID_INPUT, "point: null");
  if (pos == nullptr) return Fail(MOORDYN_INVALID_INPUT, "pos: null");
  for (int d = 0; d < 3; ++d) pos[d] = point->position[d];
  return MOORDYN_SUCCESS;
}

}  // extern "C"
