// The ENERGY_MOMENTUM stepper (engine/steppers/energy_momentum_stepper.h): the
// element's discrete gradient is one (its work over a step is the exact
// change of the strain energy, and it exerts no net force or moment), the
// stepper keeps the angular momentum of a free spinning body and of the
// spatial pendulum to rounding, keeps the falling pendulum's energy to the
// Newton tolerance, and converges at second order on the tip.

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/elements/ancf_cable_element.h"
#include "tests/energy_momentum_scenes.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

template <int D>
void CheckDiscreteGradient(BendingModel bending) {
  using Element = AncfCableElement<D>;
  const double l = 0.1, ea = 1e6, ei = 10;
  const Element element(l, ea, ei, bending);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    // A bent, stretched element, and a step that moves, stretches and
    // rotates it by up to 10 %.
    typename Element::Coords e0, e1;
    for (int k = 0; k < 4 * D; ++k) e0(k) = 0.05 * u(rng);
    e0.template segment<D>(D)(0) += 1;
    e0.template segment<D>(3 * D)(0) += 1;
    e0.template segment<D>(2 * D)(0) += l;
    for (int k = 0; k < 4 * D; ++k) e1(k) = e0(k) + 0.1 * u(rng) * (k % (2 * D) < D ? l : 1);
    const typename Element::Coords em = 0.5 * (e0 + e1);
    typename Element::Coords f = Element::Coords::Zero();
    element.ElasticForce(em, &f, nullptr);
    element.AddDiscreteGradientCorrection(e0, e1, &f);
    const auto u0 = element.StrainEnergy(e0), u1 = element.StrainEnergy(e1);
    const double du = (u1.axial + u1.bending) - (u0.axial + u0.bending);
    const double scale = u0.axial + u0.bending + u1.axial + u1.bending;
    // Directionality: exact to rounding of the energies (1e-12 relative).
    EXPECT_NEAR(f.dot(e1 - e0), du, 1e-12 * scale) << "trial " << trial;
    // No net force: the two node forces are opposite.
    EXPECT_LT((f.template segment<D>(0) + f.template segment<D>(2 * D)).norm(),
              1e-12 * f.norm());
    // No net moment about the origin at the midpoint configuration (the
    // slopes are vectors too).
    if constexpr (D == 3) {
      Eigen::Vector3d moment = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k)
        moment += em.template segment<3>(3 * k).cross(f.template segment<3>(3 * k));
      EXPECT_LT(moment.norm(), 1e-12 * f.norm() * em.norm()) << "trial " << trial;
    } else {
      double moment = 0;
      for (int k = 0; k < 4; ++k)
        moment += em(2 * k) * f(2 * k + 1) - em(2 * k + 1) * f(2 * k);
      EXPECT_LT(std::abs(moment), 1e-12 * f.norm() * em.norm()) << "trial " << trial;
    }
    // Consistency: the correction vanishes at first order as e1 -> e0
    // (it is O(|e1 - e0|)): halving the step halves it at least.
    typename Element::Coords c1 = Element::Coords::Zero(), c2 = Element::Coords::Zero();
    element.AddDiscreteGradientCorrection(e0, e0 + 1e-3 * (e1 - e0), &c1);
    element.AddDiscreteGradientCorrection(e0, e0 + 0.5e-3 * (e1 - e0), &c2);
    EXPECT_LE(c2.norm(), 0.55 * c1.norm() + 1e-9 * f.norm()) << "trial " << trial;
  }
}

TEST(EnergyMomentumElementTest, DiscreteGradientIsExactAndMomentumFreePlanarExact) {
  CheckDiscreteGradient<2>(BendingModel::kExact);
}
TEST(EnergyMomentumElementTest, DiscreteGradientIsExactAndMomentumFreePlanarLinear) {
  CheckDiscreteGradient<2>(BendingModel::kLinear);
}
TEST(EnergyMomentumElementTest, DiscreteGradientIsExactAndMomentumFreeSpatialExact) {
  CheckDiscreteGradient<3>(BendingModel::kExact);
}
TEST(EnergyMomentumElementTest, DiscreteGradientIsExactAndMomentumFreeSpatialLinear) {
  CheckDiscreteGradient<3>(BendingModel::kLinear);
}

