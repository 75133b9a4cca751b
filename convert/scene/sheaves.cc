#include "convert/scene/sections.h"

#include <algorithm>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"

namespace cablesim::scene_convert {

absl::Status ConvertSheaves(ConversionState* state) {
  constexpr int kMaxSheaves = 64;  // MultibodyModel keeps a 64-bit mask per element
  if (state->proto.sheaves_size() > kMaxSheaves)
    return Invalid("sheaves", absl::StrCat("at most ", kMaxSheaves, " (got ",
                                           state->proto.sheaves_size(), ")"));
  for (int i = 0; i < state->proto.sheaves_size(); ++i) {
    const v1::Sheave& w = state->proto.sheaves(i);
    const std::string path = absl::StrCat("sheaves[", i, "]");
    SheaveSpec spec;
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "name"), w.name()));
    spec.name = w.name();
    if (!w.body().empty()) {
      CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "body"), w.body()));
      const auto it = state->body_index.find(w.body());
      if (it == state->body_index.end())
        return Invalid(Sub(path, "body"), absl::StrCat("no body named \"", w.body(), "\""));
      spec.body = it->second;
      if (w.has_position())
        return Invalid(Sub(path, "position"),
                       "not with body (the wheel is centred on the body's centre of mass)");
    }
    CABLESIM_ASSIGN_OR_RETURN(spec.position_m, FiniteVector(Sub(path, "position"), w.position()));
    for (int k = 0; k < 3; ++k)
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(Sub(path, "position"), spec.position_m(k), plausible::kCoordinate));
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "radius"), w.radius(), plausible::kSize));
    spec.radius_m = w.radius();
    if (w.has_axis()) {
      CABLESIM_ASSIGN_OR_RETURN(spec.axis, Direction(Sub(path, "axis"), w.axis()));
    }
    for (int c = 0; c < w.cables_size(); ++c) {
      const std::string cable_path = absl::StrCat(path, ".cables[", c, "]");
      CABLESIM_RETURN_IF_ERROR(CheckNameLength(cable_path, w.cables(c)));
      const auto it = state->cable_index.find(w.cables(c));
      if (it == state->cable_index.end())
        return Invalid(cable_path, absl::StrCat("no cable named \"", w.cables(c), "\""));
      spec.cables.push_back(it->second);
    }
    if (w.has_stiffness()) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "stiffness"), w.stiffness(), plausible::kStiffness));
      spec.stiffness_n_m2 = w.stiffness();
    } else {
      // EA / R^2 of the stiffest cable it touches: a cable under
      // tension T = eps EA sinks p = T / (k R) = eps R into it.
      double ea = 0;
      for (int c = 0; c < static_cast<int>(state->scene.cables.size()); ++c) {
        if (!spec.Touches(c)) continue;
        ea =
            std::max(ea, state->scene.cables[c].youngs_modulus_pa * state->scene.cables[c].area_m2);
      }
      if (!(ea > 0)) return Invalid(Sub(path, "stiffness"), "must be given (no cable to touch)");
      spec.stiffness_n_m2 = ea / (spec.radius_m * spec.radius_m);
    }
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "damping"), w.damping()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(path, "damping"), w.damping(), plausible::kDampingCoefficient));
    spec.damping_n_s_m2 = w.damping();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "friction"), w.friction()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(path, "friction"), w.friction(), plausible::kFrictionCoefficient));
    spec.friction = w.friction();
    if (w.has_friction_speed()) {
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "friction_speed"), w.friction_speed(),
                                                    plausible::kFrictionSpeed));
      spec.friction_speed_m_s = w.friction_speed();
    }
    state->scene.sheaves.push_back(std::move(spec));
  }
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
