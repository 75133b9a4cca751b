// The explicit steppers DORMAND_PRINCE (engine/steppers/dormand_prince_stepper.h) and
// CENTRAL_DIFFERENCE (engine/steppers/central_difference_stepper.h): exact where the
// motion is a polynomial they integrate exactly, close to an implicit
// reference on the falling pendulum, at their orders (5 and 2), within
// their tolerance when adaptive, and a step beyond the stability limit is
// reported instead of written; scenes they cannot take are refused naming
// the field.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/integrator_traits.h"
#include "tests/energy_momentum_scenes.h"
#include "tests/sample_scene_json.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneError;
using testing::SceneFromJson;

// scenes/falling-pendulum.json (12 elements, E = 0.7 MPa: the soft case an
// explicit stepper is for) with `solver` fields, frames every 10 ms.
std::string Pendulum(double duration_s, const std::string& solver) {
  return testing::FallingPendulumWithSolver(duration_s, 0.01, solver);
}

std::vector<Eigen::Vector3d> Tips(const std::string& json) {
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  std::vector<Eigen::Vector3d> tips;
  for (const Frame& f : sink.frames()) tips.push_back(f.probes[0].position_m);
  return tips;
}

double LargestDifference(const std::vector<Eigen::Vector3d>& a,
                         const std::vector<Eigen::Vector3d>& b) {
  EXPECT_EQ(a.size(), b.size());
  double worst = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    worst = std::max(worst, (a[i] - b[i]).norm());
  return worst;
}

std::string Explicit(const char* integrator, double step) {
  return absl::StrFormat(R"("integrator": "%s", "step": %g)", integrator, step);
}

TEST(ExplicitStepperTest, FreeFallIsExact) {
  // An unstrained cable thrown sideways falls as a rigid body: the motion is
  // quadratic in t, which both methods integrate exactly (central
  // difference: exact for constant acceleration; Dormand-Prince: for
  // polynomials up to degree 5). Tolerance: rounding of 500 steps on
  // coordinates of order 10 m. A soft rope (its stiffest mode near 20
  // rad/s): the rounding must not excite a mode beyond the stability limit.
  for (const char* integrator : {"DORMAND_PRINCE", "CENTRAL_DIFFERENCE"}) {
    SCOPED_TRACE(integrator);
    CollectingSink sink;
    RunOk(SceneFromJson(absl::StrFormat(R"({
      "gravity": {"y": -9.81},
      "cables": [{"name": "c", "length": 2, "elements": 4, "direction": {"x": 1},
                  "density": 1000, "youngs_modulus": 1e4, "diameter": 0.01}],
      "probes": [{"name": "end", "cable": "c", "s": 2}],
      "initial_velocity": {"linear": {"x": 3, "y": 4}},
      "solver": {"duration": 1, "step": 2e-3, "output_interval": 0.1, "integrator": "%s"}})",
                                        integrator)),
          &sink);
    for (const Frame& f : sink.frames()) {
      const Eigen::Vector3d exact(2 + 3 * f.t, 4 * f.t - 0.5 * 9.81 * f.t * f.t, 0);
      EXPECT_LT((f.probes[0].position_m - exact).norm(), 1e-11) << "t = " << f.t;
    }
  }
}

