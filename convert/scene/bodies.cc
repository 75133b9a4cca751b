#include "convert/scene/sections.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "engine/scene/polyline.h"

namespace cablesim::scene_convert {
namespace {

// Body.seabed_contact: the points, their spring, damper and friction.
absl::Status ConvertBodyContact(const std::string& path, const v1::Body& b, BodySpec* body) {
  const v1::BodySeabedContact& c = b.seabed_contact();
  const std::string contact_path = Sub(path, "seabed_contact");
  if (c.points_size() == 0)
    return Invalid(Sub(contact_path, "points"), "at least one point is required");
  for (int k = 0; k < c.points_size(); ++k) {
    CABLESIM_ASSIGN_OR_RETURN(
        const Eigen::Vector3d point,
        VectorInRange(Indexed(contact_path, "points", k), c.points(k), plausible::kCoordinate));
    body->contact_points_m.push_back(point);
  }
  CABLESIM_RETURN_IF_ERROR(
      CheckPositiveInRange(Sub(contact_path, "stiffness"), c.stiffness(), plausible::kStiffness));
  body->contact_stiffness_n_m = c.stiffness();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(contact_path, "damping"), c.damping()));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange(Sub(contact_path, "damping"), c.damping(), plausible::kDampingCoefficient));
  body->contact_damping_n_s_m = c.damping();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(contact_path, "friction"), c.friction()));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange(Sub(contact_path, "friction"), c.friction(), plausible::kFrictionCoefficient));
  body->contact_friction = c.friction();
  return absl::OkStatus();
}

// One of Body.hydrodynamics and Body.hydrodynamics_parts (BodyFluidLoad) at
// `path`: the cylinder's size from the body's cylinder unless given (none
// for drag areas alone); coefficients and areas >= 0; the axis only with
// along_axis.
absl::Status ConvertBodyFluidPart(const ConversionState& state, const std::string& path,
                                  const v1::Body& b, const v1::BodyHydrodynamics& h,
                                  BodyFluidPart* part) {
  for (const auto& [name, v, range, out] :
       {std::tuple{"drag_area", &h.drag_area(), &plausible::kDragArea, &part->drag_area_m2},
        std::tuple{"rotational_drag_area", &h.rotational_drag_area(),
                   &plausible::kRotationalDragArea, &part->rotational_drag_area_m5}}) {
    CABLESIM_ASSIGN_OR_RETURN(*out, VectorInRange(Sub(path, name), *v, *range));
  }
  if (h.has_center()) {
    CABLESIM_ASSIGN_OR_RETURN(part->center_m, VectorInRange(Sub(path, "center"), h.center(),
                                                            plausible::kCoordinate));
    if (!part->center_m.isZero(0) &&
        (!part->drag_area_m2.isZero(0) || !part->rotational_drag_area_m5.isZero(0))) {
      return Invalid(Sub(path, "center"),
                     "not with drag_area or rotational_drag_area (they act at the centre of "
                     "mass): give the drag areas in a part of their own");
    }
  }
  if (h.has_axis()) {
    if (!h.along_axis())
      return Invalid(Sub(path, "axis"), "only with along_axis (the split's direction)");
    CABLESIM_ASSIGN_OR_RETURN(part->axis_body, Direction(Sub(path, "axis"), h.axis()));
  }
  // Drag areas alone on a body given by mass: no cylinder (no buoyancy).
  const bool cylinder = h.has_diameter() || h.has_height() || b.has_cylinder() ||
                        h.drag_coefficient() != 0 || h.heave_drag_coefficient() != 0 ||
                        h.added_mass() != 0 || h.heave_added_mass() != 0 || h.along_axis();
  if (!cylinder) return absl::OkStatus();
  if (!(state.scene.gravity_m_s2.norm() > 0)) {
    return Invalid(path, "needs gravity for its cylinder (it sets the vertical and the "
                         "buoyancy; without gravity give drag_area alone)");
  }
  for (const auto& [name, given, value, from_cylinder, out] :
       {std::tuple{"diameter", h.has_diameter(), h.diameter(), b.cylinder().diameter(),
                   &part->diameter_m},
        std::tuple{"height", h.has_height(), h.height(), b.cylinder().height(),
                   &part->height_m}}) {
    if (!given && !b.has_cylinder())
      return Invalid(Sub(path, name), "required for a body given by mass (no cylinder)");
    const double v = given ? value : from_cylinder;
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, name), v, plausible::kSize));
    *out = v;
  }
  for (const auto& [name, value, out] :
       {std::tuple{"drag_coefficient", h.drag_coefficient(), &part->drag},
        std::tuple{"heave_drag_coefficient", h.heave_drag_coefficient(), &part->heave_drag},
        std::tuple{"added_mass", h.added_mass(), &part->added_mass},
        std::tuple{"heave_added_mass", h.heave_added_mass(), &part->heave_added_mass}}) {
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, name), value));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, name), value, plausible::kHydroCoefficient));
    *out = value;
  }
  part->along_axis = h.along_axis();
  return absl::OkStatus();
}

