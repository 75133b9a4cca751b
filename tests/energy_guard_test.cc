// The dynamic run's energy guard (engine/run/energy_guard.h) where the rise
// is older than the step it checks. The guard checks a step when Newton
// needed 4 or more iterations or a frame ends it; a rise built up over
// steps it did not check shows at the next check already at that step's
// start, and halving the step cannot take it back. The run must then stop
// at once, at the step's start, and say between which times the energy
// rose, instead of halving the step down to its floor and blaming it.
//
// The scene: a chain 200 m long (EA 7.5e8 N) laid along a polyline that
// folds back by 112 degrees at 156.67 m, inside its 4 elements' third, so
// the element there is compressed (8.8e8 J of strain at the start), with a
// Kelvin-Voigt time of 0.03 s, pinned at both ends, frames every 1 ms.
// Released, its energy had risen by 4.3e8 J at 1.88 ms, after a check
// passed at 1.15 ms (measured, 29 November 2026), in steps of fewer than 4
// Newton iterations; the old guard halved the step at 1.88 ms down to its
// floor and failed it.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "absl/strings/numbers.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::SceneFromJson;

constexpr char kFoldedChain[] = R"({
  "name": "folded-chain",
  "gravity": {"y": -9.81},
  "cables": [{"name": "c", "length": 200, "elements": 4, "density": 1663,
              "youngs_modulus": 3.12e10, "area": 0.024, "bending": "NONE",
              "damping": {"axial_time": 0.03},
              "points": [{"x": 0, "y": 0}, {"x": 156.67, "y": 0}, {"x": 140, "y": 40}]}],
  "joints": [{"type": "PIN", "a": {"cable": "c"}},
             {"type": "PIN", "a": {"cable": "c", "s": 200}}],
  "solver": {"analysis": "DYNAMIC", "duration": 0.3, "output_interval": 0.001}
})";

// The number after `key` in `text` (NaN if absent).
double NumberAfter(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  if (at == std::string::npos) return std::nan("");
  const size_t start = at + key.size();
  const size_t end = text.find(' ', start);
  double value = std::nan("");
  if (!absl::SimpleAtod(text.substr(start, end - start), &value)) return std::nan("");
  return value;
}

TEST(EnergyGuardTest, ARiseOlderThanTheCheckedStepStopsTheRunAtItsStart) {
  CollectingSink sink;
  const auto summary = RunScene(SceneFromJson(kFoldedChain), &sink);
  ASSERT_TRUE(summary.ok()) << summary.status();
  ASSERT_EQ(summary->status, "failed");
  const std::string& error = summary->error;
  EXPECT_NE(error.find("the total energy had risen by"), std::string::npos) << error;
  // Between the last state the guard passed and the failing step's start,
  // which is where the run stops (not at the end of a halved step).
  const double from = NumberAfter(error, "between t = ");
  const double to = NumberAfter(error, "s, the last state checked, and t = ");
  ASSERT_TRUE(std::isfinite(from) && std::isfinite(to)) << error;
  EXPECT_LT(from, to);
  EXPECT_NEAR(summary->failure_time_s, to, 1e-8 * to);  // printed to 9 digits
  // Within the first frames, where the start's strain is released.
  EXPECT_LT(to, 0.01);
  // The run stops at its last accepted state, the step's start, not at
  // the end of a step halved down to its floor.
  EXPECT_EQ(summary->failure_time_s, summary->end_time_s) << error;
  EXPECT_EQ(error.find("down to h ="), std::string::npos) << error;
  // The start's strain is named (the layout is not an equilibrium).
  EXPECT_NE(error.find("solver.initial_state: STATIC"), std::string::npos) << error;
  // No frame is delivered after the state where the run stopped.
  ASSERT_FALSE(sink.frames().empty());
  EXPECT_LE(sink.frames().back().t, to);
}

}  // namespace
}  // namespace cablesim
