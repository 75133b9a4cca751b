// A body with several hydrodynamic parts (Body.hydrodynamics_parts, each a
// BodyFluidLoad at the centre of mass; engine/forces/body_fluid_load.h):
// the loads, tangents, added mass and energies of two parts are the sums of
// each part's alone; a rod part along an axis given in the body's frame
// feels the closed-form drag and added mass across and along that axis,
// turning with the body; its drag tangent is the rate derivative; the
// scene's errors name the part's field.

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRho = 1025;

using ::testing::HasSubstr;
using testing::SceneFromJson;

// A held body (mass 500 kg) at `position`, its x axis `axis`, in a current
// and (with `waves`) a regular wave, with `hydro` (the body's
// "hydrodynamics": ..., "hydrodynamics_parts": ... members, or nothing).
std::string BodyJson(const std::string& position, const std::string& axis,
                     const std::string& hydro, bool waves = true,
                     const std::string& gravity = R"({"z": -9.81})",
                     const std::string& current = R"({"x": 0.6, "y": -0.3, "z": 0.1})") {
  return absl::StrFormat(R"({
    "gravity": %s,
    "fluid": {"density": %.17g, "current": %s %s},
    "bodies": [{"name": "b", "mass": 500, "inertia": {"x": 40, "y": 60, "z": 70},
                "position": %s, "axis": %s %s}],
    "solver": {"duration": 10}})",
                         gravity, kRho, current,
                         waves ? R"(, "water_depth": 40,
                                    "waves": {"regular": [{"height": 1.5, "period": 7}]})"
                               : "",
                         position, axis, hydro);
}

// Part A: a buoy's own volume (vertical split, drag areas). Part B: a rod
// clamped across it, along the body's (y + z/2) direction.
constexpr char kPartA[] = R"({"diameter": 1.2, "height": 2, "drag_coefficient": 0.8,
    "heave_drag_coefficient": 1.5, "added_mass": 0.7, "heave_added_mass": 0.9,
    "drag_area": {"x": 0.3, "y": 0.5, "z": 0.2}})";
constexpr char kPartB[] = R"({"diameter": 0.3, "height": 3, "drag_coefficient": 1.2,
    "heave_drag_coefficient": 0.6, "added_mass": 1.0, "heave_added_mass": 0.4,
    "along_axis": true, "axis": {"y": 1, "z": 0.5}})";

// What a model gives at its initial configuration, with rates `zdot`, at
// time t: the net force and its tangent times a probe vector, the damping
// force and its tangent times the probe, the damping power, the potential
// energy and the kinetic energy.
struct Evaluation {
  Eigen::VectorXd net, net_tangent, damping, damping_tangent;
  double power = 0, potential = 0, kinetic = 0;
};

Evaluation Evaluate(const std::string& json) {
  auto model = MultibodyModel::Build(SceneFromJson(json));
  EXPECT_TRUE(model.ok()) << model.status();
  Evaluation e;
  if (!model.ok()) return e;
  const int n = model->dofs(), nq = model->coordinates();
  Eigen::VectorXd zdot(n), probe(n), q(nq), qd(nq);
  for (int i = 0; i < n; ++i) {
    zdot(i) = 0.4 * std::sin(1.3 * i + 0.2);
    probe(i) = std::cos(0.7 * i + 0.5);
  }
  model->SetTime(2.3);
  model->ToFull(model->initial_z(), &q);
  model->RateToFull(zdot, &qd);
  SkylineLdlt k, c;
  k.SetPattern(model->envelope());
  k.SetZero();
  c.SetPattern(model->envelope());
  c.SetZero();
  e.net = Eigen::VectorXd::Zero(n);
  e.damping = Eigen::VectorXd::Zero(n);
  e.net_tangent = Eigen::VectorXd::Zero(n);
  e.damping_tangent = Eigen::VectorXd::Zero(n);
  model->NetForce(q, 1, &e.net, &k, 1.0);
  model->DampingForce(q, qd, &e.damping, &c, 1.0);
  k.Multiply(probe.data(), e.net_tangent.data());
  c.Multiply(probe.data(), e.damping_tangent.data());
  e.power = model->DampingPower(q, qd);
  const EnergySample energy = model->Energy(q, qd, 1);
  e.potential = energy.potential;
  e.kinetic = energy.kinetic;
  return e;
}