TEST(ExplicitStepperTest, FallingPendulumAgreesWithAnImplicitReference) {
  // 1 s (the whipping included) against generalized-alpha (rho 1, the
  // trapezoidal rule's accuracy) at h = 2e-5 with a tight Newton tolerance:
  // its own error, second order from the 1e-3 m it has at 5e-4
  // (bench/frame_error_speed.py), is about 2e-6 m. Bounds, from the same
  // bench against an energy-momentum reference (an independent check):
  // central difference at 5e-4 is within the 1e-3 m the bench asks for;
  // Dormand-Prince at 1e-3 within 5e-5 m (its 1.7e-5 there, with margin).
  const auto reference = Tips(Pendulum(
      1, R"("integrator": "GENERALIZED_ALPHA", "rho_infinity": 1, "step": 2e-5,
            "newton_tolerance": 1e-10)"));
  const double cd =
      LargestDifference(Tips(Pendulum(1, Explicit("CENTRAL_DIFFERENCE", 5e-4))), reference);
  const double dp =
      LargestDifference(Tips(Pendulum(1, Explicit("DORMAND_PRINCE", 1e-3))), reference);
  std::printf("falling pendulum 1 s, largest tip difference to the implicit reference over "
              "10 ms frames: CENTRAL_DIFFERENCE h = 5e-4 %.3g m, DORMAND_PRINCE h = 1e-3 %.3g m\n",
              cd, dp);
  EXPECT_LT(cd, 1e-3);
  EXPECT_LT(dp, 5e-5);
}

// The tip at 0.6 s (a step end for every step below; after the swing's
// first whip, so that the errors stand well above rounding) at h, h/2, h/4
// against a Dormand-Prince run at a far smaller step; returns the two
// error ratios.
std::pair<double, double> ErrorRatios(const char* integrator, double h) {
  const Eigen::Vector3d ref = Tips(Pendulum(0.6, Explicit("DORMAND_PRINCE", h / 16))).back();
  double e[3];
  for (int k = 0; k < 3; ++k)
    e[k] = (Tips(Pendulum(0.6, Explicit(integrator, h / (1 << k)))).back() - ref).norm();
  std::printf("%s tip errors at 0.6 s, h = %g, %g, %g: %.3g, %.3g, %.3g m\n", integrator, h,
              h / 2, h / 4, e[0], e[1], e[2]);
  return {e[0] / e[1], e[1] / e[2]};
}

TEST(ExplicitStepperTest, CentralDifferenceConvergesAtSecondOrder) {
  // Ratios of successive halvings near 2^2 = 4 (in [3, 5]); the reference's
  // own error is below 1e-9 m (fifth order at h / 16).
  const auto [r1, r2] = ErrorRatios("CENTRAL_DIFFERENCE", 5e-4);
  EXPECT_GT(r1, 3);
  EXPECT_LT(r1, 5);
  EXPECT_GT(r2, 3);
  EXPECT_LT(r2, 5);
}

TEST(ExplicitStepperTest, DormandPrinceConvergesAtFifthOrder) {
  // Ratios near 2^5 = 32 (in [20, 48], orders 4.3 to 5.6; a fourth-order
  // method gives 16): the asymptotic range starts where omega_max h is well
  // inside the stability region (at 5e-4 the first ratio is 13), so from
  // h = 2.5e-4; the reference at h / 16 is 1e5 times more accurate, and the
  // finest error (1e-13 m) still stands ten times above rounding.
  const auto [r1, r2] = ErrorRatios("DORMAND_PRINCE", 2.5e-4);
  EXPECT_GT(r1, 20);
  EXPECT_LT(r1, 48);
  EXPECT_GT(r2, 20);
  EXPECT_LT(r2, 48);
}

TEST(ExplicitStepperTest, AdaptiveStepsStayNearTheTolerance) {
  // Adaptive, no step given: the largest tip error over every 10 ms frame of
  // 1 s against a fixed-step Dormand-Prince run at 2.5e-4 (error below
  // 1e-8 m: 1e-10 m at 0.6 s in the order test)
  // stays within 10 tolerances (the local tolerance accumulates over some
  // 1000 steps, most far below it), and the step varies.
  const auto reference = Tips(Pendulum(1, Explicit("DORMAND_PRINCE", 2.5e-4)));
  for (const auto& [integrator, tolerance] :
       {std::pair{"DORMAND_PRINCE", 1e-5}, std::pair{"CENTRAL_DIFFERENCE", 1e-4}}) {
    CollectingSink sink;
    const RunSummary s = RunOk(
        SceneFromJson(Pendulum(1, absl::StrFormat(R"("integrator": "%s", "adaptive": true,
                                                      "tolerance": %g)",
                                                  integrator, tolerance))),
        &sink);
    std::vector<Eigen::Vector3d> tips;
    for (const Frame& f : sink.frames()) tips.push_back(f.probes[0].position_m);
    const double err = LargestDifference(tips, reference);
    std::printf("%s adaptive, tolerance %g m: %lld steps (%lld rejected), steps %.3g to %.3g s, "
                "largest frame tip error %.3g m\n",
                integrator, tolerance, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.min_step_s, s.max_step_s, err);
    EXPECT_LT(err, 10 * tolerance) << integrator;
    EXPECT_GT(s.max_step_s, 1.5 * s.min_step_s) << integrator;
  }
}

