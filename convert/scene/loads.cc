#include "convert/scene/sections.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"

namespace cablesim::scene_convert {
namespace {

bool IsProbeNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

absl::Status ConvertLoad(const ConversionState& state, int i, LoadSpec* load) {
  const v1::Load& l = state.proto.loads(i);
  const std::string path = Indexed("", "loads", i);
  CABLESIM_ASSIGN_OR_RETURN(load->at, ConvertAttachment(state, Sub(path, "at"), l.at(), false));
  CABLESIM_ASSIGN_OR_RETURN(load->force_n,
                            VectorInRange(Sub(path, "force"), l.force(), plausible::kForce));
  const std::string torque_path = Sub(path, "torque");
  CABLESIM_ASSIGN_OR_RETURN(load->torque_nm,
                            VectorInRange(torque_path, l.torque(), plausible::kTorque));
  if (load->at.cable >= 0) {
    if (!load->torque_nm.isZero(0)) return Invalid(torque_path, "allowed on bodies only");
  }
  if (l.has_varying_force()) {
    CABLESIM_ASSIGN_OR_RETURN(
        load->varying_force_n,
        ConvertTimeVector(Sub(path, "varying_force"), l.varying_force(), plausible::kForce));
  }
  if (l.has_varying_torque()) {
    const std::string varying_torque = Sub(path, "varying_torque");
    CABLESIM_ASSIGN_OR_RETURN(
        load->varying_torque_nm,
        ConvertTimeVector(varying_torque, l.varying_torque(), plausible::kTorque));
    if (load->at.cable >= 0 && !IsZero(load->varying_torque_nm))
      return Invalid(varying_torque, "allowed on bodies only");
  }
  return absl::OkStatus();
}

absl::Status ConvertProbe(ConversionState* state, int i, ProbeSpec* probe) {
  const v1::Probe& p = state->proto.probes(i);
  const std::string path = Indexed("", "probes", i);
  const std::string name_path = Sub(path, "name");
  CABLESIM_RETURN_IF_ERROR(CheckNameLength(name_path, p.name()));
  if (!p.name().empty() && !std::all_of(p.name().begin(), p.name().end(), IsProbeNameChar)) {
    return Invalid(name_path, absl::StrCat("\"", p.name(),
                                           "\" may contain only letters, digits, '_', '-' "
                                           "and '.'"));
  }
  CABLESIM_RETURN_IF_ERROR(RegisterName(name_path, "probes", p.name(), i, &state->probe_index));
  probe->name = p.name();
  v1::Attachment at;
  at.set_cable(p.cable());
  at.set_s(p.s());
  at.set_body(p.body());
  if (p.has_point()) *at.mutable_point() = p.point();
  CABLESIM_ASSIGN_OR_RETURN(probe->at, ConvertAttachment(*state, path, at, false));
  return absl::OkStatus();
}

}  // namespace

absl::Status ConvertLoads(ConversionState* state) {
  state->scene.loads.resize(state->proto.loads_size());
  for (int i = 0; i < state->proto.loads_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(ConvertLoad(*state, i, &state->scene.loads[i]));
  }
  return absl::OkStatus();
}

absl::Status ConvertProbes(ConversionState* state) {
  state->scene.probes.resize(state->proto.probes_size());
  for (int i = 0; i < state->proto.probes_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(ConvertProbe(state, i, &state->scene.probes[i]));
  }
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
