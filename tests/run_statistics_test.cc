// Statistics of a run (engine/output/run_statistics.h): column statistics
// of constructed frame series against closed forms, rainflow counting
// against ASTM E1049-85's own example, the damage-equivalent load against a
// hand computation, and a real run's statistics against its frames.

#include "engine/output/run_statistics.h"

#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "engine/output/frame_columns.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using ::cablesim::testing::CollectingSink;
using ::cablesim::testing::SampleScene;

// Sums of ranges per range value, for comparing with a table.
std::map<double, double> CountsByRange(const std::vector<RainflowCycle>& cycles) {
  std::map<double, double> counts;
  for (const RainflowCycle& c : cycles) counts[c.range] += c.count;
  return counts;
}

// ASTM E1049-85 (reapproved 2017), Fig. 6 "Rainflow Counting Example": the
// history A..I = -2, 1, -3, 5, -1, 3, -4, 4, -2 (load units), and the
// table of Fig. 6(e): range 3: 0.5 cycles, 4: 1.5, 6: 0.5, 8: 1.0, 9: 0.5
// (ranges 1, 2, 5, 7, 10: none). Counts are exact (halves).
TEST(Rainflow, AstmFigure6Example) {
  const std::vector<double> history = {-2, 1, -3, 5, -1, 3, -4, 4, -2};
  const std::vector<RainflowCycle> cycles = CountRainflow(history);
  const std::map<double, double> expected = {{3, 0.5}, {4, 1.5}, {6, 0.5}, {8, 1.0}, {9, 0.5}};
  EXPECT_EQ(CountsByRange(cycles), expected);
  // Fig. 6 (b) to (d) step by step: A-B half, B-C half, E-F full (mean 1),
  // C-D half, then the residue D-G, G-H, H-I as halves.
  ASSERT_EQ(cycles.size(), 7u);
  EXPECT_EQ(cycles[2].range, 4);
  EXPECT_EQ(cycles[2].count, 1.0);
  EXPECT_EQ(cycles[2].mean, 1.0);
}

// The same history sampled finely (points between the turning points, and
// a plateau) counts the same: only peaks and valleys matter.
TEST(Rainflow, IntermediatePointsAndPlateausAreNotTurningPoints) {
  const std::vector<double> turning = {-2, 1, -3, 5, -1, 3, -4, 4, -2};
  std::vector<double> fine;
  for (size_t i = 0; i + 1 < turning.size(); ++i) {
    for (int k = 0; k < 4; ++k) fine.push_back(turning[i] + (turning[i + 1] - turning[i]) * k / 4);
    if (i == 3) fine.push_back(turning[i + 1]);  // a plateau at D
  }
  fine.push_back(turning.back());
  EXPECT_EQ(CountsByRange(CountRainflow(fine)), CountsByRange(CountRainflow(turning)));
  // A constant series has no cycle; one rise is one half cycle.
  EXPECT_TRUE(CountRainflow(std::vector<double>{2, 2, 2}).empty());
  const std::vector<RainflowCycle> rise = CountRainflow(std::vector<double>{0, 1, 3});
  ASSERT_EQ(rise.size(), 1u);
  EXPECT_EQ(rise[0].range, 3);
  EXPECT_EQ(rise[0].count, 0.5);
}

// DEL = (sum n_i S_i^m / N_eq)^(1/m) on Fig. 6's counts, by hand for m = 3:
// 0.5*27 + 1.5*64 + 0.5*216 + 1.0*512 + 0.5*729 = 1094.
TEST(Rainflow, DamageEquivalentLoadByHand) {
  const std::vector<RainflowCycle> cycles =
      CountRainflow(std::vector<double>{-2, 1, -3, 5, -1, 3, -4, 4, -2});
  EXPECT_NEAR(DamageEquivalentLoad(cycles, 3, 1), std::cbrt(1094.0), 1e-12);
  EXPECT_NEAR(DamageEquivalentLoad(cycles, 3, 1e7), std::cbrt(1094.0 / 1e7), 1e-15);
  // m = 1: the mean range weighted by counts, times cycles / N_eq:
  // 0.5*3 + 1.5*4 + 0.5*6 + 8 + 0.5*9 = 23.
  EXPECT_NEAR(DamageEquivalentLoad(cycles, 1, 2), 11.5, 1e-12);
  RainflowCounter counter(3);
  for (double v : {-2, 1, -3, 5, -1, 3, -4, 4, -2}) counter.Add(v);
  counter.Finish();
  EXPECT_EQ(counter.damage_sum(), 1094);
  EXPECT_EQ(counter.cycles(), 4.0);       // 0.5 + 1.5 + 0.5 + 1 + 0.5
  EXPECT_EQ(counter.half_cycles(), 6.0);  // all but E-F
  EXPECT_EQ(counter.max_range(), 9);
}

