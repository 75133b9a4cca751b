#include "server/energy_report.h"

#include <algorithm>
#include <cmath>

#include "convert/run_proto.h"

namespace cablesim {

v1::EnergyResponse EnergyFromTrajectory(const v1::RunHeader& header,
                                        const std::vector<double>& values,
                                        const v1::RunSummary& summary) {
  v1::EnergyResponse response;
  *response.mutable_summary() = summary;
  const int columns = header.columns_size();
  v1::EnergyReport* report = response.mutable_report();
  report->set_energy_dissipated(summary.energy_dissipated());
  report->set_energy_damped(summary.energy_damped());
  if (columns < 1 + kTrailingValues) return response;
  const size_t rows = values.size() / columns;
  // The trailing columns: kinetic, potential, axial, bending, total,
  // violation, damped.
  const int e0 = columns - kTrailingValues;
  double scale = 0, lo = INFINITY, hi = -INFINITY, violation = 0;
  for (size_t r = 0; r < rows; ++r) {
    const double* row = values.data() + r * columns;
    response.add_t(row[0]);
    response.add_kinetic(row[e0]);
    response.add_potential(row[e0 + 1]);
    response.add_axial(row[e0 + 2]);
    response.add_bending(row[e0 + 3]);
    response.add_total(row[e0 + 4]);
    response.add_constraint_violation(row[e0 + 5]);
    response.add_damped(row[e0 + 6]);
    scale = std::max(scale, row[e0] + row[e0 + 2] + row[e0 + 3]);
    lo = std::min(lo, row[e0 + 4]);
    hi = std::max(hi, row[e0 + 4]);
    violation = std::max(violation, row[e0 + 5]);
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
