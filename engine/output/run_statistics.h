#ifndef CABLESIM_ENGINE_OUTPUT_RUN_STATISTICS_H_
#define CABLESIM_ENGINE_OUTPUT_RUN_STATISTICS_H_

// What a cable engineer reads off a run, computed as it goes: per frame
// column (engine/output/frame_columns.h, found by name, so that columns
// added later are covered without change) the minimum and maximum with
// their times, the mean and the standard deviation (output.statistics), and
// rainflow cycle counts with a damage-equivalent load on chosen columns
// (output.rainflow).
//
// Rainflow counting follows ASTM E1049-85 (reapproved 2017), "Standard
// Practices for Cycle Counting in Fatigue Analysis", section 5.4.4: the
// series is reduced to its peaks and valleys, then
//   1. read the next peak or valley (none left: step 6);
//   2. with fewer than three points, go to 1; else X is the range of the
//      last two points, Y that of the two before;
//   3. X < Y: go to 1;
//   4. Y holds the starting point S: go to 5; else count Y as one cycle,
//      discard its two points and go to 2;
//   5. count Y as a half cycle, discard its first point (S moves to its
//      second) and go to 2;
//   6. count every range not yet counted as a half cycle.
// The damage-equivalent load of counts n_i of ranges S_i, for an S-N
// curve N S^m = const and Miner's rule, is the range that N_eq cycles
// would need to do the same damage:
//   DEL = (sum_i n_i S_i^m / N_eq)^(1/m).

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "engine/output/results.h"
#include "engine/scene/scene.h"

namespace cablesim {

// One counted range: `count` is 1 or 0.5.
struct RainflowCycle {
  double range = 0;
  double mean = 0;
  double count = 0;
};

// Counts a series value by value (ASTM E1049-85 5.4.4, above), keeping
// only the peaks and valleys not yet counted. Counted ranges are summed into
// cycles(), max_range() and damage_sum() (sum n S^m for the slope given)
// and, when a list is given, appended to it.
class RainflowCounter {
 public:
  explicit RainflowCounter(double sn_slope = 1, std::vector<RainflowCycle>* cycles = nullptr);

  void Add(double value);
  // Counts the residue as half cycles; then the counter is spent.
  void Finish();

  double cycles() const { return cycles_; }
  double half_cycles() const { return half_cycles_; }
  double max_range() const { return max_range_; }
  double damage_sum() const { return damage_sum_; }

 private:
  void Turn(double point);  // a peak or valley: steps 2 to 5
  void Count(double a, double b, double count);

  double sn_slope_;
  std::vector<RainflowCycle>* list_;
  std::vector<double> stack_;  // peaks and valleys not yet counted; S first
  bool started_ = false;
  double candidate_ = 0;  // the extreme of the current rise or fall
  int direction_ = 0;     // +1 rising, -1 falling, 0 not yet known
  double cycles_ = 0, half_cycles_ = 0, max_range_ = 0, damage_sum_ = 0;
};

// The counted ranges of `series` (RainflowCounter), in counting order.
std::vector<RainflowCycle> CountRainflow(absl::Span<const double> series);

// (damage_sum / equivalent_cycles)^(1/sn_slope), damage_sum = sum n S^m.
double DamageEquivalentLoad(double damage_sum, double sn_slope, double equivalent_cycles);
double DamageEquivalentLoad(absl::Span<const RainflowCycle> cycles, double sn_slope,
                            double equivalent_cycles);

// Whether `output` asks for statistics or rainflow counts.
inline bool WantsStatistics(const OutputSpec& output) {
  return output.statistics || !output.rainflow.columns.empty();
}

// InvalidArgument naming `field` unless `name` is a column of the frames
// of a model with `info` (engine/output/frame_columns.h; `t` and the shape
// columns are not).
absl::Status CheckStatisticsColumn(const ModelInfo& info, const std::string& name,
                                   const std::string& field);

// Checks output.statistics and output.rainflow against the model built:
// every rainflow column exists and is named once, sn_slope and
// equivalent_cycles are finite and > 0. InvalidArgument naming the field.
absl::Status CheckStatisticsSpec(const OutputSpec& output, const ModelInfo& info,
                                 bool modal);

// A FrameSink in front of another: keeps the statistics of every frame
// column and the rainflow counts of the chosen ones, then passes the frame
// on. Allocates in OnStart only (and when a rainflow residue outgrows the
// room reserved for it, which a bounded signal does not).
class StatisticsSink : public FrameSink {
 public:
  StatisticsSink(FrameSink* next, const OutputSpec& output);

  absl::Status OnStart(const ModelInfo& info) override;
  absl::Status OnFrame(const Frame& frame) override;
  bool wants_angular_momentum() const override {
    return next_ != nullptr && next_->wants_angular_momentum();
  }

  // The statistics of the frames so far (the rainflow residue counted).
  RunStatistics Finish();

 private:
  FrameSink* next_;
  OutputSpec output_;
  std::vector<std::string> names_;  // frame columns, `t` first
  std::vector<double> row_;
  int64_t count_ = 0;
  // Per column: Welford's running mean and sum of squared deviations.
  std::vector<double> min_, min_t_, max_, max_t_, mean_, m2_;
  std::vector<int> rainflow_column_;
  std::vector<RainflowCounter> counters_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_OUTPUT_RUN_STATISTICS_H_
