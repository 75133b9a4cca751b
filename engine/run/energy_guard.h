#ifndef CABLESIM_ENGINE_RUN_ENERGY_GUARD_H_
#define CABLESIM_ENGINE_RUN_ENERGY_GUARD_H_

// The dynamic run's energy guard. Every scene conserves its total energy
// plus the work done against damping (gravity and constant loads are
// potential; the work of torques, time-varying loads, moving supports and
// winches is counted in the total, MultibodyModel::Energy), so that sum never rises
// for the exact solution, and a
// stepper may lose energy (backward Euler's numerical damping) but a rise
// means it is unstable at this step (or Newton found a spurious root, such
// as an element folded through itself, which Green-Lagrange strain does
// not see). A state fails the guard when
//   total + damped - E(0) > kRiseLimit * scale + floor,
// scale being the largest energy term seen so far or in this state
// (kinetic, potential, strain) and floor the model's rounding of the
// energy (MultibodyModel::energy_roundoff). A winch's work is summed as
// the moving supports' (MultibodyModel::ExternalPower).

#include <algorithm>
#include <cmath>

#include "engine/output/results.h"

namespace cablesim {

class EnergyGuard {
 public:
  // Rises beyond this fraction of the largest energy term fail a run.
  static constexpr double kRiseLimit = 0.05;
  // A converged step is checked at once (and taken back) when Newton
  // needed at least this many iterations.
  static constexpr int kCheckAfterNewtonIterations = 4;

  EnergyGuard(bool enabled, double energy_initial, double floor)
      : enabled_(enabled), initial_(energy_initial), floor_(floor) {}

  bool enabled() const { return enabled_; }

  // The rise of e above the start [J], and the scale it is judged against
  // (`scale_seen`: the largest energy term of the frames so far).
  double Rise(const EnergySample& e) const { return e.total + e.damped - initial_; }
  static double Scale(const EnergySample& e, double scale_seen) {
    return std::max({scale_seen, std::abs(e.kinetic), std::abs(e.potential),
                     std::abs(e.axial) + std::abs(e.bending)});
  }
  // Whether e fails the guard (never when disabled).
  bool Fails(const EnergySample& e, double scale_seen) const {
    return enabled_ && Rise(e) > kRiseLimit * Scale(e, scale_seen) + floor_;
  }

 private:
  bool enabled_;
  double initial_;
  double floor_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_ENERGY_GUARD_H_
