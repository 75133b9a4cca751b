#include "engine/output/run_statistics.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "engine/output/frame_columns.h"

namespace cablesim {

RainflowCounter::RainflowCounter(double sn_slope, std::vector<RainflowCycle>* cycles)
    : sn_slope_(sn_slope), list_(cycles) {
  stack_.reserve(64);
}

void RainflowCounter::Add(double value) {
  if (!started_) {
    started_ = true;
    candidate_ = value;
    return;
  }
  if (direction_ == 0) {
    if (value == candidate_) return;
    Turn(candidate_);  // the series' first point
    direction_ = value > candidate_ ? 1 : -1;
    candidate_ = value;
    return;
  }
  if ((value - candidate_) * direction_ >= 0) {
    candidate_ = value;  // the rise or fall goes on
    return;
  }
  Turn(candidate_);  // it turned back: a peak or a valley
  direction_ = -direction_;
  candidate_ = value;
}

void RainflowCounter::Turn(double point) {
  stack_.push_back(point);
  while (stack_.size() >= 3) {
    const size_t n = stack_.size();
    const double x = std::abs(stack_[n - 1] - stack_[n - 2]);
    const double y = std::abs(stack_[n - 2] - stack_[n - 3]);
    if (x < y) return;
    if (n == 3) {
      // Y holds the starting point: a half cycle, S moves on.
      Count(stack_[0], stack_[1], 0.5);
      stack_.erase(stack_.begin());
    } else {
      Count(stack_[n - 3], stack_[n - 2], 1.0);
      stack_[n - 3] = stack_[n - 1];
      stack_.resize(n - 2);
    }
  }
}

void RainflowCounter::Finish() {
  if (direction_ != 0) Turn(candidate_);  // the series' last point
  for (size_t i = 0; i + 1 < stack_.size(); ++i) Count(stack_[i], stack_[i + 1], 0.5);
  stack_.clear();
  started_ = false;
  direction_ = 0;
}

void RainflowCounter::Count(double a, double b, double count) {
  const double range = std::abs(b - a);
  cycles_ += count;
  if (count < 1) half_cycles_ += 1;
  max_range_ = std::max(max_range_, range);
  damage_sum_ += count * std::pow(range, sn_slope_);
  if (list_ != nullptr) list_->push_back({range, 0.5 * (a + b), count});
}

std::vector<RainflowCycle> CountRainflow(absl::Span<const double> series) {
  std::vector<RainflowCycle> cycles;
  RainflowCounter counter(1, &cycles);
  for (double v : series) counter.Add(v);
  counter.Finish();
  return cycles;
}

double DamageEquivalentLoad(double damage_sum, double sn_slope, double equivalent_cycles) {
  return std::pow(damage_sum / equivalent_cycles, 1 / sn_slope);
}

double DamageEquivalentLoad(absl::Span<const RainflowCycle> cycles, double sn_slope,
                            double equivalent_cycles) {
  double sum = 0;
  for (const RainflowCycle& c : cycles) sum += c.count * std::pow(c.range, sn_slope);
  return DamageEquivalentLoad(sum, sn_slope, equivalent_cycles);
}

absl::Status CheckStatisticsColumn(const ModelInfo& info, const std::string& name,
                                   const std::string& field) {
  const std::vector<std::string> columns = FrameColumns(info, /*with_nodes=*/false);
  if (name != "t" && FrameReader::Find(columns, name) >= 0) return absl::OkStatus();
  std::string known;
  for (size_t i = 1; i < columns.size() && i <= 12; ++i) {
    absl::StrAppend(&known, i > 1 ? ", " : "", columns[i]);
  }
  if (columns.size() > 13) absl::StrAppend(&known, ", ...");
  return absl::InvalidArgumentError(
      absl::StrCat(field, ": no frame column \"", name, "\" in this scene (columns: ", known,
                   "; see docs/outputs-statistics.md)"));
}

absl::Status CheckStatisticsSpec(const OutputSpec& output, const ModelInfo& info, bool modal) {
  if (!WantsStatistics(output)) {
    const RainflowSpec& r = output.rainflow;
    if (r.sn_slope != 0 || r.equivalent_cycles != 0) {
      return absl::InvalidArgumentError(
          "output.rainflow.columns: empty (name the columns to count, or leave rainflow out)");
    }
    return absl::OkStatus();
  }
  if (modal) {
    return absl::InvalidArgumentError(
        absl::StrCat(output.statistics ? "output.statistics" : "output.rainflow",
                     ": not for a MODAL analysis (its frames are mode shapes, not a history)"));
  }
  const RainflowSpec& r = output.rainflow;
  if (r.columns.empty()) return absl::OkStatus();
  for (size_t i = 0; i < r.columns.size(); ++i) {
    const std::string field = absl::StrCat("output.rainflow.columns[", i, "]");
    if (absl::Status s = CheckStatisticsColumn(info, r.columns[i], field); !s.ok()) return s;
    for (size_t j = 0; j < i; ++j) {
      if (r.columns[j] == r.columns[i]) {
        return absl::InvalidArgumentError(absl::StrCat(field, ": \"", r.columns[i],
                                                       "\" is named twice (also columns[", j,
                                                       "])"));
      }
    }
  }
  if (!std::isfinite(r.sn_slope) || !(r.sn_slope > 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "output.rainflow.sn_slope: must be a number > 0 (the S-N curve's slope m), got ",
        r.sn_slope));
  }
  if (!std::isfinite(r.equivalent_cycles) || !(r.equivalent_cycles > 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "output.rainflow.equivalent_cycles: must be a number > 0 (the reference cycle count "
        "N_eq, e.g. 1e7), got ",
        r.equivalent_cycles));
  }
  return absl::OkStatus();
}

