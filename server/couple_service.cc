// CablesimServiceImpl::Couple: a coupling session over a bidirectional
// stream (proto/cablesim/v1/service.proto, docs/coupling.md), a thin layer
// on the engine's CouplingSession (engine/run/coupling.h): the first
// message opens the scene (checked and costed as Run checks it; the
// session holds one of the counted streams) and initialises the coupled
// points, each later message is a coupling step. A bad step message gets a
// reply with `error` set and leaves the session as it was; a step the
// lines cannot take ends the stream (ABORTED).

#include <cmath>
#include <iostream>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "convert/run_proto.h"
#include "engine/run/coupling.h"
#include "server/cablesim_service.h"
#include "server/request_checks.h"
#include "server/stream_slot.h"

namespace cablesim {
namespace {

grpc::Status ToGrpcStatus(const absl::Status& s) {
  return grpc::Status(static_cast<grpc::StatusCode>(s.code()), std::string(s.message()));
}

grpc::Status Invalid(absl::string_view message) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, std::string(message));
}

// Reads the client's next message, the wait recorded for the stall
// watchdog: a client that sends nothing for the stall timeout is cut off
// as one that reads nothing.
bool TimedRead(grpc::ServerReaderWriter<v1::CoupleResponse, v1::CoupleRequest>* stream,
               v1::CoupleRequest* request, CablesimServiceImpl::StreamWatch* watch) {
  watch->write_started_ns = NowNs();
  const bool ok = stream->Read(request);
  watch->write_started_ns = 0;
  return ok;
}

Eigen::Vector3d FromVec3(const v1::Vec3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

void ToVec3(const Eigen::Vector3d& v, v1::Vec3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

// The points of a message as the session's vectors; InvalidArgument naming
// the field (`points[2].position.x: must be finite`) for a wrong count or a
// number that is not finite.
absl::Status PointsOf(const google::protobuf::RepeatedPtrField<v1::CoupledPoint>& points,
                      int expected, std::vector<Eigen::Vector3d>* x,
                      std::vector<Eigen::Vector3d>* v) {
  if (points.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrFormat("points: %d coupled points given, the scene has %d (one per joint with "
                        "coupled: true, in scene order)",
                        points.size(), expected));
  }
  x->clear();
  v->clear();
  for (int i = 0; i < points.size(); ++i) {
    x->push_back(FromVec3(points[i].position()));
    v->push_back(FromVec3(points[i].velocity()));
    for (int d = 0; d < 3; ++d) {
      for (const auto& [name, value] : {std::pair<const char*, double>{"position", x->back()(d)},
                                        {"velocity", v->back()(d)}}) {
        if (!std::isfinite(value)) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "points[%d].%s.%c: must be finite (got %g)", i, name, "xyz"[d], value));
        }
      }
    }
  }
  return absl::OkStatus();
}

// The bodies of a message; InvalidArgument naming the field for a wrong
// count or a number that is not finite (the session checks the rest: a
// quaternion that is not unit, a jump).
absl::Status BodiesOf(const google::protobuf::RepeatedPtrField<v1::CoupledBody>& bodies,
                      int expected, std::vector<CoupledBodyKinematics>* out) {
  if (bodies.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrFormat("bodies: %d coupled bodies given, the scene has %d (one per body with "
                        "coupled: true, in scene order)",
                        bodies.size(), expected));
  }
  out->clear();
  for (const v1::CoupledBody& b : bodies) {
    CoupledBodyKinematics k;
    k.position = FromVec3(b.position());
    k.velocity = FromVec3(b.velocity());
    k.angular_velocity = FromVec3(b.angular_velocity());
    const v1::Quaternion& q = b.orientation();
    k.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z());
    out->push_back(k);
  }
  return absl::OkStatus();
}

// CouplingSession's messages name its C-style arguments (`x[1].z: ...`,
// `xd[0]: ...`, `t: ...`): renamed to the message's fields
// (`points[1].position.z`, `points[0].velocity`, `dt_s`).
std::string FieldsOfMessage(absl::string_view message) {
  for (const auto& [arg, field] : {std::pair<absl::string_view, absl::string_view>{"xd[", ".velocity"},
                                   {"x[", ".position"}}) {
    if (!absl::StartsWith(message, arg)) continue;
    const size_t close = message.find(']');
    if (close == absl::string_view::npos) break;
    return absl::StrCat("points[", message.substr(arg.size(), close - arg.size()), "]", field,
                        message.substr(close + 1));
  }
  if (absl::StartsWith(message, "t: ")) return absl::StrCat("dt_s: ", message.substr(3));
  return std::string(message);
}