TEST(ExplicitStepperTest, DampedPendulumAgreesWithAnImplicitReference) {
  // The falling pendulum with Kelvin-Voigt axial damping (tau = 2e-4 s: a
  // damping ratio omega tau / 2 = 0.11 in the stiffest mode) and
  // mass-proportional damping 0.5 1/s, 0.5 s, against generalized-alpha
  // (rho 1) at h = 2e-5: the velocity-dependent force at central
  // difference's predictor keeps second order (bound: 1e-3 m at 5e-4 s
  // as undamped, the damping only lowering the error) and Dormand-Prince's
  // stages are exact in it (bound 5e-5 m at 1e-3 s, as undamped).
  auto scene = [](const std::string& solver) {
    std::string json = Pendulum(0.5, solver);
    const std::string key = R"("bending": "EXACT")";
    json.replace(json.find(key), key.size(),
                 R"("bending": "EXACT", "damping": {"axial_time": 2e-4, "rayleigh_alpha": 0.5})");
    return json;
  };
  const auto reference = Tips(scene(R"("integrator": "GENERALIZED_ALPHA", "rho_infinity": 1,
                                        "step": 2e-5, "newton_tolerance": 1e-10)"));
  const double cd =
      LargestDifference(Tips(scene(Explicit("CENTRAL_DIFFERENCE", 5e-4))), reference);
  const double dp =
      LargestDifference(Tips(scene(Explicit("DORMAND_PRINCE", 1e-3))), reference);
  std::printf("damped falling pendulum 0.5 s, largest tip difference to the implicit reference: "
              "CENTRAL_DIFFERENCE h = 5e-4 %.3g m, DORMAND_PRINCE h = 1e-3 %.3g m\n",
              cd, dp);
  EXPECT_LT(cd, 1e-3);
  EXPECT_LT(dp, 5e-5);
}

TEST(ExplicitStepperTest, AdaptiveDormandPrinceStaysStableAtLooseTolerances) {
  // At a loose tolerance the error controller alone would grow the step
  // beyond the stability limit (its estimate is small for a mode growing
  // just beyond it); stable_step() caps it. 1 s at tolerances 1e-2 and
  // 1e-3: the runs finish, the energy never rises by 1e-3 of its scale,
  // and no step exceeds the limit of the stiffest mode at rest (1.725 /
  // 1073 rad/s).
  for (double tolerance : {1e-2, 1e-3}) {
    CollectingSink sink;
    const RunSummary s = RunOk(
        SceneFromJson(Pendulum(1, absl::StrFormat(R"("integrator": "DORMAND_PRINCE",
                                                      "adaptive": true, "tolerance": %g)",
                                                  tolerance))),
        &sink);
    double scale = 0;
    for (const Frame& f : sink.frames())
      scale = std::max({scale, std::abs(f.energy.kinetic), std::abs(f.energy.potential)});
    std::printf("DORMAND_PRINCE adaptive, tolerance %g: %lld steps (%lld rejected), largest step "
                "%.3g s, largest energy rise %.3g J of %.3g J\n",
                tolerance, static_cast<long long>(s.steps),
                static_cast<long long>(s.rejected_steps), s.max_step_s, s.energy_max_increase,
                scale);
    EXPECT_LT(s.energy_max_increase, 1e-3 * scale) << tolerance;
    EXPECT_LT(s.max_step_s, 1.725 / 1073) << tolerance;
  }
}