StatisticsSink::StatisticsSink(FrameSink* next, const OutputSpec& output)
    : next_(next), output_(output) {}

absl::Status StatisticsSink::OnStart(const ModelInfo& info) {
  names_ = FrameColumns(info, /*with_nodes=*/false);
  const size_t n = names_.size();
  row_.assign(n, 0.0);
  count_ = 0;
  if (output_.statistics) {
    min_.assign(n, 0.0);
    min_t_.assign(n, 0.0);
    max_.assign(n, 0.0);
    max_t_.assign(n, 0.0);
    mean_.assign(n, 0.0);
    m2_.assign(n, 0.0);
  }
  rainflow_column_.clear();
  counters_.clear();
  for (const std::string& name : output_.rainflow.columns) {
    const int k = FrameReader::Find(names_, name);
    if (k < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("output.rainflow.columns: no frame column \"", name, "\""));
    }
    rainflow_column_.push_back(k);
    counters_.emplace_back(output_.rainflow.sn_slope);
  }
  return next_ != nullptr ? next_->OnStart(info) : absl::OkStatus();
}

absl::Status StatisticsSink::OnFrame(const Frame& frame) {
  size_t k = 0;
  const size_t n = row_.size();
  ForEachFrameValue(frame, [&](double v) {
    if (k < n) row_[k] = v;
    ++k;
  });
  ++count_;
  if (output_.statistics) {
    const double t = frame.t;
    const double inv = 1.0 / static_cast<double>(count_);
    for (size_t i = 1; i < n; ++i) {
      const double v = row_[i];
      if (count_ == 1 || v < min_[i]) {
        min_[i] = v;
        min_t_[i] = t;
      }
      if (count_ == 1 || v > max_[i]) {
        max_[i] = v;
        max_t_[i] = t;
      }
      const double delta = v - mean_[i];
      mean_[i] += delta * inv;
      m2_[i] += delta * (v - mean_[i]);
    }
  }
  for (size_t r = 0; r < counters_.size(); ++r) counters_[r].Add(row_[rainflow_column_[r]]);
  return next_ != nullptr ? next_->OnFrame(frame) : absl::OkStatus();
}

RunStatistics StatisticsSink::Finish() {
  RunStatistics s;
  if (output_.statistics && count_ > 0) {
    for (size_t i = 1; i < names_.size(); ++i) {
      ColumnStatistics c;
      c.column = names_[i];
      c.count = count_;
      c.min = min_[i];
      c.min_t = min_t_[i];
      c.max = max_[i];
      c.max_t = max_t_[i];
      c.mean = mean_[i];
      c.stddev = std::sqrt(std::max(0.0, m2_[i] / static_cast<double>(count_)));
      s.columns.push_back(std::move(c));
    }
  }
  if (!counters_.empty()) {
    s.sn_slope = output_.rainflow.sn_slope;
    s.equivalent_cycles = output_.rainflow.equivalent_cycles;
  }
  for (size_t r = 0; r < counters_.size(); ++r) {
    RainflowCounter& counter = counters_[r];
    counter.Finish();
    RainflowStatistics f;
    f.column = output_.rainflow.columns[r];
    f.cycles = counter.cycles();
    f.half_cycles = counter.half_cycles();
    f.max_range = counter.max_range();
    f.damage_equivalent_load = DamageEquivalentLoad(
        counter.damage_sum(), output_.rainflow.sn_slope, output_.rainflow.equivalent_cycles);
    s.rainflow.push_back(std::move(f));
  }
  return s;
}

}  // namespace cablesim