TEST(EnergyMomentumStepperTest, FreeSpinningBodyKeepsAngularMomentumAndEnergyToRounding) {
  // A torque-free asymmetric body (natural coordinates, six quadratic
  // orthonormality rows) at a coarse step (4e-3 s, 500 steps, spin 1.5
  // rad/s): the exact solution and the scheme both keep L and T. Newton
  // tolerance 1e-12 so that its residual is at rounding; tolerance 1e-12
  // relative over 500 steps (rounding of the sums, ~100 eps per step).
  const std::string json = R"({
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 2, "y": 3, "z": 4},
                "axis": {"x": 1, "y": 0.2, "z": 0.1}}],
    "initial_velocity": {"angular": {"x": 0.3, "y": 0.2, "z": 1.5}},
    "probes": [{"name": "c", "body": "b"}],
    "solver": {"duration": 2, "step": 4e-3, "output_interval": 0.1,
               "newton_tolerance": 1e-12, "integrator": "ENERGY_MOMENTUM"}})";
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(s.info.model, "spatial");
  const Eigen::Vector3d l0 = sink.frames().front().angular_momentum;
  const double t0 = sink.frames().front().energy.total;
  double dl = 0, de = 0;
  for (const Frame& f : sink.frames()) {
    dl = std::max(dl, (f.angular_momentum - l0).norm() / l0.norm());
    de = std::max(de, std::abs(f.energy.total - t0) / t0);
  }
  std::printf("free body, ENERGY_MOMENTUM h = 4e-3: |dL| / |L| = %.3g, |dT| / T = %.3g\n", dl,
              de);
  EXPECT_LT(dl, 1e-12);
  EXPECT_LT(de, 1e-12);
}

// Frame::angular_momentum is computed only for a sink that asks for it
// (FrameSink::wants_angular_momentum): the free body above, spinning, run
// once for a sink that does not ask (zeros in every frame) and once for
// one that does (L = I omega, nonzero), with every other figure the same.
TEST(EnergyMomentumStepperTest, AngularMomentumOnlyForASinkThatAsks) {
  const std::string json = R"({
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 2, "y": 3, "z": 4}}],
    "initial_velocity": {"angular": {"x": 0.3, "y": 0.2, "z": 1.5}},
    "solver": {"duration": 0.1, "step": 1e-2, "output_interval": 0.05}})";
  class NotAsking : public CollectingSink {
   public:
    bool wants_angular_momentum() const override { return false; }
  };
  NotAsking plain;
  CollectingSink asking;
  RunOk(SceneFromJson(json), &plain);
  RunOk(SceneFromJson(json), &asking);
  ASSERT_EQ(plain.frames().size(), asking.frames().size());
  ASSERT_FALSE(plain.frames().empty());
  // At t = 0 the body's axes are the world's: L = diag(2, 3, 4) omega.
  EXPECT_NEAR((asking.frames().front().angular_momentum - Eigen::Vector3d(0.6, 0.6, 6.0)).norm(),
              0, 1e-12);
  for (size_t k = 0; k < plain.frames().size(); ++k) {
    EXPECT_EQ(plain.frames()[k].angular_momentum, Eigen::Vector3d::Zero());
    EXPECT_GT(asking.frames()[k].angular_momentum.norm(), 1);
    EXPECT_EQ(plain.frames()[k].energy.total, asking.frames()[k].energy.total);
  }
}

TEST(EnergyMomentumStepperTest, SpatialPendulumKeepsVerticalAngularMomentumToRounding) {
  // scenes/spatial-pendulum.json (spun at 4 rad/s about the vertical
  // through the pin) at h = 1e-3 for 0.5 s: gravity and the pin exert no
  // moment about y, so L_y is conserved by the scheme exactly; tolerance
  // 1e-11 relative (Newton tolerance 1e-12, 500 steps).
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "pendulum", "length": 1.0, "elements": 16, "direction": {"x": 1},
                "density": 320, "youngs_modulus": 1.6e6, "area": 2.5e-5,
                "second_moment": 4.973591971621729e-11, "bending": "EXACT"}],
    "joints": [{"type": "PIN", "a": {"cable": "pendulum", "s": 0}}],
    "initial_velocity": {"angular": {"y": 4.0}},
    "probes": [{"name": "tip", "cable": "pendulum", "s": 1.0}],
    "solver": {"duration": 0.5, "step": 1e-3, "output_interval": 0.01,
               "newton_tolerance": 1e-12, "integrator": "ENERGY_MOMENTUM"}})";
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(s.info.model, "spatial");
  const double l0 = sink.frames().front().angular_momentum.y();
  const double e0 = sink.frames().front().energy.total;
  double dl = 0, de = 0;
  for (const Frame& f : sink.frames()) {
    dl = std::max(dl, std::abs(f.angular_momentum.y() - l0) / l0);
    de = std::max(de, std::abs(f.energy.total - e0));
  }
  std::printf("spatial pendulum, ENERGY_MOMENTUM h = 1e-3: |dL_y| / L_y = %.3g, |dE| = %.3g J "
              "of %.3g J kinetic\n",
              dl, de, sink.frames().front().energy.kinetic);
  EXPECT_LT(dl, 1e-11);
  EXPECT_LT(de, 1e-9 * sink.frames().front().energy.kinetic);
}

