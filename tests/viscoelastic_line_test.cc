// The viscoelastic axial law (axial_law VISCOELASTIC,
// engine/elements/viscoelastic_history.h) against an independent solution
// of its differential equation, and the scene's refusals.
//
// A 10 m bar (1 cm diameter, nearly massless) is pinned at s = 0 and its
// end is pulled from rest by x(t) = V t - V sin(w t) / w (V = 0.01 m/s,
// w = pi rad/s), so its engineering strain is e(t) = x(t) / L, the same
// at every section, and its rate changes sign of curvature every second:
// the dashpots carry a share of the tension that changes with it. The
// reference integrates the law's equation
//
//   (BA + BA_D) de_1/dt = EA_2 e - (EA_1 + EA_2) e_1 + BA_D de/dt,
//   T = EA_1 e_1 + BA de_1/dt,
//
// by the classical Runge-Kutta method at 1e-5 s (its error is below 1e-12
// of T here), with EA_2 = a + beta EA_1 e_1 re-evaluated at every stage for
// the mean-load law. The engine's error, over its step h, has one
// first-order part: the fast dashpot sees the mean strain rate over the
// step (the rate of e linear in time), not the rate at its end, off by up
// to h/2 max|e''|, so T by BA BA_D / (BA + BA_D) h/2 max|e''|. The tolerance
// is twice that bound plus 1e-6 of T (2.3 mN at h = 2 ms against
// tensions of 8-30 N). The static law alone (T = EA e) is off by up to
// 6 N here, and a law without the fast dashpot by 0.4 N: both fail.

#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "convert/plausibility_warnings.h"
#include "engine/elements/viscoelastic_history.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using ::testing::HasSubstr;
using testing::RunOk;
using testing::SceneError;
using testing::SceneFromJson;

constexpr double kV = 0.01, kW = M_PI, kLength = 10;
const double kArea = M_PI / 4 * 1e-4;
const double kEa = 1e8 * kArea;  // static EA [N], 7,854 N

// The bar's scene: `visco` is the Viscoelastic message's JSON; `extra` adds
// top-level members (a body and a joint of its own).
std::string Bar(const std::string& visco, double step, const std::string& integrator = "HHT",
                const std::string& extra = "", const std::string& extra_joint = "") {
  return absl::StrFormat(R"({%s
    "cables": [{"name": "bar", "points": [{"x": 0}, {"x": 10}], "elements": 2, "density": 1,
                "youngs_modulus": 1e8, "diameter": 0.01, "axial_law": "VISCOELASTIC",
                "viscoelastic": %s}],
    "joints": [{"type": "PIN", "a": {"cable": "bar", "s": 0}},
               {"type": "PIN", "a": {"cable": "bar", "s": 10},
                "motion": {"x": {"ramp": {"slope": %.17g},
                                 "harmonic": {"amplitude": %.17g, "frequency": 0.5}}}}%s],
    "probes": [{"name": "mid", "cable": "bar", "s": 5}, {"name": "end", "cable": "bar", "s": 10}],
    "output": {"tension": true},
    "solver": {"duration": 4, "step": %.17g, "output_interval": 0.25, "integrator": "%s"}})",
                         extra, visco, kV, -kV / kW, extra_joint, step, integrator);
}

struct Reference {
  std::vector<double> tension;  // at t = 0, 0.25, ..., 4
  double dissipated = 0;        // [J] over the bar, to t = 4
};

