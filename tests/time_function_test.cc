// Time functions (engine/scene/time_function.h) against their closed forms, and
// the scene validation of prescribed motions and time-varying loads.

#include <cmath>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/scene/time_function.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = std::numbers::pi;

// Integral (a winch's free length) against composite Simpson on a grid
// that has every kink as a node (so Simpson's error is its smooth parts':
// h^4 / 180 max |f''''| ~ 1e-13 at h = 1e-3): a table, a harmonic, a ramp
// starting before and after 0, a constant and a nested sum.
TEST(TimeFunctionTest, IntegralMatchesQuadrature) {
  TimeFunction f = TimeFunction::Table({0.5, 1.0, 2.0}, {1.0, -2.0, 0.5});
  f.set_constant(0.3);
  f.add_harmonic({0.7, 1.3, 0.4});
  f.add_ramp({-0.8, 1.5});
  f.add_term(TimeFunction::Sine(0.2, 0.0, 1.1));  // frequency 0: constant 0.2 sin(1.1)
  f.add_term(TimeFunction::Linear(0.25, 0.0));
  const double h = 1e-3;
  double simpson = 0;
  for (int i = 0; i < 3000; i += 2) {
    const double t = i * h;
    simpson += h / 3 * (f(t) + 4 * f(t + h) + f(t + 2 * h));
    if ((i + 2) % 500 == 0) {
      EXPECT_NEAR(f.Integral(t + 2 * h), simpson, 1e-10) << "t = " << t + 2 * h;
    }
  }
  EXPECT_EQ(f.Integral(0), 0);
}

TEST(TimeFunctionTest, ZeroByDefault) {
  const TimeFunction f;
  EXPECT_TRUE(f.IsZero());
  const TimeFunction::Value v = f.Evaluate(3.0);
  EXPECT_EQ(v.f, 0);
  EXPECT_EQ(v.df, 0);
  EXPECT_EQ(v.ddf, 0);
}

TEST(TimeFunctionTest, HarmonicValueAndDerivativesExact) {
  // A sin(w t + phi): derivatives A w cos, -A w^2 sin (to rounding: 1e-12
  // relative to the largest term, A w^2).
  const double a = 0.3, f = 1.7, phi = 0.4, w = 2 * kPi * f;
  const TimeFunction h = TimeFunction::Sine(a, f, phi);
  for (double t : {0.0, 0.1, 0.77, 5.3}) {
    const TimeFunction::Value v = h.Evaluate(t);
    EXPECT_NEAR(v.f, a * std::sin(w * t + phi), 1e-12 * a);
    EXPECT_NEAR(v.df, a * w * std::cos(w * t + phi), 1e-12 * a * w);
    EXPECT_NEAR(v.ddf, -a * w * w * std::sin(w * t + phi), 1e-12 * a * w * w);
  }
}

TEST(TimeFunctionTest, TableIsPiecewiseLinearWithPiecewiseConstantDerivative) {
  const TimeFunction f = TimeFunction::Table({0, 1, 3}, {0, 2, 1});
  EXPECT_EQ(f.Evaluate(-1).f, 0);  // before the first time: the first value
  EXPECT_EQ(f.Evaluate(-1).df, 0);
  EXPECT_DOUBLE_EQ(f.Evaluate(0.5).f, 1);
  EXPECT_DOUBLE_EQ(f.Evaluate(0.5).df, 2);
  EXPECT_DOUBLE_EQ(f.Evaluate(2).f, 1.5);
  EXPECT_DOUBLE_EQ(f.Evaluate(2).df, -0.5);
  // At a breakpoint, the segment that starts there (right derivative).
  EXPECT_DOUBLE_EQ(f.Evaluate(1).f, 2);
  EXPECT_DOUBLE_EQ(f.Evaluate(1).df, -0.5);
  EXPECT_EQ(f.Evaluate(1).ddf, 0);  // documented: no impulse at the kink
  EXPECT_EQ(f.Evaluate(7).f, 1);    // after the last time: the last value
  EXPECT_EQ(f.Evaluate(7).df, 0);
}

TEST(TimeFunctionTest, RampStartsAtItsStart) {
  const TimeFunction r = TimeFunction::Linear(2.5, 1.0);
  EXPECT_EQ(r.Evaluate(0.5).f, 0);
  EXPECT_EQ(r.Evaluate(0.5).df, 0);
  EXPECT_DOUBLE_EQ(r.Evaluate(3).f, 5);
  EXPECT_DOUBLE_EQ(r.Evaluate(3).df, 2.5);
}