TEST(ExplicitStepperTest, FixedStepBeyondTheStabilityLimitAtTheStartIsRefused) {
  // The falling pendulum's stiffest mode at the start is 1073 rad/s (power
  // iteration; MODAL gives 1076 hanging at rest): central difference's
  // limit is 2 / omega = 1.86e-3 s, Dormand-Prince's 1.725 / omega = 1.61e-3
  // s. h = 1.9e-3 is beyond both: refused before any step, naming the field
  // and the limit; no frame is written.
  for (const char* integrator : {"DORMAND_PRINCE", "CENTRAL_DIFFERENCE"}) {
    SCOPED_TRACE(integrator);
    CollectingSink sink;
    auto summary = RunScene(SceneFromJson(Pendulum(1, Explicit(integrator, 1.9e-3))), &sink);
    ASSERT_TRUE(summary.ok()) << summary.status();
    EXPECT_EQ(summary->status, "failed");
    EXPECT_EQ(summary->failure_time_s, 0);
    EXPECT_NE(summary->error.find(absl::StrCat("solver.step: 0.0019 s is beyond ", integrator,
                                               "'s stability limit")),
              std::string::npos)
        << summary->error;
    EXPECT_TRUE(sink.frames().empty());
  }
  // Within the limit at the start (and adaptive steps, which find it
  // themselves) the run starts.
  CollectingSink within;
  RunOk(SceneFromJson(Pendulum(0.1, Explicit("CENTRAL_DIFFERENCE", 1.8e-3))), &within);
}

TEST(ExplicitStepperTest, InstabilityLaterInTheRunIsReportedNotWritten) {
  // h = 1e-3 is within both limits at the start, but the whips raise the
  // stiffest mode beyond them: both runs stop between 1 and 10 s saying
  // why (the energy guard, or a non-finite acceleration that halving the
  // step from an already grown state cannot cure), and every frame
  // delivered before is finite.
  for (const char* integrator : {"DORMAND_PRINCE", "CENTRAL_DIFFERENCE"}) {
    SCOPED_TRACE(integrator);
    CollectingSink sink;
    auto summary = RunScene(SceneFromJson(Pendulum(10, Explicit(integrator, 1e-3))), &sink);
    ASSERT_TRUE(summary.ok()) << summary.status();
    EXPECT_EQ(summary->status, "failed");
    EXPECT_TRUE(summary->error.find("unstable") != std::string::npos ||
                summary->error.find("stability limit") != std::string::npos)
        << summary->error;
    EXPECT_GT(summary->failure_time_s, 1);
    EXPECT_LT(summary->failure_time_s, 10);
    ASSERT_FALSE(sink.frames().empty());
    for (const Frame& f : sink.frames()) {
      EXPECT_TRUE(f.probes[0].position_m.allFinite()) << "t = " << f.t;
      EXPECT_TRUE(std::isfinite(f.energy.total)) << "t = " << f.t;
    }
  }
}

TEST(ExplicitStepperTest, DormandPrinceRefusesConstraintRowsNamingTheField) {
  // A cable hanging a body: the joint to the body stays as rows (only joints
  // to ground are eliminated). CENTRAL_DIFFERENCE takes them (RATTLE:
  // tests/constrained_explicit_test.cc); DORMAND_PRINCE does not.
  Scene scene = SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "start": {"y": 0}, "direction": {"y": -1}, "length": 2,
                "elements": 4, "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "bodies": [{"name": "hook", "mass": 10, "inertia": {"x": 1, "y": 1, "z": 1},
                "position": {"y": -2.1}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}},
               {"type": "PIN", "a": {"cable": "rope", "s": 2},
                "b": {"body": "hook", "point": {"y": 0.1}}}],
    "solver": {"duration": 1, "integrator": "CENTRAL_DIFFERENCE"}})");
  scene.solver.Use(Integrator::kDormandPrince);
  const auto model = MultibodyModel::Build(scene);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(model.status().message().find("solver.integrator: DORMAND_PRINCE is explicit"),
            std::string::npos)
      << model.status();
  EXPECT_NE(model.status().message().find("joints[1]"), std::string::npos) << model.status();
  // The alternatives offered include CENTRAL_DIFFERENCE now.
  EXPECT_NE(model.status().message().find("CENTRAL_DIFFERENCE"), std::string::npos)
      << model.status();
  scene.solver.Use(Integrator::kCentralDifference);
  EXPECT_TRUE(MultibodyModel::Build(scene).ok());
  // A static analysis does not step: the integrator does not matter there.
  scene.solver.Use(Integrator::kDormandPrince);
  scene.solver.analysis = Analysis::kStatic;
  EXPECT_TRUE(MultibodyModel::Build(scene).ok());
}

