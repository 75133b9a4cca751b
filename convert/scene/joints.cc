#include "convert/scene/sections.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "convert/scene_from_proto.h"

namespace cablesim::scene_convert {
namespace {

// A SLIDE joint: a body on one side, a cable on the other, no motion;
// `slide` only with SLIDE.
absl::Status ConvertSlide(const std::string& path, const v1::Joint& j, JointSpec* joint) {
  const std::string slide = Sub(path, "slide");
  if (joint->type != JointType::kSlide) {
    if (j.has_slide()) return Invalid(slide, "only with type SLIDE");
    return absl::OkStatus();
  }
  const Attachment& a = joint->a;
  const Attachment& b = joint->b;
  if (!((a.body >= 0 && b.cable >= 0) || (a.cable >= 0 && b.body >= 0))) {
    return Invalid(Sub(path, "b"), "SLIDE joins a body on one side to a cable on the other");
  }
  if (j.has_motion()) return Invalid(Sub(path, "motion"), "not with type SLIDE");
  const v1::Slide& p = j.slide();
  if (!(p.friction() >= 0) || !std::isfinite(p.friction()))
    return Invalid(Sub(slide, "friction"), "must be >= 0");
  if (!(p.stiffness() >= 0) || !std::isfinite(p.stiffness()))
    return Invalid(Sub(slide, "stiffness"), "must be >= 0");
  if (!(p.stick_velocity() >= 0) || !std::isfinite(p.stick_velocity()))
    return Invalid(Sub(slide, "stick_velocity"), "must be > 0");
  joint->slide.friction = p.friction();
  joint->slide.stiffness_n_m = p.stiffness();
  if (p.stick_velocity() > 0) joint->slide.stick_velocity_m_s = p.stick_velocity();
  return absl::OkStatus();
}

// Joint.release (line failure): a PIN or FIXED joint whose force is its
// rows' multipliers, not a moving, turning or coupled support (their
// force columns and work belong to the support), nor a winch's end.
absl::Status ConvertRelease(const ConversionState& state, const std::string& path,
                            const v1::Joint& j, JointSpec* joint) {
  if (!j.has_release()) return absl::OkStatus();
  const std::string release = Sub(path, "release");
  const v1::Release& r = j.release();
  if (!r.has_time() && !r.has_breaking_load())
    return Invalid(release, "needs time or breaking_load");
  if (joint->type == JointType::kSlide)
    return Invalid(release, "not with type SLIDE (only a PIN or FIXED joint lets go)");
  if (joint->HasMotion() || joint->HasRotation())
    return Invalid(release, "not on a moving or turning support");
  for (const Attachment* at : {&joint->a, &joint->b}) {
    if (at->cable < 0 || !state.scene.cables[at->cable].winch.enabled) continue;
    const double length = state.scene.cables[at->cable].length_m;
    if (std::abs(at->s_m - length) <= kArcLengthTolerance * length)
      return Invalid(release, "not at a winch's end (the winch holds the line)");
  }
  if (r.has_time()) {
    if (!(r.time() >= 0) || !std::isfinite(r.time()))
      return Invalid(Sub(release, "time"),
                     absl::StrCat("must be >= 0 and finite (got ", Num(r.time()), ")"));
    joint->release_time_s = r.time();
  }
  if (r.has_breaking_load()) {
    if (!(r.breaking_load() > 0) || !std::isfinite(r.breaking_load()))
      return Invalid(Sub(release, "breaking_load"),
                     absl::StrCat("must be > 0 and finite (got ", Num(r.breaking_load()), ")"));
    joint->breaking_load_n = r.breaking_load();
  }
  return absl::OkStatus();
}

absl::Status ConvertJoint(const ConversionState& state, int i, JointSpec* joint) {
  const v1::Joint& j = state.proto.joints(i);
  const std::string path = Indexed("", "joints", i);
  CABLESIM_ASSIGN_OR_RETURN(joint->type, JointTypeFromProto(j.type(), Sub(path, "type")));
  CABLESIM_ASSIGN_OR_RETURN(joint->a, ConvertAttachment(state, Sub(path, "a"), j.a(), false));
  CABLESIM_ASSIGN_OR_RETURN(joint->b, ConvertAttachment(state, Sub(path, "b"), j.b(), true));
  const Attachment& a = joint->a;
  const Attachment& b = joint->b;
  if (a.cable >= 0 && a.cable == b.cable) {
    const double length = state.scene.cables[a.cable].length_m;
    if (std::abs(a.s_m - b.s_m) <= kArcLengthTolerance * length) {
      return Invalid(Sub(path, "b"),
                     absl::StrCat("same place as side a (cable \"",
                                  state.scene.cables[a.cable].name, "\" at s = ", Num(a.s_m), ")"));
    }
  }
  if (a.body >= 0 && a.body == b.body) {
    return Invalid(Sub(path, "b"),
                   absl::StrCat("joins body \"", state.scene.bodies[a.body].name, "\" to itself"));
  }
  CABLESIM_RETURN_IF_ERROR(ConvertSlide(path, j, joint));
  joint->name = j.name();
  if (j.has_motion()) {
    const std::string motion = Sub(path, "motion");
    CABLESIM_ASSIGN_OR_RETURN(joint->motion,
                              ConvertTimeVector(motion, j.motion(), plausible::kCoordinate));
    if (joint->HasMotion() && !b.IsGround()) {
      return Invalid(motion, "only a joint to ground moves (side b must be the ground)");
    }
    for (int d = 0; d < 3; ++d) {
      const double start = joint->motion[d](0);
      if (std::abs(start) > 1e-12) {
        return Invalid(Sub(motion, std::string(1, "xyz"[d])),
                       absl::StrCat("must be 0 at t = 0 (the scene places the joint at its "
                                    "start; got ",
                                    Num(start), " m)"));
      }
    }
  }
  if (j.has_rotation()) {
    const std::string rotation = Sub(path, "rotation");
    CABLESIM_ASSIGN_OR_RETURN(joint->rotation,
                              ConvertTimeFunction(rotation, j.rotation(), plausible::kAngle));
    if (joint->HasRotation() && (!b.IsGround() || joint->type != JointType::kFixed)) {
      return Invalid(rotation,
                     "only a FIXED joint to ground turns (a PIN holds no direction; side b "
                     "must be the ground)");
    }
    if (const double start = joint->rotation(0); std::abs(start) > 1e-12) {
      return Invalid(rotation, absl::StrCat("must be 0 at t = 0 (the scene places the joint at "
                                            "its start; got ",
                                            Num(start), " rad)"));
    }
  }
  if (j.coupled()) {
    const std::string coupled = Sub(path, "coupled");
    if (!b.IsGround())
      return Invalid(coupled, "only a joint to ground is coupled (side b must be the ground)");
    if (joint->type == JointType::kSlide) return Invalid(coupled, "not with type SLIDE");
    if (!IsZero(joint->motion))
      return Invalid(coupled, "not with motion (the host moves the point)");
    if (joint->HasRotation())
      return Invalid(coupled, "not with rotation (the host moves the point)");
    joint->coupled = true;
  }
  if (j.has_rotation_axis()) {
    const std::string axis = Sub(path, "rotation_axis");
    if (!j.has_rotation()) return Invalid(axis, "only with rotation");
    CABLESIM_ASSIGN_OR_RETURN(joint->rotation_axis, Direction(axis, j.rotation_axis()));
  }
  return ConvertRelease(state, path, j, joint);
}

}  // namespace

absl::StatusOr<Attachment> ConvertAttachment(const ConversionState& state, absl::string_view path,
                                             const v1::Attachment& a, bool allow_ground) {
  Attachment result;
  const bool on_cable = !a.cable().empty();
  const bool on_body = !a.body().empty();
  if (on_cable && on_body) return Invalid(path, "names both a cable and a body");
  CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "cable"), a.cable()));
  CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "body"), a.body()));
  if (on_cable) {
    const auto it = state.cable_index.find(a.cable());
    if (it == state.cable_index.end()) {
      return Invalid(Sub(path, "cable"), absl::StrCat("no cable named \"", a.cable(), "\""));
    }
    if (a.has_point()) return Invalid(Sub(path, "point"), "only with body");
    result.cable = it->second;
    const double length = state.scene.cables[it->second].length_m;
    const std::string s_path = Sub(path, "s");
    CABLESIM_RETURN_IF_ERROR(CheckFinite(s_path, a.s()));
    const double tolerance = kArcLengthTolerance * length;
    if (a.s() < -tolerance || a.s() > length + tolerance) {
      return Invalid(s_path,
                     absl::StrCat("must be in [0, ", Num(length), "] (got ", Num(a.s()), ")"));
    }
    result.s_m = std::clamp(a.s(), 0.0, length);
    return result;
  }
  if (on_body) {
    const auto it = state.body_index.find(a.body());
    if (it == state.body_index.end()) {
      return Invalid(Sub(path, "body"), absl::StrCat("no body named \"", a.body(), "\""));
    }
    if (a.s() != 0) return Invalid(Sub(path, "s"), "only with cable");
    result.body = it->second;
    CABLESIM_ASSIGN_OR_RETURN(result.point_body_m,
                              VectorInRange(Sub(path, "point"), a.point(), plausible::kCoordinate));
    return result;
  }
  if (!allow_ground) return Invalid(path, "must name a cable or a body");
  if (a.s() != 0) return Invalid(Sub(path, "s"), "only with cable");
  if (a.has_point()) return Invalid(Sub(path, "point"), "only with body");
  return result;  // ground
}

absl::Status ConvertJoints(ConversionState* state) {
  Scene& scene = state->scene;
  scene.joints.resize(state->proto.joints_size());
  for (int i = 0; i < state->proto.joints_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(ConvertJoint(*state, i, &scene.joints[i]));
  }
  // Bodies threaded on a cable: a PIN at each face, after the scene's own.
  for (const JointSpec& joint : state->threaded_joints) scene.joints.push_back(joint);
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