TEST(TimeFunctionTest, PartsAndTermsAdd) {
  TimeFunction f = TimeFunction::Constant(1);
  f.add_harmonic({2, 0.5, 0});
  f.add_term(TimeFunction::Linear(3, 0));
  f.add_term(TimeFunction::Sine(1, 1, kPi / 2));
  const double t = 0.3, w1 = kPi, w2 = 2 * kPi;
  const TimeFunction::Value v = f.Evaluate(t);
  EXPECT_NEAR(v.f, 1 + 2 * std::sin(w1 * t) + 3 * t + std::cos(w2 * t), 1e-12);
  EXPECT_NEAR(v.df, 2 * w1 * std::cos(w1 * t) + 3 - w2 * std::sin(w2 * t), 1e-12);
  EXPECT_NEAR(v.ddf, -2 * w1 * w1 * std::sin(w1 * t) - w2 * w2 * std::cos(w2 * t), 1e-11);
}

// A ramp times a harmonic, s max(0, t - t0) A sin(w t + phi), against the
// product rule's closed form: f' = s A sin + s (t - t0) A w cos,
// f'' = 2 s A w cos - s (t - t0) A w^2 sin (after t0; 0 before).
// Tolerance: rounding, 1e-12 relative to the largest term (s t A w^2 ~ 60).
TEST(TimeFunctionTest, ProductOfRampAndHarmonicFollowsTheProductRule) {
  const double slope = 0.2, t0 = 0.5, a = 1.5, freq = 0.8, phi = 0.3, w = 2 * kPi * freq;
  TimeFunction f;
  f.add_product({TimeFunction::Linear(slope, t0), TimeFunction::Sine(a, freq, phi)});
  EXPECT_FALSE(f.IsZero());
  EXPECT_TRUE(f.HasProduct());
  for (double t : {0.0, 0.4, 0.5, 0.9, 3.7, 10.2}) {
    const TimeFunction::Value v = f.Evaluate(t);
    const double r = t >= t0 ? slope * (t - t0) : 0, dr = t >= t0 ? slope : 0;
    const double sn = std::sin(w * t + phi), cs = std::cos(w * t + phi);
    EXPECT_NEAR(v.f, r * a * sn, 1e-12 * 60) << t;
    EXPECT_NEAR(v.df, dr * a * sn + r * a * w * cs, 1e-12 * 60) << t;
    EXPECT_NEAR(v.ddf, 2 * dr * a * w * cs - r * a * w * w * sn, 1e-12 * 60) << t;
  }
}

// Three factors, one a sum: 2 (A1 sin a)(A2 sin b + c) with a = w1 t,
// b = w2 t + phi: the second derivative has the cross term
// 2 f' g' that a two-factor rule applied wrongly would miss.
TEST(TimeFunctionTest, ProductOfThreeFactorsAndASumFollowsTheProductRule) {
  const double a1 = 0.7, f1 = 0.3, a2 = 1.2, f2 = 1.1, phi = 0.9, c = 0.4;
  const double w1 = 2 * kPi * f1, w2 = 2 * kPi * f2;
  TimeFunction sum = TimeFunction::Sine(a2, f2, phi);
  sum.add_term(TimeFunction::Constant(c));
  TimeFunction f = TimeFunction::Constant(1.0);  // other parts still add
  f.add_product({TimeFunction::Constant(2), TimeFunction::Sine(a1, f1, 0), sum});
  for (double t : {0.0, 0.37, 1.9, 7.25}) {
    const double sa = std::sin(w1 * t), ca = std::cos(w1 * t);
    const double g = a2 * std::sin(w2 * t + phi) + c, dg = a2 * w2 * std::cos(w2 * t + phi),
                 ddg = -a2 * w2 * w2 * std::sin(w2 * t + phi);
    const TimeFunction::Value v = f.Evaluate(t);
    EXPECT_NEAR(v.f, 1 + 2 * a1 * sa * g, 1e-12 * 20) << t;
    EXPECT_NEAR(v.df, 2 * a1 * (w1 * ca * g + sa * dg), 1e-12 * 20) << t;
    EXPECT_NEAR(v.ddf, 2 * a1 * (-w1 * w1 * sa * g + 2 * w1 * ca * dg + sa * ddg), 1e-12 * 200)
        << t;
  }
}

// A product with a zero factor adds nothing; a product has no closed-form
// integral (NaN: a winch's speed refuses products, below).
TEST(TimeFunctionTest, ProductWithAZeroFactorIsZeroAndHasNoIntegral) {
  TimeFunction zero;
  zero.add_product({TimeFunction::Sine(1, 1, 0), TimeFunction()});
  EXPECT_TRUE(zero.IsZero());
  EXPECT_FALSE(zero.HasProduct());
  TimeFunction f;
  TimeFunction inner;
  inner.add_product({TimeFunction::Sine(1, 1, 0), TimeFunction::Linear(1, 0)});
  f.add_term(inner);
  EXPECT_TRUE(f.HasProduct());
  EXPECT_TRUE(std::isnan(f.Integral(1.0)));
}