// The session's state after a message: time, forces, steps, lines.
void SetState(const CouplingSession& session, bool lines, v1::CoupleResponse* reply) {
  reply->set_time_s(session.time());
  for (int i = 0; i < session.coupled_points(); ++i) {
    ToVec3(session.mean_forces()[i], reply->add_forces());
    ToVec3(session.forces()[i], reply->add_end_forces());
  }
  for (int i = 0; i < session.coupled_bodies(); ++i) {
    ToVec3(session.mean_body_forces()[i], reply->add_body_forces());
    ToVec3(session.mean_body_moments()[i], reply->add_body_moments());
    ToVec3(session.body_forces()[i], reply->add_body_end_forces());
    ToVec3(session.body_moments()[i], reply->add_body_end_moments());
  }
  reply->set_host_work_j(session.host_work());
  reply->set_energy_j(session.energy());
  reply->set_dissipated_j(session.dissipated());
  reply->set_steps(session.steps());
  reply->set_rejected_steps(session.rejected_steps());
  if (!lines) return;
  for (int c = 0; c < session.cables(); ++c) {
    v1::CoupledLine* line = reply->add_lines();
    line->set_name(session.cable_name(c));
    for (const Eigen::Vector3d& p : session.NodePositions(c)) ToVec3(p, line->add_nodes());
    for (double t : session.NodeTensions(c)) line->add_tensions(t);
  }
}

}  // namespace