// The body with both parts against each part alone (an independent
// evaluation of one BodyFluidLoad each, the path a single-part body always
// took): every load, tangent and energy of the pair is the sum of the
// singles' less the bare body's (its weight, its kinetic energy), to
// rounding (1e-12 of the largest term). The body is tilted and both parts
// pierce the surface in a wave with a current, so buoyancy, its stiffness,
// drag, inertia and the drag areas all act.
TEST(BodyFluidPartsTest, TwoPartsAreTheSumOfEachAlone) {
  const std::string position = R"({"z": -0.4})", axis = R"({"x": 1, "y": 0.4, "z": 0.3})";
  const Evaluation both = Evaluate(BodyJson(
      position, axis,
      absl::StrFormat(R"(, "hydrodynamics": %s, "hydrodynamics_parts": [%s])", kPartA, kPartB)));
  const Evaluation a = Evaluate(BodyJson(position, axis, absl::StrFormat(
                                                             R"(, "hydrodynamics": %s)", kPartA)));
  // Part B alone, given as the only entry of hydrodynamics_parts.
  const Evaluation b = Evaluate(BodyJson(
      position, axis, absl::StrFormat(R"(, "hydrodynamics_parts": [%s])", kPartB)));
  const Evaluation bare = Evaluate(BodyJson(position, axis, ""));
  auto check = [](const char* what, const Eigen::VectorXd& both, const Eigen::VectorXd& a,
                  const Eigen::VectorXd& b, const Eigen::VectorXd& bare) {
    const Eigen::VectorXd sum = a + b - bare;
    const double size = std::max({a.lpNorm<Eigen::Infinity>(), b.lpNorm<Eigen::Infinity>(),
                                  bare.lpNorm<Eigen::Infinity>()});
    std::printf("%s: |both - sum| %.3g of %.3g\n", what, (both - sum).lpNorm<Eigen::Infinity>(),
                size);
    EXPECT_GT((a - bare).lpNorm<Eigen::Infinity>(), 1e-3 * size) << what << ": part A acts";
    EXPECT_GT((b - bare).lpNorm<Eigen::Infinity>(), 1e-3 * size) << what << ": part B acts";
    EXPECT_LT((both - sum).lpNorm<Eigen::Infinity>(), 1e-12 * size) << what;
  };
  check("net force", both.net, a.net, b.net, bare.net);
  check("stiffness x probe", both.net_tangent, a.net_tangent, b.net_tangent, bare.net_tangent);
  check("damping force", both.damping, a.damping, b.damping, bare.damping);
  check("damping x probe", both.damping_tangent, a.damping_tangent, b.damping_tangent,
        bare.damping_tangent);
  for (const auto& [what, x, xa, xb, x0] :
       {std::tuple{"damping power", both.power, a.power, b.power, bare.power},
        std::tuple{"potential", both.potential, a.potential, b.potential, bare.potential},
        std::tuple{"kinetic", both.kinetic, a.kinetic, b.kinetic, bare.kinetic}}) {
    const double size = std::max({std::abs(xa), std::abs(xb), std::abs(x0)});
    std::printf("%s: both %.15g, sum %.15g\n", what, x, xa + xb - x0);
    EXPECT_NE(xa, x0) << what;
    EXPECT_NE(xb, x0) << what;
    EXPECT_NEAR(x, xa + xb - x0, 1e-12 * size) << what;
  }
}

