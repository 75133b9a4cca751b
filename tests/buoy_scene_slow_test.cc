// The issue-17 sample scene scenes/mooring-three-line-buoy.json: a 20 t
// buoy (a vertical cylinder of 4 m diameter and height) floating on three
// 180 m catenary lines of 50 elements each in 50 m of water, started from
// static equilibrium and moved by a regular wave (H = 2 m, T = 10 s,
// ramped in over 10 s) through its hydrodynamics (engine/forces/
// body_fluid_load.h). Run for 30 s (the ramp and two periods):
//  - it steps without halvings;
//  - the anchor ends stay on the bed (no uplift at the anchors: a point
//    10.8 m from each anchor stays within the bed's sink w / k = 1 mm plus
//    1 cm of the bed at every frame);
//  - the buoy heaves with the wave. Its heave is a linear oscillator of
//    mass m + m_a = 20000 + 0.5 rho A s = 33030 kg and stiffness rho g A =
//    126.4 kN/m (T_n = 3.21 s) excited by rho g A eta (1 - k s) (the wave
//    buoyancy and the vertical Froude-Krylov inertia, k s = 0.081), so
//    its amplitude is a (1 - k s) / (1 - (T_n / T)^2) = 1.025 a. The lines'
//    vertical stiffness and the mass they move with the buoy, and the heave
//    drag, shift this by a few per cent: the measured amplitude over the
//    last period must be within 10 % of it;
//  - energy.total + energy.damped (line and buoy drag, bed damping and
//    friction, the waves' work) stays within 0.1 % of the waves' work.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "engine/forces/waves.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(BuoySceneTest, BuoyRidesTheWaveOnItsMooring) {
  auto scene = std::make_optional(testing::SampleScene("mooring-three-line-buoy.json"));
  ASSERT_FALSE(scene->cables.empty());
  scene->solver.duration_s = 30;
  // A point 3 elements from each anchor (a node already: 180 m / 50).
  const int first_new_probe = static_cast<int>(scene->probes.size());
  for (int c = 0; c < 3; ++c) {
    ProbeSpec probe;
    probe.name = absl::StrCat("anchor_side", c + 1);
    probe.at.cable = c;
    probe.at.s_m = 10.8;
    scene->probes.push_back(probe);
  }
  testing::CollectingSink sink;
  const RunSummary s = testing::RunOk(*scene, &sink);
  const auto& frames = sink.frames();
  ASSERT_GT(frames.size(), 10u);
  std::printf("%lld steps, %lld rejected, %lld Newton, %.3f s wall for %.1f s simulated; "
              "energy initial %.6g final %.6g damped %.6g\n",
              static_cast<long long>(s.steps), static_cast<long long>(s.rejected_steps),
              static_cast<long long>(s.newton_iterations), s.wall_seconds, s.end_time_s,
              s.energy_initial, s.energy_final, s.energy_damped);
  EXPECT_EQ(s.rejected_steps, 0);

  // The anchor ends stay on the bed (depth 50 m).
  const double w = (7850 * 0.005 - 1025 * kPi * 0.1 * 0.1 / 4) * 9.81;  // [N/m]
  double lowest = 0, highest = -100;
  for (const Frame& f : frames) {
    for (int c = 0; c < 3; ++c) {
      const double z = f.probes[first_new_probe + c].position_m.z();
      lowest = std::min(lowest, z);
      highest = std::max(highest, z);
    }
  }
  std::printf("anchor-side points between z = %.6f and %.6f m (bed sink w/k = %.2e m)\n", lowest,
              highest, w / 3e5);
  EXPECT_GT(lowest, -50 - w / 3e5 - 0.01);
  EXPECT_LT(highest, -50 + 0.01);

  // The heave over the last wave period (20 s to 30 s) against the
  // linear response.
  const double g = 9.81, rho = 1025, d = 4, area = kPi * d * d / 4, period = 10;
  const double omega = 2 * kPi / period, k = WaveField::Wavenumber(omega, 50, g);
  const double z_eq = frames.front().probes[0].position_m.z();
  const double draft = 2 - z_eq;
  const double mass = 20000 + 0.5 * rho * area * draft;
  const double omega_n2 = rho * g * area / mass;
  const double expected = 1.0 * (1 - k * draft) / (1 - omega * omega / omega_n2);
  double zmin = 1e9, zmax = -1e9;
  for (const Frame& f : frames) {
    if (f.t < 20) continue;
    zmin = std::min(zmin, f.probes[0].position_m.z());
    zmax = std::max(zmax, f.probes[0].position_m.z());
  }
  const double amplitude = (zmax - zmin) / 2;
  std::printf("static draft %.4f m; heave amplitude %.4f m, linear estimate %.4f m\n", draft,
              amplitude, expected);
  EXPECT_NEAR(amplitude, expected, 0.1 * expected);

  // Energy balance, against the waves' work.
  double worst = 0, work = 0;
  const double balance0 = frames.front().energy.total + frames.front().energy.damped;
  for (const Frame& f : frames) {
    worst = std::max(worst, std::abs(f.energy.total + f.energy.damped - balance0));
    work = std::max(work, std::abs(f.energy.damped));
  }
  std::printf("energy balance within %.4g J of %.4g J\n", worst, work);
  EXPECT_LT(worst, 1e-3 * work);
}

}  // namespace
}  // namespace cablesim