std::string FallingPendulum(double duration, double step, const std::string& extra) {
  return testing::EnergyMomentumFallingPendulum(duration, step, extra);
}

TEST(EnergyMomentumStepperTest, FallingPendulumKeepsItsEnergyToTheNewtonTolerance) {
  // 1 s at h = 1e-3 (the 100 s run is in energy_momentum_slow_test): the
  // total energy of every frame within 1e-7 of the energy scale (Newton
  // tolerance 1e-10 on residuals relative to the largest force term; the
  // tolerance leaves a margin of 100 for 1000 steps of such residuals).
  for (const char* solver : {"DIRECT", "MINRES", "GMRES"}) {
    CollectingSink sink;
    const RunSummary s =
        RunOk(SceneFromJson(FallingPendulum(
                  1, 1e-3,
                  absl::StrFormat(R"(, "newton_tolerance": 1e-10, "linear_solver": "%s")",
                                  solver))),
              &sink);
    double scale = 0, drift = 0;
    for (const Frame& f : sink.frames()) {
      scale = std::max({scale, std::abs(f.energy.kinetic), std::abs(f.energy.potential)});
      drift = std::max(drift, std::abs(f.energy.total - sink.frames()[0].energy.total));
    }
    std::printf("falling pendulum 1 s, ENERGY_MOMENTUM + %s: %lld steps, %lld Newton "
                "iterations, energy drift %.3g J of %.3g J\n",
                solver, static_cast<long long>(s.steps),
                static_cast<long long>(s.newton_iterations), drift, scale);
    EXPECT_LT(drift, 1e-7 * scale) << solver;
  }
}

TEST(EnergyMomentumStepperTest, TipConvergesAtSecondOrder) {
  // Tip position at t = 0.5 s at h = 2e-3, 1e-3, 5e-4 against h = 1.25e-4
  // (whose own error is 16 times below the h = 5e-4 one's at order 2):
  // the error ratios of successive halvings must be near 4 (in [3, 5]).
  auto tip = [](double step) {
    CollectingSink sink;
    RunOk(SceneFromJson(FallingPendulum(0.5, step, R"(, "newton_tolerance": 1e-11)")), &sink);
    return sink.frames().back().probes[0].position_m;
  };
  const Eigen::Vector3d ref = tip(1.25e-4);
  const double e1 = (tip(2e-3) - ref).norm(), e2 = (tip(1e-3) - ref).norm(),
               e3 = (tip(5e-4) - ref).norm();
  std::printf("ENERGY_MOMENTUM tip errors at 0.5 s: %.3g, %.3g, %.3g m (ratios %.3f, %.3f)\n", e1,
              e2, e3, e1 / e2, e2 / e3);
  EXPECT_GT(e1 / e2, 3);
  EXPECT_LT(e1 / e2, 5);
  EXPECT_GT(e2 / e3, 3);
  EXPECT_LT(e2 / e3, 5);
}

TEST(EnergyMomentumStepperTest, AdaptiveStepsMeetTheTolerance) {
  // Adaptive steps with tolerance 1e-4 m: the run finishes, varies its
  // step, and its tip at 1 s is within 1e-2 m of a fixed-step h = 1e-4
  // run (local tolerance 1e-4 m over ~100 steps accumulates to well below
  // that).
  CollectingSink fixed, adaptive;
  RunOk(SceneFromJson(FallingPendulum(1, 1e-4, "")), &fixed);
  const RunSummary s = RunOk(
      SceneFromJson(FallingPendulum(1, 1e-3, R"(, "adaptive": true, "tolerance": 1e-4)")),
      &adaptive);
  const double err = (adaptive.frames().back().probes[0].position_m -
                      fixed.frames().back().probes[0].position_m)
                         .norm();
  std::printf("ENERGY_MOMENTUM adaptive 1e-4: %lld steps (%lld rejected), min step %.3g s, tip "
              "error %.3g m\n",
              static_cast<long long>(s.steps), static_cast<long long>(s.rejected_steps),
              s.min_step_s, err);
  EXPECT_LT(err, 1e-2);
  EXPECT_GT(s.max_step_s, s.min_step_s);
}

TEST(EnergyMomentumStepperTest, RhoInfinityIsRejectedNamingTheField) {
  auto proto = ParseSceneJson(FallingPendulum(1, 1e-3, R"(, "rho_infinity": 0.8)"));
  ASSERT_TRUE(proto.ok());
  auto scene = SceneFromProto(*proto);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.status().message().find("solver.rho_infinity"), std::string::npos)
      << scene.status();
}

}  // namespace
}  // namespace cablesim