// The equation above by RK4; `ea2_of` gives EA_2 from e_1.
template <typename Ea2>
Reference Solve(Ea2 ea2_of, double ba, double bd) {
  auto strain = [](double t) { return (kV * t - kV * std::sin(kW * t) / kW) / kLength; };
  auto rate = [](double t) { return kV * (1 - std::cos(kW * t)) / kLength; };
  auto slope = [&](double t, double e1) {
    const double ea2 = ea2_of(e1), ea1 = ea2 * kEa / (ea2 - kEa);
    return (ea2 * strain(t) - (ea1 + ea2) * e1 + bd * rate(t)) / (ba + bd);
  };
  auto power = [&](double t, double e1) {  // per unit length
    const double r1 = slope(t, e1), r2 = rate(t) - r1;
    return ba * r1 * r1 + bd * r2 * r2;
  };
  Reference ref;
  const double dt = 1e-5;
  const int per_frame = 25000;
  double e1 = 0, t = 0;
  for (int frame = 0; frame <= 16; ++frame) {
    const double ea2 = ea2_of(e1), ea1 = ea2 * kEa / (ea2 - kEa);
    ref.tension.push_back(ea1 * e1 + ba * slope(t, e1));
    if (frame == 16) break;
    for (int i = 0; i < per_frame; ++i) {
      const double k1 = slope(t, e1), k2 = slope(t + dt / 2, e1 + dt / 2 * k1),
                   k3 = slope(t + dt / 2, e1 + dt / 2 * k2), k4 = slope(t + dt, e1 + dt * k3);
      const double p0 = power(t, e1);
      e1 += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += dt;
      ref.dissipated += kLength * dt / 2 * (p0 + power(t, e1));
    }
  }
  return ref;
}

void ExpectFollows(const std::string& scene, const Reference& ref, double ba, double bd,
                   double step) {
  CollectingSink sink;
  const RunSummary summary = RunOk(SceneFromJson(scene), &sink);
  ASSERT_EQ(sink.frames().size(), ref.tension.size());
  // |e''| <= V w / L.
  const double bound = ba * bd / (ba + bd) * step / 2 * kV * kW / kLength;
  double largest_static_miss = 0;
  for (size_t i = 1; i < ref.tension.size(); ++i) {
    const Frame& f = sink.frames()[i];
    const double tol = 2 * bound + 1e-6 * std::abs(ref.tension[i]);
    ASSERT_EQ(f.probe_tensions.size(), 2u);
    for (double tension : f.probe_tensions) EXPECT_NEAR(tension, ref.tension[i], tol) << "t = " << f.t;
    ASSERT_EQ(f.support_forces.size(), 1u);
    EXPECT_NEAR(f.support_forces[0].x(), ref.tension[i], tol) << "t = " << f.t;
    const double x = kV * f.t - kV * std::sin(kW * f.t) / kW;
    largest_static_miss = std::max(largest_static_miss, std::abs(ref.tension[i] - kEa * x / kLength) / tol);
  }
  EXPECT_GT(largest_static_miss, 100);  // the dashpots' share, in tolerances
  // energy.damped: the dashpots' work, within 1 % (the trapezoidal rule on
  // the power at the step ends).
  EXPECT_NEAR(summary.energy_damped, ref.dissipated, 0.01 * ref.dissipated);
}

TEST(ViscoelasticLineTest, ConstantDynamicStiffnessFollowsItsEquation) {
  const double ea2 = 3 * kEa, ba = 2 * kEa, bd = 0.25 * kEa;
  const Reference ref = Solve([&](double) { return ea2; }, ba, bd);
  const std::string visco = absl::StrFormat(
      R"({"dynamic_ea": %.17g, "static_damping": %.17g, "dynamic_damping": %.17g})", ea2, ba, bd);
  ExpectFollows(Bar(visco, 0.002), ref, ba, bd, 0.002);
}

