// Hard cases of issue 5 (label slow): a stiff steel cable at a large step,
// a heavy cylinder on a light cable that goes slack and snaps taut, the
// falling pendulum at g = 50 with 40 elements, and a 100 s run without
// numerical damping. Each must finish without NaN, keep the energy from
// growing (beyond the stated drift for the non-dissipative setting), keep
// constraint violations under the Newton tolerance, and a setting that
// cannot converge must fail with a message.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// Largest energy term over the run [J]: the scale of energy errors.
double EnergyScale(const CollectingSink& sink) {
  double scale = 0;
  for (const Frame& f : sink.frames()) {
    scale = std::max({scale, std::abs(f.energy.kinetic), std::abs(f.energy.potential),
                      f.energy.axial + f.energy.bending});
  }
  return scale;
}

// Checks every frame is finite and returns the largest rise of the total
// energy above its initial value [J].
double MaxEnergyRise(const CollectingSink& sink) {
  double rise = 0;
  for (const Frame& f : sink.frames()) {
    EXPECT_TRUE(std::isfinite(f.energy.total)) << "t = " << f.t;
    for (const ProbeSample& p : f.probes) EXPECT_TRUE(p.position_m.allFinite()) << "t = " << f.t;
    rise = std::max(rise, f.energy.total - sink.frames()[0].energy.total);
  }
  return rise;
}

// The default stepper (HHT) and backward Euler must pass every hard case
// (strict). Generalized-alpha is less robust here (measured: on the slack-
// taut cable, or over 100 s, with rho_infinity 0.5 its stretch modes gain
// energy): it must either pass the same checks or fail with a message
// before delivering garbage (every delivered frame finite and within the
// energy guard, 5 % of the energy scale). ENERGY_MOMENTUM (no numerical
// damping) is strict on the g = 50 and the slack-taut cases: its energy may
// not rise beyond the Newton tolerance's share either (its frames on the
// 5 ms grid are step ends: halved steps return to the nominal grid).
bool Strict(const std::string& integrator) { return integrator != "GENERALIZED_ALPHA"; }

// Runs `json`; strict runs must succeed, others may fail cleanly. Returns
// whether the run finished.
bool RunHardCase(const std::string& json, const std::string& integrator, CollectingSink* sink,
                 RunSummary* summary) {
  if (Strict(integrator)) {
    *summary = RunOk(SceneFromJson(json), sink);
    return summary->status == "ok";
  }
  auto s = RunScene(SceneFromJson(json), sink);
  EXPECT_TRUE(s.ok()) << s.status();
  if (!s.ok()) return false;
  *summary = *s;
  if (s->status != "ok") {
    EXPECT_EQ(s->status, "failed");
    EXPECT_FALSE(s->error.empty());
    std::printf("%s failed cleanly: %s\n", integrator.c_str(), s->error.c_str());
    const double scale = EnergyScale(*sink);
    EXPECT_LE(MaxEnergyRise(*sink), 0.05 * scale);
    return false;
  }
  return true;
}

std::string SteelCable(const std::string& solver) {
  // E = 2e11 Pa, d = 0.01 m, 100 elements, 10 m, pinned at one end,
  // released horizontal.
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "steel", "length": 10, "elements": 100, "direction": {"x": 1},
                "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "steel", "s": 0}}],
    "probes": [{"name": "tip", "cable": "steel", "s": 10}],
    "solver": {"duration": 2, "step": 1e-3, "output_interval": 0.01, %s}})",
                         solver);
}

TEST(HardCasesTest, SteelCableAtOneMillisecond) {
  // Dissipative settings: the energy may not rise by more than the Newton
  // tolerance's share of the energy scale (1e-6 relative: residuals of 1e-8
  // relative to the largest force term, accumulated over 2000 steps).
  for (const char* integrator : {"GENERALIZED_ALPHA", "HHT", "IMPLICIT_EULER"}) {
    CollectingSink sink;
    RunSummary s;
    if (!RunHardCase(SteelCable(absl::StrFormat(R"("integrator": "%s")", integrator)), integrator,
                     &sink, &s)) {
      continue;
    }
    const double scale = EnergyScale(sink), rise = MaxEnergyRise(sink);
    std::printf("steel cable, %s: %lld steps, %lld rejected, energy removed %.4g J of %.4g J, "
                "largest rise %.3g J\n",
                integrator, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.energy_dissipated, scale, rise);
    EXPECT_LE(rise, 1e-6 * scale) << integrator;
    // The tip has fallen: the cable swings (a 10 m pendulum needs ~2 s for
    // a quarter period, so after 2 s it is well below the pivot).
    EXPECT_LT(sink.frames().back().probes[0].position_m.y(), -5) << integrator;
  }
}

