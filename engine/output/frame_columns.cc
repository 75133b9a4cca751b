#include "engine/output/frame_columns.h"

#include <string_view>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"

namespace cablesim {

std::vector<std::string> FrameColumns(const ModelInfo& info, bool with_nodes) {
  std::vector<std::string> columns = {"t"};
  for (const std::string& name : info.probe_names) {
    for (const char* c : {"x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"}) {
      columns.push_back(absl::StrCat(name, ".", c));
    }
  }
  for (const char* c : {"energy.kinetic", "energy.potential", "energy.axial", "energy.bending",
                        "energy.total", "constraint.violation", "energy.damped"}) {
    columns.push_back(c);
  }
  for (size_t i = 0; i < info.cable_names.size(); ++i) {
    for (const char* c : {"kinetic", "gravity", "axial", "bending"}) {
      columns.push_back(absl::StrCat("cables[", i, "].energy.", c));
    }
  }
  for (size_t i = 0; i < info.body_names.size(); ++i) {
    for (const char* c : {"kinetic", "gravity"}) {
      columns.push_back(absl::StrCat("bodies[", i, "].energy.", c));
    }
  }
  columns.push_back("loads.energy.potential");
  for (const std::string& name : info.force_probe_names) {
    for (const char* c : {"fx", "fy", "fz"}) columns.push_back(absl::StrCat(name, ".", c));
  }
  if (info.contact) columns.push_back("energy.contact");
  for (size_t i = 0; i < info.joint_reaction_values.size(); ++i) {
    const int n = info.joint_reaction_values[i];
    if (n >= 3)
      for (const char* c : {"fx", "fy", "fz"}) columns.push_back(absl::StrCat("joints[", i, "].", c));
    if (n >= 6)
      for (const char* c : {"mx", "my", "mz"}) columns.push_back(absl::StrCat("joints[", i, "].", c));
  }
  for (const std::string& name : info.tension_probe_names) columns.push_back(name + ".tension");
  if (info.body_orientation) {
    for (size_t i = 0; i < info.body_names.size(); ++i) {
      for (const char* c : {"qw", "qx", "qy", "qz", "roll", "pitch", "yaw", "wx", "wy", "wz"}) {
        columns.push_back(absl::StrCat("bodies[", i, "].", c));
      }
    }
  }
  for (const std::string& name : info.bending_moment_probe_names) {
    columns.push_back(name + ".bending_moment");
  }
  for (const int j : info.release_joints)
    columns.push_back(absl::StrCat("joints[", j, "].released"));
  if (!info.shape || !with_nodes) return columns;
  for (size_t i = 0; i < info.cable_nodes.size(); ++i) {
    for (int k = 0; k < info.cable_nodes[i]; ++k) {
      for (const char* c : {"x", "y", "z"}) {
        columns.push_back(absl::StrCat("cables[", i, "].nodes[", k, "].", c));
      }
    }
  }
  if (!info.node_tension) return columns;
  for (size_t i = 0; i < info.cable_nodes.size(); ++i) {
    for (int k = 0; k < info.cable_nodes[i]; ++k) {
      columns.push_back(absl::StrCat("cables[", i, "].nodes[", k, "].tension"));
    }
  }
  return columns;
}

int FrameReader::Find(absl::Span<const std::string> columns, const std::string& name) {
  for (size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return static_cast<int>(i);
  }
  return -1;
}

FrameReader::FrameReader(const ModelInfo& info, absl::Span<const std::string> columns)
    : row_size_(static_cast<int>(columns.size())),
      probes_(static_cast<int>(info.probe_names.size())),
      cables_(static_cast<int>(info.cable_names.size())),
      bodies_(static_cast<int>(info.body_names.size())),
      forces_(static_cast<int>(info.force_probe_names.size())),
      nodes_(info.shape ? static_cast<int>(info.node_s.size()) : 0),
      contact_(info.contact),
      reaction_values_(info.joint_reaction_values),
      tension_probes_(static_cast<int>(info.tension_probe_names.size())),
      node_tension_(info.shape && info.node_tension),
      orientation_values_(info.body_orientation ? 10 * static_cast<int>(info.body_names.size())
                                                : 0),
      bending_moment_probes_(static_cast<int>(info.bending_moment_probe_names.size())),
      release_joints_(static_cast<int>(info.release_joints.size())) {
  absl::flat_hash_map<std::string_view, int> column;
  for (size_t i = 0; i < columns.size(); ++i) column.emplace(columns[i], static_cast<int>(i));
  for (const std::string& name : FrameColumns(info)) {
    const auto it = column.find(name);
    index_.push_back(it == column.end() ? -1 : it->second);
  }
}

void FrameReader::Read(absl::Span<const double> row, Frame* frame) const {
  frame->probes.resize(probes_);
  frame->energy_parts.cables.resize(cables_);
  frame->energy_parts.bodies.resize(bodies_);
  frame->support_forces.resize(forces_);
  frame->nodes.resize(nodes_);
  frame->has_contact = contact_;
  frame->probe_tensions.resize(tension_probes_);
  frame->node_tensions.resize(node_tension_ ? nodes_ : 0);
  frame->body_orientation.resize(orientation_values_);
  frame->probe_bending_moments.resize(bending_moment_probes_);
  frame->joint_released.resize(release_joints_);
  frame->reactions.resize(reaction_values_.size());
  for (size_t j = 0; j < reaction_values_.size(); ++j)
    frame->reactions[j].values = reaction_values_[j];
  size_t k = 0;
  auto read = [&](double& value) {
    const int i = index_[k++];
    value = i >= 0 && static_cast<size_t>(i) < row.size() ? row[i] : 0.0;
  };
  ForEachFrameValue(*frame, read);
  ForEachNodeValue(*frame, read);
}

}  // namespace cablesim
