#include "server/energy_report.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

// The column of each named quantity of a trajectory, or -1.
class Columns {
 public:
  explicit Columns(const v1::RunHeader& header) {
    for (int i = 0; i < header.columns_size(); ++i) index_.emplace(header.columns(i), i);
  }
  int operator()(const std::string& name) const {
    const auto it = index_.find(name);
    return it == index_.end() ? -1 : it->second;
  }

 private:
  absl::flat_hash_map<std::string, int> index_;
};

}  // namespace

v1::EnergyResponse EnergyFromTrajectory(const v1::RunHeader& header,
                                        const std::vector<double>& values,
                                        const v1::RunSummary& summary) {
  v1::EnergyResponse response;
  *response.mutable_summary() = summary;
  const int columns = header.columns_size();
  v1::EnergyReport* report = response.mutable_report();
  report->set_energy_dissipated(summary.energy_dissipated());
  report->set_energy_damped(summary.energy_damped());
  // Every column by name (a trajectory stored before a column was added
  // lacks it; the columns after the totals have grown).
  const Columns find(header);
  const int t = find("t"), kinetic = find("energy.kinetic"), potential = find("energy.potential"),
            axial = find("energy.axial"), bending = find("energy.bending"),
            total = find("energy.total"), violation_column = find("constraint.violation");
  if (columns < 1 || t < 0 || kinetic < 0 || potential < 0 || axial < 0 || bending < 0 ||
      total < 0 || violation_column < 0) {
    return response;
  }
  // The parts: a series per cable and body whose columns are all there.
  struct Part {
    v1::PartEnergySeries* series;
    int kinetic, gravity, axial, bending;
  };
  std::vector<Part> parts;
  auto add_parts = [&](const char* kind, const auto& names, bool strain,
                       google::protobuf::RepeatedPtrField<v1::PartEnergySeries>* out) {
    for (int i = 0; i < names.size(); ++i) {
      const std::string prefix = absl::StrCat(kind, "[", i, "].energy.");
      Part p{nullptr, find(prefix + "kinetic"), find(prefix + "gravity"),
             strain ? find(prefix + "axial") : -1, strain ? find(prefix + "bending") : -1};
      if (p.kinetic < 0 || p.gravity < 0 || (strain && (p.axial < 0 || p.bending < 0))) return;
      p.series = out->Add();
      p.series->set_name(names[i]);
      p.series->set_index(i);
      parts.push_back(p);
    }
  };
  add_parts("cables", header.info().cable_names(), true, response.mutable_cables());
  add_parts("bodies", header.info().body_names(), false, response.mutable_bodies());
  const int loads = find("loads.energy.potential");
  const int damped = find("energy.damped");
  const size_t rows = values.size() / columns;
  double scale = 0, lo = INFINITY, hi = -INFINITY, violation = 0;
  for (size_t r = 0; r < rows; ++r) {
    const double* row = values.data() + r * columns;
    response.add_t(row[t]);
    response.add_kinetic(row[kinetic]);
    response.add_potential(row[potential]);
    response.add_axial(row[axial]);
    response.add_bending(row[bending]);
    response.add_total(row[total]);
    response.add_constraint_violation(row[violation_column]);
    if (damped >= 0) response.add_damped(row[damped]);
    scale = std::max(scale, row[kinetic] + row[axial] + row[bending]);
    lo = std::min(lo, row[total]);
    hi = std::max(hi, row[total]);
    violation = std::max(violation, row[violation_column]);
    for (const Part& p : parts) {
      p.series->add_kinetic(row[p.kinetic]);
      p.series->add_gravity(row[p.gravity]);
      if (p.axial >= 0) p.series->add_axial(row[p.axial]);
      if (p.bending >= 0) p.series->add_bending(row[p.bending]);
    }
    if (loads >= 0) response.add_loads(row[loads]);
  }
  if (rows == 0) return response;
  const double initial = response.total(0);
  const double final = response.total(static_cast<int>(rows) - 1);
  report->set_initial(initial);
  report->set_final(final);
  report->set_min(lo);
  report->set_max(hi);
  report->set_scale(scale);
  report->set_relative_drift(scale > 0 ? (final - initial) / scale : 0.0);
  report->set_max_constraint_violation(violation);
  return response;
}

}  // namespace cablesim