// The damping force's part on the centre of mass (the first D full
// coordinates) at the initial configuration, the body at rest.
Eigen::Vector3d DragOnCentre(const std::string& json) {
  auto model = MultibodyModel::Build(SceneFromJson(json));
  EXPECT_TRUE(model.ok()) << model.status();
  if (!model.ok()) return Eigen::Vector3d::Zero();
  const int nq = model->coordinates(), n = model->dofs();
  Eigen::VectorXd q(nq), qd = Eigen::VectorXd::Zero(nq), f = Eigen::VectorXd::Zero(n);
  model->ToFull(model->initial_z(), &q);
  model->DampingForce(q, qd, &f);
  // f = S^T f_full with S mapping z to q: recover the centre's force from
  // the columns of S (the centre's rows).
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n), col(nq);
    e(j) = 1;
    model->RateToFull(e, &col);
    force.head(model->dimension()) += f(j) * col.head(model->dimension());
  }
  return force;
}

// A horizontal rod part (d 0.3 m, L 3 m, wholly under water) along the
// body's y axis, in a current of 0.8 m/s along or across it: across, the
// drag is 0.5 rho Cd d L |v| v; along, 0.5 rho Cd_end (pi d^2 / 4) |v| v
// (closed forms, to rounding: 1e-12). The body's x axis along the world's
// x puts the rod along the world's y; turned (x along the world's y) the
// rod's body-y is the world's -x, so the same currents swap roles: the
// axis turns with the body. Spatial, and planar (gravity -y, the rod
// along the body's y in the plane). Before hydrodynamics_parts and
// BodyHydrodynamics.axis the scene did not parse; with the body's x axis
// (the only along_axis direction then) the drag would be the other one.
TEST(BodyFluidPartsTest, RodPartDragsAcrossAndAlongItsOwnAxis) {
  const double d = 0.3, length = 3, cd = 1.2, cd_end = 0.6, v = 0.8;
  const std::string part = absl::StrFormat(
      R"(, "hydrodynamics": {"diameter": 1, "height": 1},
         "hydrodynamics_parts": [{"diameter": %.17g, "height": %.17g,
           "drag_coefficient": %.17g, "heave_drag_coefficient": %.17g,
           "along_axis": true, "axis": {"y": 1}}])",
      d, length, cd, cd_end);
  const double across = 0.5 * kRho * cd * d * length * v * v;
  const double along = 0.5 * kRho * cd_end * (kPi * d * d / 4) * v * v;
  struct Case {
    const char* what;
    bool planar, turned;
    int current_axis;  // world axis of the current
    double expected;   // drag along it
  };
  for (const Case& c : {Case{"spatial, current along world y (along the rod)", false, false, 1,
                             along},
                        Case{"spatial, current along world x (across)", false, false, 0, across},
                        Case{"spatial turned, current along world x (along)", false, true, 0,
                             along},
                        Case{"spatial turned, current along world y (across)", false, true, 1,
                             across},
                        Case{"planar, current along world y (along)", true, false, 1, along},
                        Case{"planar, current along world x (across)", true, false, 0, across}}) {
    SCOPED_TRACE(c.what);
    const std::string current = c.current_axis == 0 ? absl::StrFormat(R"({"x": %.17g})", v)
                                                    : absl::StrFormat(R"({"y": %.17g})", v);
    const std::string position = c.planar ? R"({"y": -20})" : R"({"z": -20})";
    const std::string gravity = c.planar ? R"({"y": -9.81})" : R"({"z": -9.81})";
    const std::string axis = c.turned ? R"({"y": 1})" : R"({"x": 1})";
    const Eigen::Vector3d f =
        DragOnCentre(BodyJson(position, axis, part, false, gravity, current));
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    expected(c.current_axis) = c.expected;
    std::printf("%s: drag %.15g, closed form %.15g\n", c.what, f(c.current_axis), c.expected);
    EXPECT_LT((f - expected).norm(), 1e-12 * expected.norm()) << f.transpose();
  }
}