TEST(ExplicitStepperTest, ConstrainedCentralDifferenceRefusesBadSettingsNamingTheField) {
  // CENTRAL_DIFFERENCE with rows (scenes/cable-with-end-cylinder.json: a
  // cylinder FIXED to a pinned cable): a fixed step beyond
  // 2 / omega_max (5.2e-5 s here) is refused before the first step, and
  // Newton's settings do not apply to the rows' projection (its tolerance
  // is fixed), so they are refused naming the field.
  const auto scene = [](const std::string& solver) {
    return testing::SampleSceneJsonWithSolver(
        "cable-with-end-cylinder.json", "",
        absl::StrCat(R"("duration": 0.01, "integrator": "CENTRAL_DIFFERENCE", )", solver));
  };
  CollectingSink sink;
  const auto summary = RunScene(SceneFromJson(scene(R"("step": 1e-4)")), &sink);
  ASSERT_TRUE(summary.ok()) << summary.status();
  EXPECT_EQ(summary->status, "failed");
  EXPECT_NE(summary->error.find("solver.step: 0.0001 s is beyond CENTRAL_DIFFERENCE's stability "
                                "limit"),
            std::string::npos)
      << summary->error;
  EXPECT_EQ(RunOk(SceneFromJson(scene(R"("step": 4e-5)")), &sink).status, "ok");
  for (const auto& [setting, field] :
       {std::pair{R"("newton_tolerance": 1e-6)", "solver.newton_tolerance"},
        std::pair{R"("max_newton_iterations": 5)", "solver.max_newton_iterations"},
        std::pair{R"("linear_solver": "MINRES")", "solver.linear_solver"}}) {
    EXPECT_NE(SceneError(scene(absl::StrCat(R"("step": 4e-5, )", setting)))
                  .find(absl::StrCat(field, ": ")),
              std::string::npos)
        << setting;
  }
}

TEST(ExplicitStepperTest, WinchesAreRefusedNamingTheField) {
  Scene scene = SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "start": {"y": -5}, "direction": {"y": 1}, "length": 5,
                "elements": 10, "density": 7850, "youngs_modulus": 1e11, "diameter": 0.02,
                "winch": {"speed": {"constant": -0.1}}}],
    "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 5}}],
    "solver": {"duration": 1, "integrator": "DORMAND_PRINCE"}})");
  const auto model = MultibodyModel::Build(scene);
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.status().message().find(
                "solver.integrator: DORMAND_PRINCE does not take winches (cables[0].winch)"),
            std::string::npos)
      << model.status();
}

TEST(ExplicitStepperTest, NewtonAndLinearSolverSettingsAreRefusedNamingTheField) {
  for (const char* integrator : {"DORMAND_PRINCE", "CENTRAL_DIFFERENCE"}) {
    for (const auto& [setting, field] :
         {std::pair{R"("linear_solver": "MINRES")", "solver.linear_solver"},
          std::pair{R"("linear_solver": "GMRES")", "solver.linear_solver"},
          std::pair{R"("newton_tolerance": 1e-6)", "solver.newton_tolerance"},
          std::pair{R"("max_newton_iterations": 5)", "solver.max_newton_iterations"},
          std::pair{R"("linear_tolerance": 1e-6)", "solver.linear_tolerance"},
          std::pair{R"("max_linear_iterations": 50)", "solver.max_linear_iterations"},
          std::pair{R"("preconditioner": "JACOBI")", "solver.preconditioner"},
          std::pair{R"("accept_inexact_solves": true)", "solver.accept_inexact_solves"},
          std::pair{R"("rho_infinity": 0.8)", "solver.rho_infinity"},
          std::pair{R"("reuse_factorization": true)", "solver.reuse_factorization"}}) {
      const std::string solver = absl::StrFormat(R"("integrator": "%s", %s)", integrator, setting);
      EXPECT_NE(SceneError(Pendulum(1, solver)).find(absl::StrCat(field, ": ")), std::string::npos)
          << integrator << " " << setting;
    }
    // A static solve first uses Newton and the linear solver: the same
    // settings are then accepted.
    EXPECT_EQ(SceneError(Pendulum(1, absl::StrFormat(R"("integrator": "%s",
                                                        "initial_state": "STATIC",
                                                        "newton_tolerance": 1e-6,
                                                        "linear_solver": "MINRES")",
                                                     integrator))),
              "ok");
  }
}

}  // namespace
}  // namespace cablesim
