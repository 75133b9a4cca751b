#include "convert/scene/sections.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/scene_from_proto.h"

namespace cablesim::scene_convert {
namespace {

constexpr int kDefaultElements = 10;
constexpr int kMaxElements = 100000;

// The polyline's corner at points[corner], between the segment from the
// point before it and the segment to `next`, must not fold the cable back.
absl::Status CheckCorner(absl::string_view cable_path, int corner,
                         const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& next) {
  const Eigen::Vector3d in = points[corner] - points[corner - 1];
  const Eigen::Vector3d out = next - points[corner];
  const double cosine = in.dot(out) / (in.norm() * out.norm());
  const double turn_degrees = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / kPi;
  if (!(turn_degrees <= plausible::kMaxCornerTurnDegrees)) {
    return Invalid(Indexed(cable_path, "points", corner),
                   absl::StrFormat("the polyline folds back at this corner (turns by %.1f "
                                   "degrees; at most %g)",
                                   turn_degrees, plausible::kMaxCornerTurnDegrees));
  }
  return absl::OkStatus();
}

// The tension-strain table of axial_law TABLE (scene.proto TensionTable)
// into the cable's knots, the origin (0, 0) first.
absl::Status ConvertTensionTable(const std::string& path, const v1::TensionTable& t,
                                 CableSpec* cable) {
  const auto& strains = t.strains();
  const auto& tensions = t.tensions();
  if (strains.empty()) return Invalid(Sub(path, "strains"), "must have at least one entry");
  if (tensions.size() != strains.size()) {
    return Invalid(Sub(path, "tensions"),
                   absl::StrCat("must have as many entries as strains (", strains.size(),
                                "; got ", tensions.size(), ")"));
  }
  cable->tension_table_strains = {0.0};
  cable->tension_table_tensions = {0.0};
  for (int k = 0; k < strains.size(); ++k) {
    const std::string strain = Indexed(path, "strains", k);
    const std::string tension = Indexed(path, "tensions", k);
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(strain, strains[k]));
    CABLESIM_RETURN_IF_ERROR(CheckRange(strain, strains[k], plausible::kStrain));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(tension, tensions[k]));
    CABLESIM_RETURN_IF_ERROR(CheckRange(tension, tensions[k], plausible::kForce));
    if (strains[k] == 0) {
      if (k > 0) {
        return Invalid(Sub(path, "strains"),
                       absl::StrCat("strains must increase (strains[", k, "] = 0 after ",
                                    Num(strains[k - 1]), ")"));
      }
      if (tensions[k] != 0) {
        return Invalid(tension, absl::StrCat("must be 0 at zero strain (got ", Num(tensions[k]),
                                             " N): a line is unloaded unstretched"));
      }
      continue;  // the origin, already there
    }
    if (!(strains[k] > cable->tension_table_strains.back())) {
      return Invalid(Sub(path, "strains"),
                     absl::StrCat("strains must increase (strains[", k, "] = ", Num(strains[k]),
                                  " after ", Num(strains[k - 1]), ")"));
    }
    if (tensions[k] < cable->tension_table_tensions.back()) {
      return Invalid(Sub(path, "tensions"),
                     absl::StrCat("tensions must not decrease (tensions[", k,
                                  "] = ", Num(tensions[k]), " after ",
                                  Num(cable->tension_table_tensions.back()),
                                  "): the line would soften into instability"));
    }
    cable->tension_table_strains.push_back(strains[k]);
    cable->tension_table_tensions.push_back(tensions[k]);
  }
  if (!(cable->tension_table_tensions.back() > 0)) {
    return Invalid(Sub(path, "tensions"), "must not all be 0 (the line would have no stiffness)");
  }
  return absl::OkStatus();
}