// The added mass of a rod part along the body's y axis (wholly under
// water, V = pi d^2 / 4 L): the kinetic energy of the centre moving at v
// across the rod is (m + Ca rho V) v^2 / 2, along it (m + Ca_end rho V)
// v^2 / 2 (closed form, to rounding).
TEST(BodyFluidPartsTest, RodPartAddedMassAcrossAndAlongItsAxis) {
  const double d = 0.3, length = 3, ca = 1.0, ca_end = 0.25, mass = 500;
  const double volume = kPi * d * d / 4 * length;
  const std::string json = BodyJson(
      R"({"z": -20})", R"({"x": 1})",
      absl::StrFormat(R"(, "hydrodynamics_parts": [{"diameter": %.17g, "height": %.17g,
           "added_mass": %.17g, "heave_added_mass": %.17g, "along_axis": true,
           "axis": {"y": 2}}])",
                      d, length, ca, ca_end),
      false);
  auto model = MultibodyModel::Build(SceneFromJson(json));
  ASSERT_TRUE(model.ok()) << model.status();
  const int nq = model->coordinates();
  Eigen::VectorXd q(nq);
  model->ToFull(model->initial_z(), &q);
  for (const auto& [what, axis, coefficient] :
       {std::tuple{"across (world x)", 0, ca}, std::tuple{"across (world z)", 2, ca},
        std::tuple{"along (world y)", 1, ca_end}}) {
    Eigen::VectorXd qd = Eigen::VectorXd::Zero(nq);
    qd(axis) = 1;  // the centre's velocity, 1 m/s
    const double kinetic = model->Energy(q, qd, 1).kinetic;
    const double expected = 0.5 * (mass + coefficient * kRho * volume);
    std::printf("%s: kinetic %.15g J, closed form %.15g J\n", what, kinetic, expected);
    EXPECT_NEAR(kinetic, expected, 1e-12 * expected) << what;
  }
}