TEST(HardCasesTest, HeavyCylinderOnALightCableGoesSlackAndSnapsTaut) {
  // A 1.5 kg steel cylinder on a 0.5 m, 12 g cable, released above the
  // pivot (tilted 17 degrees): it falls past the pivot with the cable slack
  // and is caught when the cable snaps taut.
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "cable", "length": 0.5, "elements": 20,
                "direction": {"x": 0.3, "y": 1},
                "density": 1000, "youngs_modulus": 1e9, "diameter": 0.005}],
    "bodies": [{"name": "cylinder", "cylinder": {"diameter": 0.05, "height": 0.1},
                "density": 7800, "position": {"x": 0.1436739427831727, "y": 0.47891314261057566}}],
    "joints": [{"type": "PIN", "a": {"cable": "cable", "s": 0}},
               {"type": "PIN", "a": {"cable": "cable", "s": 0.5}, "b": {"body": "cylinder"}}],
    "probes": [{"name": "cylinder", "body": "cylinder"}],
    "solver": {"duration": 1.5, "step": 1e-3, "output_interval": 0.005,
               "integrator": "INTEGRATOR", "max_step_halvings": 16}})";
  for (const char* integrator : {"GENERALIZED_ALPHA", "HHT", "IMPLICIT_EULER", "ENERGY_MOMENTUM"}) {
    std::string scene = json;
    scene.replace(scene.find("INTEGRATOR"), 10, integrator);
    CollectingSink sink;
    RunSummary s;
    if (!RunHardCase(scene, integrator, &sink, &s)) continue;
    double lowest = 1e300, shortest = 1e300, longest = 0;
    for (const Frame& f : sink.frames()) {
      const double r = f.probes[0].position_m.norm();
      lowest = std::min(lowest, f.probes[0].position_m.y());
      shortest = std::min(shortest, r);
      longest = std::max(longest, r);
      EXPECT_LT(f.constraint_violation, 1e-6) << integrator << " t = " << f.t;
    }
    const double scale = EnergyScale(sink), rise = MaxEnergyRise(sink);
    std::printf("slack-taut, %s: %lld steps, %lld rejected, min step %.3g s, cylinder distance "
                "from pivot %.3f..%.3f m, energy removed %.4g J of %.4g J, largest rise %.3g J\n",
                integrator, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.min_step_s, shortest, longest,
                s.energy_dissipated, scale, rise);
    // Slack: the cylinder came closer to the pivot than the cable's length;
    // taut: it went below the pivot by about the length (not much beyond:
    // a stiff cable stretches little).
    EXPECT_LT(shortest, 0.45) << integrator;
    EXPECT_LT(lowest, -0.4) << integrator;
    EXPECT_LT(longest, 0.56) << integrator;
    EXPECT_LE(rise, 1e-6 * scale) << integrator;
  }
}

std::string FallingPendulum(int elements, double g, double duration, const std::string& solver) {
  return absl::StrFormat(R"({
    "gravity": {"y": %g},
    "cables": [{"name": "beam", "length": 1.2, "elements": %d, "direction": {"x": 1},
                "density": 5540, "youngs_modulus": 0.7e6,
                "area": 0.0018, "second_moment": 1.215e-8}],
    "joints": [{"type": "PIN", "a": {"cable": "beam", "s": 0}}],
    "probes": [{"name": "tip", "cable": "beam", "s": 1.2}],
    "solver": {"duration": %g, "output_interval": 0.01, %s}})",
                         -g, elements, duration, solver);
}

TEST(HardCasesTest, FallingPendulumAtFiftyGWithFortyElements) {
  for (const char* integrator : {"GENERALIZED_ALPHA", "HHT", "IMPLICIT_EULER", "ENERGY_MOMENTUM"}) {
    CollectingSink sink;
    RunSummary s;
    if (!RunHardCase(FallingPendulum(40, 50, 1.0,
                                     absl::StrFormat(R"("step": 1e-4, "integrator": "%s")",
                                                     integrator)),
                     integrator, &sink, &s)) {
      continue;
    }
    const double scale = EnergyScale(sink), rise = MaxEnergyRise(sink);
    std::printf("g = 50, 40 elements, %s: %lld steps, %lld rejected, energy removed %.4g J of "
                "%.4g J, largest rise %.3g J\n",
                integrator, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.energy_dissipated, scale, rise);
    EXPECT_LE(rise, 1e-6 * scale) << integrator;
  }
}