// A joint elsewhere that lets go at t = 2 s rebuilds the model
// (engine/run/joint_release.h): the bar's law goes on with its state
// (without it, the relaxed law from there on is off by 5 N).
TEST(ViscoelasticLineTest, StateSurvivesAJointLettingGo) {
  const double ea2 = 3 * kEa, ba = 2 * kEa, bd = 0.25 * kEa;
  const Reference ref = Solve([&](double) { return ea2; }, ba, bd);
  const std::string visco = absl::StrFormat(
      R"({"dynamic_ea": %.17g, "static_damping": %.17g, "dynamic_damping": %.17g})", ea2, ba, bd);
  ExpectFollows(Bar(visco, 0.002, "HHT",
                    R"("bodies": [{"name": "block", "mass": 1, "position": {"y": 5},
                                   "inertia": {"x": 0.1, "y": 0.1, "z": 0.1}}],)",
                    R"(, {"type": "PIN", "a": {"body": "block"}, "release": {"time": 2}})"),
                ref, ba, bd, 0.002);
}

// Held at a stretch from the start, a line under the mean-load law is at
// rest: its tension stays EA e (the start's EA_2 is the law's at the
// static tension, EA_2 = a + beta EA e; the start from the unloaded
// stiffness was 7 % low at 5 % strain with beta = 20 and rang).
TEST(ViscoelasticLineTest, MeanLoadLineHeldStretchedStaysAtRest) {
  const double a = 2 * kEa, beta = 20, ba = 2 * kEa, bd = 0.25 * kEa;
  const std::string json = absl::StrFormat(R"({
    "cables": [{"name": "bar", "points": [{"x": 0}, {"x": 10.5}], "length": 10, "elements": 2,
                "density": 1, "youngs_modulus": 1e8, "diameter": 0.01,
                "axial_law": "VISCOELASTIC",
                "viscoelastic": {"dynamic_ea_base": %.17g, "dynamic_ea_slope": %.17g,
                                 "static_damping": %.17g, "dynamic_damping": %.17g}}],
    "joints": [{"type": "PIN", "a": {"cable": "bar", "s": 0}},
               {"type": "PIN", "a": {"cable": "bar", "s": 10}}],
    "probes": [{"name": "mid", "cable": "bar", "s": 5}],
    "output": {"tension": true},
    "solver": {"duration": 2, "step": 0.01, "output_interval": 0.5, "integrator": "HHT"}})",
                                           a, beta, ba, bd);
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(sink.frames().size(), 5u);
  for (const Frame& f : sink.frames())
    EXPECT_NEAR(f.probe_tensions[0], 0.05 * kEa, 1e-9 * 0.05 * kEa) << "t = " << f.t;
}

TEST(ViscoelasticLineTest, MeanLoadStiffnessFollowsItsEquation) {
  // EA_2 = a + beta T_m with T_m = EA_1 e_1 (MoorDyn's alphaMBL and beta).
  const double a = 1.5 * kEa, beta = 40, ba = 2 * kEa, bd = 0.25 * kEa;
  const ViscoelasticHistory::Law law{kEa, 0, a, beta, ba, bd};
  const Reference ref =
      Solve([&](double e1) { return ViscoelasticHistory::DynamicStiffness(law, e1); }, ba, bd);
  // The law's closed form is the root of EA_2 = a + beta EA_1(EA_2) e_1.
  const double e1 = 1e-3, ea2 = ViscoelasticHistory::DynamicStiffness(law, e1);
  EXPECT_NEAR(ea2, a + beta * ViscoelasticHistory::SlowStiffness(law, ea2) * e1, 1e-9 * ea2);
  ExpectFollows(Bar(absl::StrFormat(R"({"dynamic_ea_base": %.17g, "dynamic_ea_slope": %.17g,
                                        "static_damping": %.17g, "dynamic_damping": %.17g})",
                                    a, beta, ba, bd),
                    0.002),
                ref, ba, bd, 0.002);
}