absl::Status ConvertCable(ConversionState* state, int i, CableSpec* cable) {
  const v1::Cable& c = state->proto.cables(i);
  const std::string path = Indexed("", "cables", i);
  CABLESIM_RETURN_IF_ERROR(
      RegisterName(Sub(path, "name"), "cables", c.name(), i, &state->cable_index));
  cable->name = c.name();

  cable->elements = c.has_elements() ? c.elements() : kDefaultElements;
  CABLESIM_RETURN_IF_ERROR(CheckIntRange(Sub(path, "elements"), cable->elements, 1, kMaxElements));
  if (c.has_gauss_points()) {
    CABLESIM_RETURN_IF_ERROR(CheckIntRange(Sub(path, "gauss_points"), c.gauss_points(),
                                           CableSpec::kMinGaussPoints,
                                           CableSpec::kMaxGaussPoints));
    // Measured (tests/cable_statics_test.cc's slack V, 24 and 12 elements,
    // bending NONE): 4 points found an asymmetric equilibrium, its sag 1.9 %
    // off the catenary; 3 hang within 6e-4 of it, 5 to 8 within 2e-6.
    if (c.gauss_points() == 4) {
      return Invalid(Sub(path, "gauss_points"),
                     "4 is refused: with 4 points a slack line without bending found a "
                     "spurious, asymmetric equilibrium (sag 1.9 % off the catenary); use 3 or 5 "
                     "to 8");
    }
    // The winch's own terms on its paid-out element integrate with 5.
    if (c.has_winch() && c.gauss_points() != cable->gauss_points) {
      return Invalid(Sub(path, "gauss_points"),
                     absl::StrCat("a cable with a winch keeps the default ", cable->gauss_points,
                                  " (its winch terms are integrated with those)"));
    }
    cable->gauss_points = c.gauss_points();
  }

  // Geometry: a polyline, or start + direction * length.
  if (c.points_size() > 0) {
    if (c.has_start()) return Invalid(Sub(path, "start"), "give either start/direction or points");
    if (c.has_direction()) {
      return Invalid(Sub(path, "direction"), "give either start/direction or points");
    }
    if (c.points_size() < 2) {
      return Invalid(Sub(path, "points"),
                     absl::StrCat("needs at least 2 points (got ", c.points_size(), ")"));
    }
    double polyline_length = 0;
    for (int j = 0; j < c.points_size(); ++j) {
      const std::string point_path = Indexed(path, "points", j);
      CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d p,
                                VectorInRange(point_path, c.points(j), plausible::kCoordinate));
      if (j > 0) {
        const Eigen::Vector3d& previous = cable->points.back();
        const double segment = (p - previous).norm();
        const double scale = std::max(p.norm(), previous.norm());
        if (!(segment > 1e-12 * scale) || segment == 0) {
          return Invalid(point_path, absl::StrCat("same as points[", j - 1,
                                                  "] (consecutive points must differ)"));
        }
        if (j > 1) CABLESIM_RETURN_IF_ERROR(CheckCorner(path, j - 1, cable->points, p));
        polyline_length += segment;
      }
      cable->points.push_back(p);
    }
    if (!(polyline_length >= plausible::kCableLength.lo &&
          polyline_length <= plausible::kCableLength.hi)) {
      return Invalid(
          Sub(path, "points"),
          absl::StrCat("polyline length must be in [", Num(plausible::kCableLength.lo), ", ",
                       Num(plausible::kCableLength.hi), "] m (got ", Num(polyline_length), ")"));
    }
    if (c.has_length()) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "length"), c.length(), plausible::kCableLength));
      cable->length_m = c.length();
    } else {
      cable->length_m = polyline_length;
    }
  } else {
    CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d start,
                              VectorInRange(Sub(path, "start"), c.start(), plausible::kCoordinate));
    Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
    if (c.has_direction()) {
      CABLESIM_ASSIGN_OR_RETURN(direction, Direction(Sub(path, "direction"), c.direction()));
    }
    if (!c.has_length()) return Invalid(Sub(path, "length"), "required (or give points)");
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "length"), c.length(), plausible::kCableLength));
    cable->length_m = c.length();
    cable->points = {start, Eigen::Vector3d(start + direction * cable->length_m)};
  }

  CABLESIM_RETURN_IF_ERROR(
      CheckPositiveInRange(Sub(path, "density"), c.density(), plausible::kDensity));
  cable->density_kg_m3 = c.density();
  // With a tension-strain table youngs_modulus may be omitted (it then
  // follows from the table, below).
  const bool modulus_from_table = c.axial_law() == v1::TABLE && c.youngs_modulus() == 0;
  if (!modulus_from_table) {
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "youngs_modulus"),
                                                  c.youngs_modulus(), plausible::kYoungsModulus));
  }
  cable->youngs_modulus_pa = c.youngs_modulus();

  if (c.has_diameter()) {
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "diameter"), c.diameter(), plausible::kSize));
  }
  const double d = c.diameter();
  if (c.has_area()) {
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "area"), c.area(), plausible::kArea));
    cable->area_m2 = c.area();
  } else if (c.has_diameter()) {
    cable->area_m2 = kPi * d * d / 4;
  } else {
    return Invalid(Sub(path, "area"), "required (give area or diameter)");
  }

  CABLESIM_ASSIGN_OR_RETURN(cable->bending, BendingFromProto(c.bending(), Sub(path, "bending")));
  const bool no_bending = cable->bending == BendingModel::kNone;
  if (c.has_second_moment()) {
    const std::string moment_path = Sub(path, "second_moment");
    CABLESIM_RETURN_IF_ERROR(no_bending ? CheckNonNegative(moment_path, c.second_moment())
                                        : CheckPositive(moment_path, c.second_moment()));
    if (c.second_moment() != 0) {
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(moment_path, c.second_moment(), plausible::kSecondMoment));
    }
    cable->second_moment_m4 = c.second_moment();
  } else if (c.has_diameter()) {
    cable->second_moment_m4 = kPi * d * d * d * d / 64;
  } else if (no_bending) {
    cable->second_moment_m4 = 0;
  } else {
    return Invalid(Sub(path, "second_moment"),
                   "required unless bending is NONE (give second_moment or diameter)");
  }
  if (!std::isfinite(cable->area_m2) || !(cable->area_m2 > 0) ||
      !std::isfinite(cable->second_moment_m4)) {
    return Invalid(Sub(path, "diameter"), "section properties out of range");
  }
  if (c.has_hydrodynamics()) {
    const v1::Hydrodynamics& h = c.hydrodynamics();
    const std::string hydro_path = Sub(path, "hydrodynamics");
    if (!(state->proto.fluid().density() > 0)) {
      return Invalid(hydro_path, "needs a fluid around the cables (fluid.density > 0)");
    }
    for (const auto& [name, value, out] :
         {std::tuple{"normal_drag", h.normal_drag(), &cable->normal_drag},
          std::tuple{"tangential_drag", h.tangential_drag(), &cable->tangential_drag},
          std::tuple{"added_mass", h.added_mass(), &cable->added_mass}}) {
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(hydro_path, name), value));
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(Sub(hydro_path, name), value, plausible::kHydroCoefficient));
      *out = value;
    }
    if (h.has_axial_added_mass()) {
      const std::string axial_path = Sub(hydro_path, "axial_added_mass");
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(axial_path, h.axial_added_mass()));
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(axial_path, h.axial_added_mass(), plausible::kHydroCoefficient));
      cable->has_axial_added_mass = true;
      cable->axial_added_mass = h.axial_added_mass();
    }
    if (h.has_diameter()) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(hydro_path, "diameter"), h.diameter(), plausible::kSize));
      cable->hydro_diameter_m = h.diameter();
    }
    for (int end = 0; end < 2; ++end) {
      const v1::TipLoad& tip = end == 0 ? h.start_tip() : h.end_tip();
      const std::string tip_path = Sub(hydro_path, end == 0 ? "start_tip" : "end_tip");
      const std::string area_path = Sub(tip_path, "drag_area");
      const std::string mass_path = Sub(tip_path, "added_mass");
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(area_path, tip.drag_area()));
      CABLESIM_RETURN_IF_ERROR(CheckRange(area_path, tip.drag_area(), plausible::kDragArea));
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(mass_path, tip.added_mass()));
      CABLESIM_RETURN_IF_ERROR(CheckRange(mass_path, tip.added_mass(), plausible::kMassOrZero));
      if ((tip.drag_area() != 0 || tip.added_mass() != 0) && c.has_winch()) {
        return Invalid(tip_path, "a tip load on a winch cable is not modelled (its end nodes "
                                 "move with the mesh, not the material)");
      }
      cable->tip_drag_area_m2[end] = tip.drag_area();
      cable->tip_added_mass_kg[end] = tip.added_mass();
    }
  }
  switch (c.axial_law()) {
    case v1::AXIAL_LAW_UNSPECIFIED:
    case v1::GREEN_LAGRANGE:
      cable->axial_law = AxialLaw::kGreenLagrange;
      break;
    case v1::ENGINEERING:
      cable->axial_law = AxialLaw::kEngineering;
      break;
    case v1::TABLE:
      cable->axial_law = AxialLaw::kTable;
      break;
    case v1::VISCOELASTIC:
      cable->axial_law = AxialLaw::kViscoelastic;
      break;
    default:
      return Invalid(Sub(path, "axial_law"),
                     absl::StrCat("unknown value ", c.axial_law(),
                                  " (must be GREEN_LAGRANGE, ENGINEERING, TABLE or "
                                  "VISCOELASTIC)"));
  }
  if (cable->axial_law == AxialLaw::kViscoelastic) {
    const std::string vpath = Sub(path, "viscoelastic");
    if (!c.has_viscoelastic()) return Invalid(vpath, "required with axial_law VISCOELASTIC");
    const v1::Viscoelastic& v = c.viscoelastic();
    const double ea = cable->youngs_modulus_pa * cable->area_m2;
    auto stiffer = [&](const std::string& field, double value) -> absl::Status {
      CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(vpath, field), value));
      if (!(value > ea)) {
        return Invalid(Sub(vpath, field),
                       absl::StrCat("must exceed the static EA, youngs_modulus * area = ", Num(ea),
                                    " N (got ", Num(value), "): the dynamic stiffness is the "
                                    "stiffer one"));
      }
      return absl::OkStatus();
    };
    if (v.has_dynamic_ea()) {
      if (v.has_dynamic_ea_base() || v.has_dynamic_ea_slope()) {
        return Invalid(Sub(vpath, v.has_dynamic_ea_base() ? "dynamic_ea_base" : "dynamic_ea_slope"),
                       "not with dynamic_ea (a constant dynamic stiffness or the mean-load law, "
                       "not both)");
      }
      CABLESIM_RETURN_IF_ERROR(stiffer("dynamic_ea", v.dynamic_ea()));
      cable->visco_dynamic_ea_n = v.dynamic_ea();
    } else {
      if (!v.has_dynamic_ea_base() || !v.has_dynamic_ea_slope()) {
        return Invalid(Sub(vpath, v.has_dynamic_ea_base() ? "dynamic_ea_slope" : "dynamic_ea_base"),
                       "required: give dynamic_ea, or dynamic_ea_base and dynamic_ea_slope");
      }
      CABLESIM_RETURN_IF_ERROR(stiffer("dynamic_ea_base", v.dynamic_ea_base()));
      CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(vpath, "dynamic_ea_slope"), v.dynamic_ea_slope()));
      CABLESIM_RETURN_IF_ERROR(
          CheckNonNegative(Sub(vpath, "dynamic_ea_slope"), v.dynamic_ea_slope()));
      cable->visco_dynamic_ea_base_n = v.dynamic_ea_base();
      cable->visco_dynamic_ea_slope = v.dynamic_ea_slope();
    }
    CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(vpath, "static_damping"), v.static_damping()));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(vpath, "static_damping"), v.static_damping()));
    CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(vpath, "dynamic_damping"), v.dynamic_damping()));
    CABLESIM_RETURN_IF_ERROR(
        CheckNonNegative(Sub(vpath, "dynamic_damping"), v.dynamic_damping()));
    if (!(v.static_damping() + v.dynamic_damping() > 0)) {
      return Invalid(Sub(vpath, "static_damping"),
                     "static_damping + dynamic_damping must be > 0 (without a dashpot the two "
                     "springs in series are one spring: use axial_law ENGINEERING)");
    }
    cable->visco_static_damping_ns = v.static_damping();
    cable->visco_dynamic_damping_ns = v.dynamic_damping();
  } else if (c.has_viscoelastic()) {
    return Invalid(Sub(path, "viscoelastic"), "only with axial_law VISCOELASTIC");
  }
  if (cable->axial_law == AxialLaw::kTable) {
    if (!c.has_tension_table()) {
      return Invalid(Sub(path, "tension_table"), "required with axial_law TABLE");
    }
    CABLESIM_RETURN_IF_ERROR(
        ConvertTensionTable(Sub(path, "tension_table"), c.tension_table(), cable));
    if (modulus_from_table) {
      // The table's steepest slope as the nominal EA.
      double stiffest = 0;
      for (size_t k = 1; k < cable->tension_table_strains.size(); ++k) {
        stiffest = std::max(stiffest, (cable->tension_table_tensions[k] -
                                       cable->tension_table_tensions[k - 1]) /
                                          (cable->tension_table_strains[k] -
                                           cable->tension_table_strains[k - 1]));
      }
      cable->youngs_modulus_pa = stiffest / cable->area_m2;
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "youngs_modulus"),
                                                    cable->youngs_modulus_pa,
                                                    plausible::kYoungsModulus));
    }
  } else if (c.has_tension_table()) {
    return Invalid(Sub(path, "tension_table"), "only with axial_law TABLE");
  }
  // A bed of its own: checked for a seabed in ConvertScene (after ConvertSeabed).
  if (c.has_seabed_stiffness()) {
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "seabed_stiffness"),
                                                  c.seabed_stiffness(), plausible::kStiffness));
    cable->seabed_stiffness_n_m2 = c.seabed_stiffness();
  }
  if (c.has_seabed_damping()) {
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "seabed_damping"), c.seabed_damping()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "seabed_damping"), c.seabed_damping(),
                                        plausible::kDampingCoefficient));
    cable->seabed_damping_n_s_m2 = c.seabed_damping();
  }
  if (c.has_winch()) {
    if (cable->axial_law != AxialLaw::kGreenLagrange) {
      return Invalid(Sub(path, "axial_law"),
                     absl::StrCat(cable->axial_law == AxialLaw::kTable          ? "TABLE"
                                  : cable->axial_law == AxialLaw::kViscoelastic ? "VISCOELASTIC"
                                                                                : "ENGINEERING",
                                  " is not available on a cable with a winch (its line tension "
                                  "is the Green-Lagrange law's)"));
    }
    cable->winch.enabled = true;
    CABLESIM_ASSIGN_OR_RETURN(
        cable->winch.speed, ConvertTimeFunction(Sub(Sub(path, "winch"), "speed"), c.winch().speed(),
                                                plausible::kVelocity));
    if (cable->winch.speed.HasProduct()) {
      return Invalid(Sub(Sub(path, "winch"), "speed"),
                     "a product is not available in a winch's speed (the free length is the "
                     "speed's integral, exact for the other parts only)");
    }
  }
  if (c.has_damping()) {
    const v1::CableDamping& d = c.damping();
    const std::string damping_path = Sub(path, "damping");
    for (const auto& [name, value, out, range] :
         {std::tuple{"axial_time", d.axial_time(), &cable->axial_damping_s,
                     &plausible::kDampingTime},
          std::tuple{"bending_time", d.bending_time(), &cable->bending_damping_s,
                     &plausible::kDampingTime},
          std::tuple{"rayleigh_alpha", d.rayleigh_alpha(), &cable->rayleigh_alpha_1_s,
                     &plausible::kRayleighAlpha},
          std::tuple{"rayleigh_beta", d.rayleigh_beta(), &cable->rayleigh_beta_s,
                     &plausible::kDampingTime}}) {
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(damping_path, name), value));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, name), value, *range));
      *out = value;
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ConvertCables(ConversionState* state) {
  const v1::Scene& proto = state->proto;
  if (proto.cables_size() == 0 && proto.bodies_size() == 0) {
    return Invalid("cables", "a scene needs at least one cable or body");
  }
  state->scene.cables.resize(proto.cables_size());
  for (int i = 0; i < proto.cables_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(ConvertCable(state, i, &state->scene.cables[i]));
  }
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