absl::Status Validate(const std::string& json) {
  auto proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  return SceneFromProto(*proto).status();
}

std::string PinnedRope(const std::string& motion) {
  return R"({"cables": [{"name": "rope", "length": 1, "density": 1000, "youngs_modulus": 1e9,
               "diameter": 0.01}],
             "joints": [{"type": "PIN", "a": {"cable": "rope", "s": 0}, "motion": )" +
         motion + R"(}], "solver": {"duration": 1}})";
}

TEST(TimeFunctionValidationTest, NamesTheField) {
  EXPECT_TRUE(Validate(PinnedRope(R"({"x": {"harmonic": {"amplitude": 0.1, "frequency": 1}}})")).ok());
  absl::Status s = Validate(PinnedRope(R"({"x": {"table": {"times": [0, 2, 1], "values": [0, 1, 2]}}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.x.table.times: times must increase"));
  s = Validate(PinnedRope(R"({"y": {"table": {"times": [0, 1], "values": [0]}}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.y.table.values: must have as many"));
  s = Validate(PinnedRope(R"({"x": {"harmonic": {"amplitude": 1, "frequency": -1}}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.x.harmonic.frequency: must be >= 0"));
  s = Validate(PinnedRope(R"({"x": {"sum": [{"ramp": {"slope": 1, "start": -1}}]}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.x.sum[0].ramp.start: must be >= 0"));
  // A ramp in (a table from 0 to 1 over 20 s) times a harmonic: the
  // fields of each factor are checked and named.
  EXPECT_TRUE(Validate(PinnedRope(R"({"x": {"product": [{"table": {"times": [0, 20],
      "values": [0, 1]}}, {"harmonic": {"amplitude": 2, "frequency": 0.1}}]}})")).ok());
  s = Validate(PinnedRope(R"({"x": {"product": [{"ramp": {"slope": 1}},
      {"harmonic": {"amplitude": 1, "frequency": -1}}]}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.x.product[1].harmonic.frequency: must be"));
  std::string deep = R"({"ramp": {"slope": 1}})";
  for (int k = 0; k < 8; ++k) deep = R"({"product": [)" + deep + R"(, {"constant": 1}]})";
  s = Validate(PinnedRope(R"({"x": )" + deep + "}"));
  EXPECT_THAT(s.message(), HasSubstr("levels of sum and product"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.x.product[0].product[0]"));
  // A winch's free length integrates its speed: no product there.
  s = Validate(R"({"gravity": {"y": -9.81},
      "cables": [{"name": "c", "length": 1, "density": 7850, "youngs_modulus": 2e11,
                  "diameter": 0.01, "winch": {"speed": {"product": [{"constant": 1},
                  {"harmonic": {"amplitude": 0.1, "frequency": 1}}]}}}],
      "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1}}], "solver": {"duration": 1}})");
  EXPECT_THAT(s.message(), HasSubstr("cables[0].winch.speed: a product is not available"));
  // The scene places the joint at t = 0: a motion must start at 0.
  s = Validate(PinnedRope(R"({"z": {"constant": 0.5}})"));
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion.z: must be 0 at t = 0"));
}

TEST(TimeFunctionValidationTest, OnlyJointsToGroundMoveAndTorquesOnBodies) {
  absl::Status s = Validate(R"({"cables": [{"name": "a", "length": 1, "density": 1000,
        "youngs_modulus": 1e9, "diameter": 0.01},
      {"name": "b", "start": {"x": 1}, "length": 1, "density": 1000, "youngs_modulus": 1e9,
        "diameter": 0.01}],
      "joints": [{"type": "PIN", "a": {"cable": "a", "s": 1}, "b": {"cable": "b", "s": 0},
                  "motion": {"x": {"ramp": {"slope": 1}}}}], "solver": {"duration": 1}})");
  EXPECT_THAT(s.message(), HasSubstr("joints[0].motion: only a joint to ground moves"));
  s = Validate(R"({"cables": [{"name": "a", "length": 1, "density": 1000,
        "youngs_modulus": 1e9, "diameter": 0.01}],
      "loads": [{"at": {"cable": "a", "s": 1},
                 "varying_torque": {"z": {"harmonic": {"amplitude": 1, "frequency": 1}}}}],
      "solver": {"duration": 1}})");
  EXPECT_THAT(s.message(), HasSubstr("loads[0].varying_torque: allowed on bodies only"));
}

}  // namespace
}  // namespace cablesim
