#ifndef CABLESIM_ENGINE_OUTPUT_FRAME_COLUMNS_H_
#define CABLESIM_ENGINE_OUTPUT_FRAME_COLUMNS_H_

// The columns of a frame row, the one layout shared by the CSV of
// `cablesim run --out` (client/csv_writer.h) and the service's frame rows
// (convert/run_proto.h, FrameBatch):
//
//   t
//   per probe NAME.x NAME.y NAME.z NAME.vx NAME.vy NAME.vz NAME.ax NAME.ay NAME.az
//   energy.kinetic energy.potential energy.axial energy.bending energy.total
//   constraint.violation energy.damped
//   per cable i  cables[i].energy.kinetic cables[i].energy.gravity
//                cables[i].energy.axial cables[i].energy.bending
//   per body j   bodies[j].energy.kinetic bodies[j].energy.gravity
//   loads.energy.potential
//   per probe on a moving support (ModelInfo::force_probe_names)
//                NAME.fx NAME.fy NAME.fz
//   with a seabed (ModelInfo::contact)  energy.contact
//   with output.reactions, per joint i (ModelInfo::joint_reaction_values)
//                joints[i].fx joints[i].fy joints[i].fz
//                and for FIXED joints[i].mx joints[i].my joints[i].mz
//   with output.tension, per probe on a cable (ModelInfo::tension_probe_names)
//                NAME.tension
//   with output.orientation (ModelInfo::body_orientation), per body i
//                bodies[i].qw .qx .qy .qz .roll .pitch .yaw .wx .wy .wz
//   with output.bending_moment, per probe on a cable
//                (ModelInfo::bending_moment_probe_names)  NAME.bending_moment
//   per joint i that may let go (ModelInfo::release_joints, a scene
//                joint with a `release`)  joints[i].released: 0 while it
//                holds, 1 from the release on
//   with output.shape (ModelInfo::shape), per cable i and node k
//                cables[i].nodes[k].x cables[i].nodes[k].y cables[i].nodes[k].z
//   with output.shape and output.tension (ModelInfo::node_tension), per
//   cable i and node k  cables[i].nodes[k].tension
//
// (EnergyParts, output/results.h). Parts are named by their index in the scene
// file, as field paths are (`cables[1].length`): a cable's name is free
// text (it may hold a comma) and a cable and a body may share a name; the
// names are in ModelInfo (cable_names, body_names) in the same order.
//
// Columns are only ever added after the existing ones, and whatever reads a
// row back finds its columns by name (FrameReader), so a reader keeps
// working on rows written before or after a column was added.

#include <string>
#include <vector>

#include "absl/types/span.h"
#include "engine/output/results.h"

namespace cablesim {

// Numbers per probe, per cable and per body in a row.
inline constexpr int kValuesPerProbe = 9;
inline constexpr int kValuesPerCable = 4;
inline constexpr int kValuesPerBody = 2;
// The totals, the constraint violation and the damped work after the probes.
inline constexpr int kTotalValues = 7;

// The column names of a frame row of a model with `info`'s probes, cables
// and bodies, and its nodes when info.shape and `with_nodes` (the run CSV
// leaves them out: `cablesim run --shape` writes them in a file of their
// own, client/shape_csv_writer.h).
std::vector<std::string> FrameColumns(const ModelInfo& info, bool with_nodes = true);

// The numbers in a row.
// `force_probes` are the probes on a moving support (3 numbers each).
// `contact`: the scene has a seabed (one more number, energy.contact).
inline int64_t FrameRowSize(int64_t probes, int64_t cables, int64_t bodies,
                            int64_t force_probes = 0, bool contact = false) {
  return 1 + kValuesPerProbe * probes + kTotalValues + kValuesPerCable * cables +
         kValuesPerBody * bodies + 1 + 3 * force_probes + (contact ? 1 : 0);
}

// Calls add(value) for every number of `frame`'s row, in column order.
// `FrameT` is Frame or const Frame: add receives the numbers by reference
// (FrameReader fills a frame through the same order).
template <typename FrameT, typename Add>
void ForEachFrameValue(FrameT& frame, Add&& add) {
  add(frame.t);
  for (auto& p : frame.probes) {
    for (int k = 0; k < 3; ++k) add(p.position_m[k]);
    for (int k = 0; k < 3; ++k) add(p.velocity_m_s[k]);
    for (int k = 0; k < 3; ++k) add(p.acceleration_m_s2[k]);
  }
  auto& e = frame.energy;
  add(e.kinetic);
  add(e.potential);
  add(e.axial);
  add(e.bending);
  add(e.total);
  add(frame.constraint_violation);
  add(e.damped);
  for (auto& c : frame.energy_parts.cables) {
    add(c.kinetic);
    add(c.gravity);
    add(c.axial);
    add(c.bending);
  }
  for (auto& b : frame.energy_parts.bodies) {
    add(b.kinetic);
    add(b.gravity);
  }
  add(frame.energy_parts.loads);
  for (auto& f : frame.support_forces) {
    for (int k = 0; k < 3; ++k) add(f[k]);
  }
  if (frame.has_contact) add(e.contact);
  for (auto& r : frame.reactions) {
    if (r.values < 3) continue;
    for (int k = 0; k < 3; ++k) add(r.force[k]);
    if (r.values < 6) continue;
    for (int k = 0; k < 3; ++k) add(r.moment[k]);
  }
  for (auto& t : frame.probe_tensions) add(t);
  for (auto& o : frame.body_orientation) add(o);
  for (auto& m : frame.probe_bending_moments) add(m);
  for (auto& r : frame.joint_released) add(r);
}

// Calls add(value) for x, y, z of every node of `frame` (empty without
// output.shape): the row's last columns, after ForEachFrameValue's.
template <typename FrameT, typename Add>
void ForEachNodeValue(FrameT& frame, Add&& add) {
  for (auto& r : frame.nodes) {
    for (int k = 0; k < 3; ++k) add(r[k]);
  }
  for (auto& t : frame.node_tensions) add(t);
}

// Reads frames back from rows whose columns are known by name: each
// quantity of a Frame is looked up in the column names once, and a column
// that is absent (a row written before it was added) reads as 0.
class FrameReader {
 public:
  // The quantities of `info` (probes, cables and bodies) in rows of
  // `columns`.
  FrameReader(const ModelInfo& info, absl::Span<const std::string> columns);

  // The number of values in a row (the number of column names).
  int row_size() const { return row_size_; }

  // Fills `frame` from one row of row_size() numbers (its vectors are
  // resized; no allocation once they have the size).
  void Read(absl::Span<const double> row, Frame* frame) const;

  // The column of `name`, or -1.
  static int Find(absl::Span<const std::string> columns, const std::string& name);

 private:
  int row_size_ = 0;
  int probes_ = 0, cables_ = 0, bodies_ = 0, forces_ = 0, nodes_ = 0;
  bool contact_ = false;
  std::vector<int> reaction_values_;
  int tension_probes_ = 0;
  bool node_tension_ = false;
  int orientation_values_ = 0;
  int bending_moment_probes_ = 0;
  int release_joints_ = 0;
  // The column of every number of ForEachFrameValue's and then
  // ForEachNodeValue's order, or -1.
  std::vector<int> index_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_OUTPUT_FRAME_COLUMNS_H_
