// Time-varying loads (Load.varying_force, Load.varying_torque): a
// cantilever driven at its first natural frequency (from MODAL analysis)
// against the modal closed form of resonance, and a body spun up by a
// harmonic torque against its closed form; the loads' work in the energy
// balance.

#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// Steel rod, 1 m, d = 0.01 m, clamped at x = 0 (no gravity).
constexpr double kE = 2e11, kRho = 7850, kD = 0.01, kL = 1.0;
constexpr double kForce = 0.005;  // N, amplitude at the tip
const char kRod[] = R"("cables": [{"name": "rod", "length": 1, "elements": 10, "density": 7850,
    "youngs_modulus": 2e11, "diameter": 0.01}],
  "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}}],
  "probes": [{"name": "tip", "cable": "rod", "s": 1}])";

class ResonanceTest : public ::testing::TestWithParam<const char*> {};

// F(t) = F0 sin(w1 t) at the tip, w1 the first natural frequency of the
// discrete model (MODAL). Mode 1 of a uniform cantilever, scaled to 1 at
// the tip, has modal mass rho A L / 4 (every mode of a clamped-free beam
// does: int phi^2 dx = L phi(L)^2 / 4), so from rest its tip moves as the
// undamped oscillator at resonance,
//   y(t) = F0 / (M1 w1^2) (sin w1 t - w1 t cos w1 t) / 2,
// an amplitude growing linearly in t. The other modes answer
// quasi-statically: together at most 2.9 % of the static tip deflection
// F0 L^3 / (3 EI) (mode 1 holds 97.1 % of it: 3 / 1.8751^4 * 4), times
// the dynamic factor 1 / (1 - (w1 / w2)^2) = 1.03, i.e. 5.1e-7 m; the
// tolerance is 1e-6 m against an amplitude of 5.2e-4 m after 10 periods
// (measured 5.7e-7 m for HHT and GENERALIZED_ALPHA at 280 steps a period,
// whose phase error over 10 periods is 1e-4). Forcing 1 % off resonance
// slips the response's phase by about 0.3 rad in 10 periods, moving the tip
// by about 30 % of the amplitude; backward Euler (numerical
// damping ~ w h / 2) is left out: its envelope saturates.
TEST_P(ResonanceTest, AmplitudeGrowsLinearlyAsModalClosedForm) {
  CollectingSink modal;
  const RunSummary m = RunOk(
      SceneFromJson(absl::StrCat("{", kRod, R"(, "solver": {"analysis": "MODAL", "modes": 2}})")),
      &modal);
  ASSERT_EQ(m.frequencies_hz.size(), 2u);
  const double f1 = m.frequencies_hz[0], w = 2 * kPi * f1;
  const double periods = 10, duration = periods / f1;
  CollectingSink sink;
  const RunSummary s = RunOk(
      SceneFromJson(absl::StrCat(
          "{", kRod, R"(, "loads": [{"at": {"cable": "rod", "s": 1}, "varying_force": {"y":
            {"harmonic": {"amplitude": )",
          kForce, R"(, "frequency": )", absl::StrFormat("%.17g", f1), R"(}}}}],
          "solver": {"duration": )",
          absl::StrFormat("%.17g", duration), R"(, "step": 0.0005, "output_interval": 0.002,
                     "integrator": ")",
          GetParam(), R"("}})")),
      &sink);
  const double area = kPi * kD * kD / 4;
  const double modal_mass = kRho * area * kL / 4;
  double worst = 0, amplitude = 0, kinetic = 0;
  for (const Frame& f : sink.frames()) {
    const double y =
        kForce / (modal_mass * w * w) * (std::sin(w * f.t) - w * f.t * std::cos(w * f.t)) / 2;
    worst = std::max(worst, std::abs(f.probes[0].position_m.y() - y));
    amplitude = std::max(amplitude, std::abs(y));
    kinetic = std::max(kinetic, f.energy.kinetic);
  }
  EXPECT_GT(amplitude, 5e-4);
  EXPECT_LT(worst, 1e-6) << GetParam();
  // The load's work is in the balance: the total stays at 0 to the
  // trapezoidal rule's error (measured 2e-9 J), against a kinetic energy
  // of 4e-5 J that the load put in.
  EXPECT_GT(kinetic, 3e-5);
  EXPECT_NEAR(s.energy_final, s.energy_initial, 1e-7);
}

INSTANTIATE_TEST_SUITE_P(Steppers, ResonanceTest,
                         ::testing::Values("HHT", "GENERALIZED_ALPHA"));

// A free body (planar, no gravity) turned by T(t) = T0 sin(W t) about z:
// I th'' = T, from rest th = T0 / (I W) (t - sin(W t) / W). Its point at
// (1, 0, 0) in body axes is at (cos th, sin th). HHT at h = 1e-3 over 2 s:
// second order, measured 2.4e-6 m; tolerance 5e-6 m, against a turn of
// 0.64 rad (a torque a step late turns it by up to 6e-4 rad less). The torque's
// work (summed step by step) keeps the total at 0 while the kinetic energy
// rises to 0.2 J and falls back.
TEST(VaryingTorqueTest, SpinsBodyAsClosedForm) {
  constexpr double kInertia = 0.5, kTorque = 1, kHz = 1;
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(R"({
      "bodies": [{"name": "wheel", "mass": 1, "inertia": {"x": 0.25, "y": 0.25, "z": 0.5}}],
      "loads": [{"at": {"body": "wheel"},
                 "varying_torque": {"z": {"harmonic": {"amplitude": 1, "frequency": 1}}}}],
      "probes": [{"name": "rim", "body": "wheel", "point": {"x": 1}}],
      "solver": {"duration": 2, "step": 0.001, "output_interval": 0.1}})"),
                             &sink);
  const double w = 2 * kPi * kHz;
  double worst = 0;
  for (const Frame& f : sink.frames()) {
    const double th = kTorque / (kInertia * w) * (f.t - std::sin(w * f.t) / w);
    worst = std::max(worst, (f.probes[0].position_m -
                             Eigen::Vector3d(std::cos(th), std::sin(th), 0)).norm());
  }
  EXPECT_LT(worst, 5e-6);
  double kinetic = 0, drift = 0;
  for (const Frame& f : sink.frames()) {
    kinetic = std::max(kinetic, f.energy.kinetic);
    drift = std::max(drift, std::abs(f.energy.total - s.energy_initial));
  }
  EXPECT_GT(kinetic, 0.1);
  EXPECT_LT(drift, 1e-6);
}

}  // namespace
}  // namespace cablesim