TEST(HardCasesTest, HundredSecondsWithoutNumericalDamping) {
  // rho_infinity = 1 at h = 1e-3 (frames every 0.01 s): no numerical
  // damping. Measured: the energy wanders by about 3 % of its scale (82 J)
  // for a few seconds, then the stiff stretch modes gain energy without
  // bound (the nonlinear instability of energy-conserving-for-linear
  // Newmark-type schemes, Simo and Tarnow, ZAMP 43, 1992) near t = 6 s. The
  // run must stop there with the energy message rather than deliver that
  // growth: every delivered frame stays within the guard (5 % of the scale).
  CollectingSink sink;
  auto s = RunScene(SceneFromJson(FallingPendulum(
                        12, 9.81, 100,
                        R"("step": 1e-3, "integrator": "GENERALIZED_ALPHA", "rho_infinity": 1,
                           "linear_solver": "DIRECT")")),
                    &sink);
  ASSERT_TRUE(s.ok()) << s.status();
  const double scale = EnergyScale(sink);
  double drift = 0;
  for (const Frame& f : sink.frames()) {
    ASSERT_TRUE(std::isfinite(f.energy.total)) << f.t;
    drift = std::max(drift, std::abs(f.energy.total - sink.frames()[0].energy.total));
  }
  std::printf("100 s, rho_infinity 1: status %s at t = %.4g s after %lld steps; largest energy "
              "drift over the delivered frames %.4g J (%.3g %% of %.4g J); %s\n",
              s->status.c_str(), sink.frames().back().t, static_cast<long long>(s->steps), drift,
              100 * drift / scale, scale, s->error.c_str());
  EXPECT_LE(drift, 0.05 * scale);
  if (s->status != "ok") {
    EXPECT_EQ(s->status, "failed");
    EXPECT_NE(s->error.find("energy"), std::string::npos) << s->error;
  }
  // HHT with rho_infinity = 0.9 (alpha = -0.053) finishes the same 100 s,
  // and the energy never rises (Newton-tolerance share of the scale).
  CollectingSink damped;
  const RunSummary d = RunOk(SceneFromJson(FallingPendulum(
                                 12, 9.81, 100,
                                 R"("step": 1e-3, "integrator": "HHT",
                                    "rho_infinity": 0.9, "linear_solver": "DIRECT")")),
                             &damped);
  std::printf("100 s, HHT rho_infinity 0.9: %lld steps, energy removed %.4g J\n",
              static_cast<long long>(d.steps), d.energy_dissipated);
  EXPECT_LE(MaxEnergyRise(damped), 1e-6 * EnergyScale(damped));
  // HHT with its default rho_infinity 0.5 (the default stepper before
  // AUTO): the same, energy never rises.
  CollectingSink hht;
  const RunSummary hs = RunOk(
      SceneFromJson(FallingPendulum(12, 9.81, 100, R"("step": 1e-3, "integrator": "HHT")")), &hht);
  std::printf("100 s, HHT (rho %g, %s): %lld steps, %lld rejected, energy removed %.4g J\n",
              hs.rho_infinity, hs.linear_solver_used.c_str(), static_cast<long long>(hs.steps),
              static_cast<long long>(hs.rejected_steps), hs.energy_dissipated);
  EXPECT_LE(MaxEnergyRise(hht), 1e-6 * EnergyScale(hht));
  // And the defaults (AUTO: central difference while its error estimate
  // holds, HHT where it does not). They finish the 100 s, remove energy on
  // balance (HHT's stretches damp), and central difference's stretches keep
  // it without drift: a symplectic step's energy error oscillates at
  // O((omega h)^2) of the fast modes' share, measured 1.2e-5 of the scale,
  // bounded here by 1e-4 (a drift of the kind undamped generalized-alpha
  // shows above grows to 3 % of the scale).
  CollectingSink defaults;
  const RunSummary ds =
      RunOk(SceneFromJson(FallingPendulum(12, 9.81, 100, R"("step": 1e-3)")), &defaults);
  std::printf("100 s, defaults (%s first, %zu stretches, %s): %lld steps, %lld rejected, energy "
              "removed %.4g J\n",
              ds.integrator.c_str(), ds.integrator_segments.size(),
              ds.linear_solver_used.c_str(), static_cast<long long>(ds.steps),
              static_cast<long long>(ds.rejected_steps), ds.energy_dissipated);
  EXPECT_EQ(ds.integrator_requested, "AUTO");
  EXPECT_GT(ds.energy_dissipated, 0);
  EXPECT_LE(MaxEnergyRise(defaults), 1e-4 * EnergyScale(defaults));
}

TEST(HardCasesTest, SettingThatCannotConvergeFailsWithAMessage) {
  // The steel cable at h = 1e-3 with one Newton iteration per attempt and no
  // halving cannot converge: the run fails, names Newton and the time, and
  // every delivered frame is finite.
  CollectingSink sink;
  auto s = RunScene(SceneFromJson(SteelCable(
                        R"("integrator": "GENERALIZED_ALPHA", "max_newton_iterations": 1,
                           "max_step_halvings": 0)")),
                    &sink);
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->status, "failed");
  EXPECT_NE(s->error.find("Newton"), std::string::npos) << s->error;
  EXPECT_NE(s->error.find("t = "), std::string::npos) << s->error;
  MaxEnergyRise(sink);
}

}  // namespace
}  // namespace cablesim