// A model of one probe "p" on a moving support (so that p.fz exists).
ModelInfo OneProbeInfo() {
  ModelInfo info;
  info.model = "planar";
  info.probe_names = {"p"};
  info.force_probe_names = {"p"};
  return info;
}

Frame FrameAt(double t, double x, double z, double fz) {
  Frame f;
  f.t = t;
  f.probes.resize(1);
  f.probes[0].position_m = {x, 0, z};
  f.support_forces = {Eigen::Vector3d(0, 0, fz)};
  return f;
}

// x = A sin(2 pi t / T) sampled N times evenly over whole periods (N a
// multiple of 4): mean 0, population variance A^2 / 2 exactly (the sums of
// sin and sin^2 over a period's N points are 0 and N/2), max A at T/4, min
// -A at 3T/4. z = k (k = 0..N-1): mean (N-1)/2, variance (N^2-1)/12.
// Tolerance: rounding of N terms, 1e-12 relative.
TEST(StatisticsSink, KnownSignalsAgainstClosedForms) {
  const double amplitude = 2.5, period = 0.8;
  const int n = 400;  // five periods of 80 frames
  OutputSpec output;
  output.statistics = true;
  CollectingSink next;
  StatisticsSink sink(&next, output);
  ASSERT_TRUE(sink.OnStart(OneProbeInfo()).ok());
  for (int k = 0; k < n; ++k) {
    const double t = k * 5 * period / n;
    ASSERT_TRUE(sink.OnFrame(FrameAt(t, amplitude * std::sin(2 * std::numbers::pi * t / period),
                                     k, 0))
                    .ok());
  }
  EXPECT_EQ(next.frames().size(), static_cast<size_t>(n));  // passed on
  const RunStatistics s = sink.Finish();
  std::map<std::string, ColumnStatistics> by_name;
  for (const ColumnStatistics& c : s.columns) by_name[c.column] = c;
  // Every column but t, in column order.
  const std::vector<std::string> columns = FrameColumns(OneProbeInfo(), false);
  ASSERT_EQ(s.columns.size(), columns.size() - 1);
  EXPECT_EQ(s.columns.front().column, columns[1]);
  const ColumnStatistics& x = by_name.at("p.x");
  EXPECT_EQ(x.count, n);
  EXPECT_NEAR(x.mean, 0, 1e-12 * amplitude);
  EXPECT_NEAR(x.stddev, amplitude / std::sqrt(2.0), 1e-12 * amplitude);
  EXPECT_NEAR(x.max, amplitude, 1e-12 * amplitude);
  EXPECT_NEAR(x.max_t, period / 4, 1e-12);  // first reached in the first period
  EXPECT_NEAR(x.min, -amplitude, 1e-12 * amplitude);
  EXPECT_NEAR(x.min_t, 3 * period / 4, 1e-12);
  const ColumnStatistics& z = by_name.at("p.z");
  EXPECT_NEAR(z.mean, (n - 1) / 2.0, 1e-12 * n);
  EXPECT_NEAR(z.stddev, std::sqrt((n * n - 1.0) / 12.0), 1e-12 * n);
  EXPECT_EQ(z.min, 0);
  EXPECT_EQ(z.min_t, 0);
  EXPECT_EQ(z.max, n - 1);
  EXPECT_NEAR(z.max_t, (n - 1) * 5 * period / n, 1e-12);
  const ColumnStatistics& y = by_name.at("p.y");
  EXPECT_EQ(y.stddev, 0);
  EXPECT_TRUE(s.rainflow.empty());
}

// Rainflow through the sink on a support force column: Fig. 6's history
// as p.fz gives the hand-computed DEL.
TEST(StatisticsSink, RainflowOnAColumn) {
  OutputSpec output;
  output.rainflow.columns = {"p.fz"};
  output.rainflow.sn_slope = 3;
  output.rainflow.equivalent_cycles = 10;
  StatisticsSink sink(nullptr, output);
  ASSERT_TRUE(sink.OnStart(OneProbeInfo()).ok());
  double t = 0;
  for (double v : {-2, 1, -3, 5, -1, 3, -4, 4, -2}) ASSERT_TRUE(sink.OnFrame(FrameAt(t++, 0, 0, v)).ok());
  const RunStatistics s = sink.Finish();
  EXPECT_TRUE(s.columns.empty());  // output.statistics is off
  ASSERT_EQ(s.rainflow.size(), 1u);
  EXPECT_EQ(s.rainflow[0].column, "p.fz");
  EXPECT_EQ(s.rainflow[0].cycles, 4.0);
  EXPECT_EQ(s.rainflow[0].max_range, 9);
  EXPECT_NEAR(s.rainflow[0].damage_equivalent_load, std::cbrt(109.4), 1e-12);
  EXPECT_EQ(s.sn_slope, 3);
  EXPECT_EQ(s.equivalent_cycles, 10);
}

