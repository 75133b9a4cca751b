#ifndef CABLESIM_ENGINE_SCENE_RUN_CONTROL_H_
#define CABLESIM_ENGINE_SCENE_RUN_CONTROL_H_

#include <cstdint>
#include <functional>

namespace cablesim {

// How a caller bounds and stops a run (a server's limits, deadlines and
// cancellation). Both are checked before every step (or load increment).
struct RunControl {
  // Returns true to stop: the summary's status becomes "cancelled" and every
  // frame up to the last converged step has been delivered.
  std::function<bool()> should_stop;
  // Largest number of step attempts, accepted and rejected (0: no limit);
  // beyond it the run stops with status "failed" and says so.
  int64_t max_steps = 0;
};

// Asks a RunControl's should_stop from inside a step's costly loops (the
// element forces over Gauss points and wave components, so also every
// Newton iteration) without paying for a call each time: work is counted
// in units (one Gauss point of one element, times one plus the wave
// components summed there) and should_stop is asked once every
// kUnitsPerAsk units, about a millisecond of work. Once it said stop the
// poll stays stopped, and the model makes the rest of the step's forces
// not-a-number so that the step fails at once and the run reports
// "cancelled" (MultibodyModel::set_stop_poll).
class StopPoll {
 public:
  static constexpr int64_t kUnitsPerAsk = int64_t{1} << 16;
  // `should_stop` (may be empty) must outlive the poll.
  explicit StopPoll(const std::function<bool()>& should_stop) : should_stop_(should_stop) {}
  // Counts `units` of work done; true when the run should stop.
  bool Poll(int64_t units) {
    if (stopped_) return true;
    if ((budget_ -= units) > 0) return false;
    budget_ = kUnitsPerAsk;
    stopped_ = should_stop_ && should_stop_();
    return stopped_;
  }
  bool stopped() const { return stopped_; }

 private:
  const std::function<bool()>& should_stop_;
  int64_t budget_ = kUnitsPerAsk;
  bool stopped_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_RUN_CONTROL_H_