// The velocity Jacobian of a two-part body (a vertical buoy and a tilted
// rod on its own body-frame axis, drag areas, a current, waves) against
// central differences of the damping force (step 1e-6 m/s: truncation
// ~1e-12 relative, rounding ~1e-10): within 1e-6 of the largest entry.
// The rates turn the body, but the drag's dependence on the axis is a
// configuration derivative, not a rate one.
TEST(BodyFluidPartsTest, DragTangentIsTheRateDerivative) {
  auto model = MultibodyModel::Build(SceneFromJson(BodyJson(
      R"({"z": -6})", R"({"x": 1, "y": 0.4, "z": 0.3})",
      // Part A's drag areas made equal (their tangent is exact only then).
      absl::StrFormat(R"(, "hydrodynamics": %s, "hydrodynamics_parts": [%s, %s])",
                      absl::StrReplaceAll(kPartA, {{R"({"x": 0.3, "y": 0.5, "z": 0.2})",
                                                    R"({"x": 0.4, "y": 0.4, "z": 0.4})"}}),
                      kPartB,
                      R"({"diameter": 0.2, "height": 2, "drag_coefficient": 1.1,
                          "heave_drag_coefficient": 0.9, "along_axis": true,
                          "axis": {"x": -1, "z": 2}})"))));
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->body_fluid_loads().size(), 3u);
  double size = 0;
  const double error = testing::DampingTangentError(*model, Eigen::VectorXd(), 1e-6, &size);
  std::printf("tangent error %.3g of %.3g\n", error, size);
  EXPECT_GT(size, 1);
  EXPECT_LT(error, 1e-6 * size);
}

TEST(BodyFluidPartsTest, ValidationNamesThePartsField) {
  auto error = [](const std::string& json) {
    auto proto = ParseSceneJson(json);
    EXPECT_TRUE(proto.ok()) << proto.status();
    if (!proto.ok()) return std::string();
    auto scene = SceneFromProto(*proto);
    EXPECT_FALSE(scene.ok());
    return scene.ok() ? std::string() : std::string(scene.status().message());
  };
  auto parts = [](const std::string& second) {
    return BodyJson(R"({"z": -5})", R"({"x": 1})",
                    absl::StrFormat(R"(, "hydrodynamics_parts": [%s, %s])", kPartB, second));
  };
  EXPECT_THAT(error(parts(R"({"diameter": 0, "height": 1})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].diameter: must be > 0"));
  EXPECT_THAT(error(parts(R"({"height": 1})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].diameter: required for a body given "
                        "by mass"));
  EXPECT_THAT(error(parts(R"({"diameter": 1, "height": 1, "drag_coefficient": -1})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].drag_coefficient: must be >= 0"));
  EXPECT_THAT(error(parts(R"({"diameter": 1, "height": 1, "axis": {"y": 1}})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].axis: only with along_axis"));
  EXPECT_THAT(error(parts(R"({"diameter": 1, "height": 1, "along_axis": true, "axis": {}})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].axis: must be non-zero"));
  EXPECT_THAT(error(parts(R"({"drag_area": {"z": -1}})")),
              HasSubstr("bodies[0].hydrodynamics_parts[1].drag_area.z: must be in [0,"));
  // The axis of `hydrodynamics` too.
  EXPECT_THAT(error(BodyJson(R"({"z": -5})", R"({"x": 1})",
                             R"(, "hydrodynamics": {"diameter": 1, "height": 1,
                                  "axis": {"z": 1}})")),
              HasSubstr("bodies[0].hydrodynamics.axis: only with along_axis"));
  // Parts alone need a fluid.
  std::string dry = parts(R"({"diameter": 1, "height": 1})");
  dry.replace(dry.find(R"("density": 1025)"), 15, R"("density": 0)");
  EXPECT_THAT(error(dry), HasSubstr("bodies[0].hydrodynamics_parts: needs a fluid"));
  // A current that varies in space is refused for a body's drag, naming
  // the field the body was given (parts only here, not `hydrodynamics`).
  const std::string profile =
      R"({}, "current_profile": [{"depth": 0, "velocity": {"x": 1}},
                                 {"depth": 50, "velocity": {"x": 0.5}}])";
  const std::string gravity = R"({"z": -9.81})";
  EXPECT_THAT(error(BodyJson(R"({"z": -5})", R"({"x": 1})",
                             absl::StrFormat(R"(, "hydrodynamics_parts": [%s])", kPartB),
                             /*waves=*/false, gravity, profile)),
              HasSubstr("fluid.current_profile: not taken by bodies[0].hydrodynamics_parts"));
  EXPECT_THAT(error(BodyJson(R"({"z": -5})", R"({"x": 1})",
                             absl::StrFormat(R"(, "hydrodynamics": %s)", kPartA),
                             /*waves=*/false, gravity, profile)),
              HasSubstr("fluid.current_profile: not taken by bodies[0].hydrodynamics "));
}

// A part's axis out of the plane makes the scene spatial: a scene forced
// planar names it.
TEST(BodyFluidPartsTest, PartAxisOutOfThePlaneIsNamed) {
  const std::string json = R"({
    "model": "PLANAR", "gravity": {"y": -9.81}, "fluid": {"density": 1025},
    "bodies": [{"name": "b", "mass": 500, "inertia": {"x": 40, "y": 60, "z": 70},
                "position": {"y": -5},
                "hydrodynamics_parts": [{"diameter": 0.3, "height": 3, "along_axis": true,
                                         "axis": {"x": 1, "z": 1}}]}],
    "solver": {"duration": 1}})";
  auto model = MultibodyModel::Build(SceneFromJson(json));
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(std::string(model.status().message()),
              HasSubstr("bodies[0].hydrodynamics_parts[0].axis.z"));
}

}  // namespace
}  // namespace cablesim