// Held at a constant stretch the dashpots relax to the static law:
// T -> EA e, with the slow part's time constant (BA + BA_D) / (EA_1 + EA_2).
TEST(ViscoelasticLineTest, StepCoefficientsRelaxToTheStaticLaw) {
  const ViscoelasticHistory::Law law{kEa, 3 * kEa, 0, 0, 2 * kEa, 0.25 * kEa};
  const double ea2 = 3 * kEa, ea1 = ViscoelasticHistory::SlowStiffness(law, ea2);
  EXPECT_NEAR(ea1 * ea2 / (ea1 + ea2), kEa, 1e-12 * kEa);
  // A long step from e_1 = 0 at e = 1e-3 held: T = EA e.
  const auto c = ViscoelasticHistory::StepCoefficients(law, ea1, ea2, 1e-3, 0, 1e3);
  EXPECT_NEAR(c.k * 1e-3 + c.p, kEa * 1e-3, 1e-9 * kEa * 1e-3);
  // A short one (1e-7 s, where the series of psi is used) from a rested
  // state at the same strain: still T = EA e (nothing moved).
  const double e1 = ea2 / (ea1 + ea2) * 1e-3;
  const auto s = ViscoelasticHistory::StepCoefficients(law, ea1, ea2, 1e-3, e1, 1e-7);
  EXPECT_NEAR(s.k * 1e-3 + s.p, kEa * 1e-3, 1e-9 * kEa * 1e-3);
}

// The fixed-step warning measures a viscoelastic line's axial bounce on its
// dynamic stiffness: the bar's is 2.09 ms with EA_2 = 3 EA (3.63 ms with
// the static EA), so a 3 ms step is warned about.
TEST(ViscoelasticLineTest, StepWarningUsesTheDynamicStiffness) {
  const std::string json = Bar(R"({"dynamic_ea": 23561.9, "static_damping": 1e4})", 0.003);
  const absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  ASSERT_TRUE(proto.ok()) << proto.status();
  const std::vector<std::string> warnings = PlausibilityWarnings(*proto, SceneFromJson(json));
  EXPECT_THAT(warnings, ::testing::Contains(HasSubstr(
                            "solver.step: 0.003 s is above the shortest period the scene's "
                            "cables resolve, 0.00209 s")));
}

TEST(ViscoelasticLineTest, RefusalsNameTheField) {
  const std::string good = R"({"dynamic_ea": 3e4, "static_damping": 1e4})";
  EXPECT_THAT(SceneError(Bar(good, 0.01, "CENTRAL_DIFFERENCE")),
              HasSubstr("solver.integrator: CENTRAL_DIFFERENCE does not apply to cables[0]"));
  EXPECT_THAT(SceneError(Bar(good, 0.01, "ENERGY_MOMENTUM")),
              HasSubstr("solver.integrator: ENERGY_MOMENTUM does not apply"));
  EXPECT_THAT(SceneError(Bar(R"({"dynamic_ea": 5000, "static_damping": 1e4})", 0.01)),
              HasSubstr("cables[0].viscoelastic.dynamic_ea: must exceed the static EA"));
  EXPECT_THAT(SceneError(Bar(R"({"dynamic_ea": 3e4})", 0.01)),
              HasSubstr("cables[0].viscoelastic.static_damping: static_damping + "
                        "dynamic_damping must be > 0"));
  EXPECT_THAT(SceneError(Bar(R"({"dynamic_ea_base": 3e4, "static_damping": 1e4})", 0.01)),
              HasSubstr("cables[0].viscoelastic.dynamic_ea_slope: required"));
  EXPECT_THAT(
      SceneError(Bar(R"({"dynamic_ea": 3e4, "dynamic_ea_slope": 1, "static_damping": 1e4})",
                     0.01)),
      HasSubstr("cables[0].viscoelastic.dynamic_ea_slope: not with dynamic_ea"));
  std::string no_law = Bar(good, 0.01);
  const std::string law = R"("axial_law": "VISCOELASTIC")";
  no_law.replace(no_law.find(law), law.size(), R"("axial_law": "ENGINEERING")");
  EXPECT_THAT(SceneError(no_law),
              HasSubstr("cables[0].viscoelastic: only with axial_law VISCOELASTIC"));
}

}  // namespace
}  // namespace cablesim