grpc::Status CablesimServiceImpl::Couple(
    grpc::ServerContext* context,
    grpc::ServerReaderWriter<v1::CoupleResponse, v1::CoupleRequest>* stream) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  StreamSlot slot(this, context, /*counted=*/true, ClientKey(context, tenant));
  if (!slot.acquired()) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, slot.refusal());
  }
  v1::CoupleRequest request;
  if (!TimedRead(stream, &request, slot.watch())) {
    return context->IsCancelled()
               ? grpc::Status(grpc::StatusCode::CANCELLED, "the client cancelled or went away")
               : grpc::Status::OK;  // closed without opening a session
  }
  if (!request.has_open()) {
    return Invalid("open: the first message of a coupling session opens it (CoupleRequest.open)");
  }
  // (`request` is read into again: what the session keeps of it is copied.)
  const v1::CoupleOpen& open = request.open();
  const bool lines = open.lines();
  absl::StatusOr<v1::Scene> scene = SceneOrDeckOfRequest(open.has_scene(), open.scene(),
                                                         open.scene_json(), open.scene_moordyn());
  if (!scene.ok()) return ToGrpcStatus(scene.status());
  if (open.strict()) scene->mutable_solver()->set_strict(true);
  std::unique_ptr<CouplingSession> session;
  double end_time_s = 0;
  v1::CoupleResponse reply;
  try {
    absl::StatusOr<CheckedScene> checked =
        CheckScene(*scene, limits_, [context] { return context->IsCancelled(); });
    if (!checked.ok()) return ToGrpcStatus(checked.status());
    const Scene& engine_scene = checked->scene;
    if (engine_scene.solver.strict && !engine_scene.warnings.empty()) {
      return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                          absl::StrCat("solver.strict: the scene has warnings: ",
                                       absl::StrJoin(engine_scene.warnings, "; ")));
    }
    absl::StatusOr<std::unique_ptr<CouplingSession>> opened = CouplingSession::Open(engine_scene);
    if (!opened.ok()) return ToGrpcStatus(opened.status());
    session = std::move(*opened);
    end_time_s = checked->end_time_s;
    *reply.mutable_model() = ModelInfoToProto(checked->info);
    for (const std::string& w : engine_scene.warnings) reply.add_warnings(w);
  } catch (const std::bad_alloc&) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                        "the scene needs more memory than the server can get");
  }
  const int n = session->coupled_points(), nb = session->coupled_bodies();
  std::vector<Eigen::Vector3d> x, v;
  std::vector<CoupledBodyKinematics> bodies;
  if (absl::Status s = PointsOf(open.points(), n, &x, &v); !s.ok()) return Invalid(s.message());
  if (absl::Status s = BodiesOf(open.bodies(), nb, &bodies); !s.ok()) return Invalid(s.message());
  if (absl::Status s = session->Initialize(x, v, bodies); !s.ok()) {
    return grpc::Status(static_cast<grpc::StatusCode>(s.code()), FieldsOfMessage(s.message()));
  }
  for (int i = 0; i < n; ++i) {
    reply.add_coupled_joints(session->coupled_joint(i));
    ToVec3(session->scene_position(i), reply.add_scene_positions());
  }
  for (int i = 0; i < nb; ++i) {
    reply.add_coupled_bodies(session->coupled_body(i));
    ToVec3(session->body_scene_position(i), reply.add_body_scene_positions());
    const Eigen::Quaterniond& q = session->body_scene_orientation(i);
    v1::Quaternion* out = reply.add_body_scene_orientations();
    out->set_w(q.w());
    out->set_x(q.x());
    out->set_y(q.y());
    out->set_z(q.z());
  }
  reply.set_max_jump_m(session->max_jump_m());
  reply.set_end_time_s(end_time_s);
  SetState(*session, lines, &reply);
  if (!TimedWrite(stream, reply, slot.watch())) {
    return grpc::Status(grpc::StatusCode::CANCELLED, "the client went away");
  }
  if (log_)
    std::cerr << "cablesim-server: coupling session opened (" << n << " points, " << nb
              << " bodies)\n";
  while (TimedRead(stream, &request, slot.watch())) {
    reply.Clear();
    absl::Status refused;
    if (request.has_open()) {
      refused = absl::InvalidArgumentError("open: the session is open already");
    } else if (!request.has_step()) {
      refused = absl::InvalidArgumentError("step: a message after open is a step");
    } else {
      const v1::CoupleStep& step = request.step();
      const double t_end = session->time() + step.dt_s();
      if (!std::isfinite(step.dt_s()) || !(step.dt_s() > 0)) {
        refused = absl::InvalidArgumentError(
            absl::StrFormat("dt_s: must be > 0 and finite (got %g): time does not go backwards",
                            step.dt_s()));
      } else if (t_end > end_time_s * (1 + 1e-12) + 1e-12) {
        refused = absl::InvalidArgumentError(absl::StrFormat(
            "dt_s: the step ends at %.9g s, past the scene's solver.duration %g s (the time the "
            "server costed the session for; give a longer duration)",
            t_end, end_time_s));
      } else {
        refused = PointsOf(step.points(), n, &x, &v);
        if (refused.ok()) refused = BodiesOf(step.bodies(), nb, &bodies);
      }
      if (refused.ok()) {
        absl::Status stepped;
        try {
          stepped = session->Step(t_end, x, v, bodies);
        } catch (const std::bad_alloc&) {
          return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                              "a step needs more memory than the server can get");
        }
        if (session->failed()) {
          if (log_)
            std::cerr << "cablesim-server: coupling session failed: " << stepped.message() << "\n";
          return grpc::Status(grpc::StatusCode::ABORTED,
                              absl::StrCat("the lines could not be advanced: ",
                                           stepped.message()));
        }
        if (stepped.code() != absl::StatusCode::kInvalidArgument && !stepped.ok()) {
          return ToGrpcStatus(stepped);
        }
        refused = stepped;
      }
    }
    if (!refused.ok()) {
      SetFieldError(absl::Status(refused.code(), FieldsOfMessage(refused.message())),
                    reply.mutable_error());
    }
    SetState(*session, lines, &reply);
    if (!TimedWrite(stream, reply, slot.watch())) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "the client went away");
    }
  }
  if (context->IsCancelled()) {
    return grpc::Status(grpc::StatusCode::CANCELLED,
                        "the client cancelled, went away or sent nothing for the stall timeout");
  }
  if (log_)
    std::cerr << "cablesim-server: coupling session closed at t = " << session->time() << " s ("
              << session->steps() << " steps)\n";
  return grpc::Status::OK;
}

}  // namespace cablesim