// Body.hydrodynamics and Body.hydrodynamics_parts: one BodyFluidPart each,
// `hydrodynamics` first.
absl::Status ConvertBodyHydrodynamics(const ConversionState& state, int i, const v1::Body& b,
                                      BodySpec* body) {
  if (!b.has_hydrodynamics() && b.hydrodynamics_parts_size() == 0) return absl::OkStatus();
  const std::string body_path = Indexed("", "bodies", i);
  if (!(state.proto.fluid().density() > 0)) {
    return Invalid(Sub(body_path, b.has_hydrodynamics() ? "hydrodynamics" : "hydrodynamics_parts"),
                   "needs a fluid around the body (fluid.density > 0)");
  }
  body->has_hydrodynamics = true;
  if (b.has_hydrodynamics()) {
    BodyFluidPart part;
    CABLESIM_RETURN_IF_ERROR(ConvertBodyFluidPart(state, Sub(body_path, "hydrodynamics"), b,
                                                  b.hydrodynamics(), &part));
    body->hydro_parts.push_back(part);
  }
  for (int k = 0; k < b.hydrodynamics_parts_size(); ++k) {
    BodyFluidPart part;
    part.scene_index = k;
    CABLESIM_RETURN_IF_ERROR(ConvertBodyFluidPart(
        state, Indexed(body_path, "hydrodynamics_parts", k), b, b.hydrodynamics_parts(k), &part));
    body->hydro_parts.push_back(part);
  }
  return absl::OkStatus();
}

// Body.on: the position and axis from the cable's polyline (the points
// the model builder lays the cable's nodes at), and for a threaded body
// the two PIN joints at its faces.
absl::Status PlaceOnCable(ConversionState* state, int i, const v1::Body& b) {
  BodySpec* body = &state->scene.bodies[i];
  const std::string path = Indexed("", "bodies", i);
  const std::string on = Sub(path, "on");
  if (b.has_position())
    return Invalid(Sub(path, "position"), "not with on (the cable places the body)");
  if (b.has_axis())
    return Invalid(Sub(path, "axis"), "not with on (the cable's tangent is the axis)");
  CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(on, "cable"), b.on().cable()));
  const auto it = state->cable_index.find(b.on().cable());
  if (it == state->cable_index.end()) {
    return Invalid(Sub(on, "cable"), absl::StrCat("no cable named \"", b.on().cable(), "\""));
  }
  const CableSpec& cable = state->scene.cables[it->second];
  const double length = cable.length_m, s = b.on().s();
  const std::string s_path = Sub(on, "s");
  CABLESIM_RETURN_IF_ERROR(CheckFinite(s_path, s));
  const double half = b.on().threaded() ? b.cylinder().height() / 2 : 0;
  if (b.on().threaded() && !b.has_cylinder()) {
    return Invalid(Sub(on, "threaded"),
                   "needs cylinder (its faces are where the cable enters and leaves)");
  }
  const double tolerance = kArcLengthTolerance * length;
  if (s - half < -tolerance || s + half > length + tolerance) {
    return Invalid(s_path, absl::StrCat("must be in [", Num(half), ", ", Num(length - half),
                                        "] (got ", Num(s), ")"));
  }
  Eigen::Vector3d point, tangent;
  if (!b.on().threaded()) {
    PolylineAt(cable.points, std::clamp(s, 0.0, length) / length, &point, &tangent);
    body->position_m = point;
    body->axis = tangent;
    return absl::OkStatus();
  }
  const double s1 = std::max(s - half, 0.0), s2 = std::min(s + half, length);
  Eigen::Vector3d p1, p2;
  PolylineAt(cable.points, s1 / length, &p1, &tangent);
  PolylineAt(cable.points, s2 / length, &p2, &tangent);
  const double chord = (p2 - p1).norm();
  if (!(chord > 0)) return Invalid(s_path, "the cable's faces coincide");
  body->position_m = (p1 + p2) / 2;
  body->axis = (p2 - p1) / chord;
  for (const auto& [arc, x] : {std::pair{s1, -chord / 2}, std::pair{s2, chord / 2}}) {
    JointSpec joint;
    joint.type = JointType::kPin;
    joint.a.cable = it->second;
    joint.a.s_m = arc;
    joint.b.body = i;
    joint.b.point_body_m = Eigen::Vector3d(x, 0, 0);
    state->threaded_joints.push_back(joint);
  }
  return absl::OkStatus();
}

