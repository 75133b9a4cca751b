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

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_RUN_CONTROL_H_