TEST(StatisticsSpec, EveryFieldIsChecked) {
  const ModelInfo info = OneProbeInfo();
  auto error = [&](const OutputSpec& o, bool modal = false) {
    const absl::Status s = CheckStatisticsSpec(o, info, modal);
    EXPECT_TRUE(s.ok() || s.code() == absl::StatusCode::kInvalidArgument) << s;
    return s.ok() ? std::string("ok") : std::string(s.message());
  };
  OutputSpec o;
  o.statistics = true;
  EXPECT_EQ(error(o), "ok");
  EXPECT_EQ(error(o, true).rfind("output.statistics: not for a MODAL", 0), 0u) << error(o, true);
  o.rainflow = {{"p.fz", "p.x"}, 3, 1e7};
  EXPECT_EQ(error(o), "ok");
  o.rainflow.columns = {"p.fz", "top.fz"};
  EXPECT_EQ(error(o).rfind("output.rainflow.columns[1]: no frame column \"top.fz\"", 0), 0u)
      << error(o);
  o.rainflow.columns = {"t"};
  EXPECT_EQ(error(o).rfind("output.rainflow.columns[0]: no frame column \"t\"", 0), 0u);
  o.rainflow.columns = {"p.x", "p.x"};
  EXPECT_EQ(error(o).rfind("output.rainflow.columns[1]: \"p.x\" is named twice", 0), 0u);
  o.rainflow.columns = {"p.x"};
  for (double bad : {0.0, -3.0, std::nan("")}) {
    o.rainflow.sn_slope = bad;
    EXPECT_EQ(error(o).rfind("output.rainflow.sn_slope: must be a number > 0", 0), 0u) << bad;
  }
  o.rainflow.sn_slope = 3;
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::infinity()}) {
    o.rainflow.equivalent_cycles = bad;
    EXPECT_EQ(error(o).rfind("output.rainflow.equivalent_cycles: must be a number > 0", 0), 0u)
        << bad;
  }
  OutputSpec slope_only;
  slope_only.rainflow.sn_slope = 3;
  EXPECT_EQ(error(slope_only).rfind("output.rainflow.columns: empty", 0), 0u);
}

// A real run (crane-winch: a winch, a moving support) with statistics:
// each column's statistics agree with those computed from the frames it
// delivered (independently, two-pass), and the scene's checks run before
// the model runs (RunScene refuses an unknown column naming the field).
TEST(StatisticsRun, AgreesWithItsFramesAndRefusesAnUnknownColumn) {
  Scene scene = SampleScene("crane-winch.json");
  scene.solver.duration_s = 2;
  scene.output.statistics = true;
  scene.output.rainflow = {{"boom_tip.fy", "hook.y"}, 4, 1e6};
  CollectingSink sink;
  const RunSummary summary = testing::RunOk(scene, &sink);
  ASSERT_TRUE(summary.has_statistics);
  const std::vector<std::string> columns = FrameColumns(sink.info(), false);
  ASSERT_EQ(summary.statistics.columns.size(), columns.size() - 1);
  for (size_t i = 1; i < columns.size(); ++i) {
    std::vector<double> v;
    for (const Frame& f : sink.frames()) {
      size_t k = 0;
      ForEachFrameValue(f, [&](double x) {
        if (k++ == i) v.push_back(x);
      });
    }
    double mean = 0, lo = v[0], hi = v[0];
    for (double x : v) mean += x, lo = std::min(lo, x), hi = std::max(hi, x);
    mean /= v.size();
    double var = 0;
    for (double x : v) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / v.size());
    const ColumnStatistics& c = summary.statistics.columns[i - 1];
    EXPECT_EQ(c.column, columns[i]);
    EXPECT_EQ(c.count, static_cast<int64_t>(v.size()));
    EXPECT_EQ(c.min, lo) << c.column;
    EXPECT_EQ(c.max, hi) << c.column;
    // Welford against two passes: rounding of the frames' sums.
    const double scale = std::max(std::abs(lo), std::abs(hi)) + 1e-300;
    EXPECT_NEAR(c.mean, mean, 1e-12 * scale) << c.column;
    EXPECT_NEAR(c.stddev, sd, 1e-9 * scale) << c.column;
  }
  ASSERT_EQ(summary.statistics.rainflow.size(), 2u);
  std::vector<double> hook_y;
  const int hook = testing::ProbeIndex(sink.info(), "hook");
  for (const Frame& f : sink.frames()) hook_y.push_back(f.probes[hook].position_m.y());
  const std::vector<RainflowCycle> cycles = CountRainflow(hook_y);
  EXPECT_NEAR(summary.statistics.rainflow[1].damage_equivalent_load,
              DamageEquivalentLoad(cycles, 4, 1e6), 1e-12);

  scene.output.rainflow.columns = {"boom_tip.fy", "hook.fz"};
  const absl::StatusOr<RunSummary> refused = RunScene(scene, nullptr);
  ASSERT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(refused.status().message().rfind("output.rainflow.columns[1]: no frame column", 0),
            0u)
      << refused.status();
}

}  // namespace
}  // namespace cablesim
