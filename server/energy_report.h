#ifndef CABLESIM_SERVER_ENERGY_REPORT_H_
#define CABLESIM_SERVER_ENERGY_REPORT_H_

// Energy diagnostics of a trajectory: the time series of every energy
// component [J] and the report (service.proto, EnergyReport):
//   E = kinetic + potential + axial + bending,
//   relative_drift = (E_final - E_initial) / scale,
//   scale = max over frames of (kinetic + axial + bending),
// and the series of each cable and body (EnergyParts, engine/run/simulation.h).

#include <vector>

#include "cablesim/v1/service.pb.h"

namespace cablesim {

// `values` are rows in the header's columns (engine/output/frame_columns.h),
// found by name: a trajectory stored before the energy per part was
// recorded has no part series.
v1::EnergyResponse EnergyFromTrajectory(const v1::RunHeader& header,
                                        const std::vector<double>& values,
                                        const v1::RunSummary& summary);

}  // namespace cablesim

#endif  // CABLESIM_SERVER_ENERGY_REPORT_H_