absl::Status ConvertBody(ConversionState* state, int i, BodySpec* body) {
  const v1::Body& b = state->proto.bodies(i);
  const std::string path = Indexed("", "bodies", i);
  CABLESIM_RETURN_IF_ERROR(
      RegisterName(Sub(path, "name"), "bodies", b.name(), i, &state->body_index));
  body->name = b.name();

  if (b.has_cylinder()) {
    if (b.has_mass()) {
      return Invalid(Sub(path, "mass"),
                     "give either cylinder + density or mass + inertia, not both");
    }
    if (b.has_inertia()) {
      return Invalid(Sub(path, "inertia"),
                     "follows from the cylinder; give inertia only with mass");
    }
    const std::string cylinder_path = Sub(path, "cylinder");
    const double d = b.cylinder().diameter();
    const double h = b.cylinder().height();
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(cylinder_path, "diameter"), d, plausible::kSize));
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(cylinder_path, "height"), h, plausible::kSize));
    if (!b.has_density()) return Invalid(Sub(path, "density"), "required with cylinder");
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "density"), b.density(), plausible::kDensity));
    const double m = b.density() * kPi * d * d / 4 * h;
    const double r = d / 2;
    const double transverse = m * (3 * r * r + h * h) / 12;
    body->mass_kg = m;
    body->inertia_kg_m2 = Eigen::Vector3d(m * d * d / 8, transverse, transverse);
    if (!std::isfinite(m) || !(m > 0) || !body->inertia_kg_m2.allFinite() ||
        !(body->inertia_kg_m2.minCoeff() > 0)) {
      return Invalid(cylinder_path, "mass or inertia out of range");
    }
  } else if (b.has_mass()) {
    if (b.has_density()) {
      return Invalid(Sub(path, "density"),
                     "only with cylinder (give either cylinder + density or mass + inertia)");
    }
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "mass"), b.mass(), plausible::kMass));
    body->mass_kg = b.mass();
    const std::string inertia_path = Sub(path, "inertia");
    CABLESIM_ASSIGN_OR_RETURN(body->inertia_kg_m2, FiniteVector(inertia_path, b.inertia()));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(inertia_path, "x"), b.inertia().x()));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(inertia_path, "y"), b.inertia().y()));
    CABLESIM_RETURN_IF_ERROR(CheckPositive(Sub(inertia_path, "z"), b.inertia().z()));
    CABLESIM_RETURN_IF_ERROR(
        VectorInRange(inertia_path, b.inertia(), plausible::kInertia).status());
  } else if (b.has_density()) {
    return Invalid(Sub(path, "cylinder"), "required with density");
  } else {
    return Invalid(Sub(path, "mass"), "required (give cylinder + density, or mass + inertia)");
  }

  if (b.has_seabed_contact()) CABLESIM_RETURN_IF_ERROR(ConvertBodyContact(path, b, body));
  CABLESIM_RETURN_IF_ERROR(ConvertBodyHydrodynamics(*state, i, b, body));
  // Damping before the placement: a body placed `on` a cable returns
  // from there (its damping was silently dropped before).
  if (b.has_damping()) {
    const std::string damping_path = Sub(path, "damping");
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(damping_path, "linear"), b.damping().linear()));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(damping_path, "angular"), b.damping().angular()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, "linear"), b.damping().linear(),
                                        plausible::kDampingCoefficient));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, "angular"), b.damping().angular(),
                                        plausible::kDampingCoefficient));
    body->linear_damping_n_s_m = b.damping().linear();
    body->angular_damping_n_m_s = b.damping().angular();
  }
  body->coupled = b.coupled();
  if (b.has_on()) return PlaceOnCable(state, i, b);
  CABLESIM_ASSIGN_OR_RETURN(
      body->position_m, VectorInRange(Sub(path, "position"), b.position(), plausible::kCoordinate));
  body->axis = Eigen::Vector3d::UnitX();
  if (b.has_axis()) {
    CABLESIM_ASSIGN_OR_RETURN(body->axis, Direction(Sub(path, "axis"), b.axis()));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ConvertBodies(ConversionState* state) {
  state->scene.bodies.resize(state->proto.bodies_size());
  for (int i = 0; i < state->proto.bodies_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(ConvertBody(state, i, &state->scene.bodies[i]));
  }
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
