// A body with several hydrodynamic parts (Body.hydrodynamics_parts, each a
// BodyFluidLoad at the centre of mass or off it; engine/forces/body_fluid_load.h):
// the loads, tangents, added mass and energies of two parts are the sums of
// each part's alone; a rod part along an axis given in the body's frame
// feels the closed-form drag and added mass across and along that axis,
// turning with the body; its drag tangent is the rate derivative; the
// scene's errors name the part's field. A part off the centre of mass:
// its force is the energy's gradient, its tangents the derivatives, its
// added mass that of its centre, and a float off a pin rights the body and
// swings it at the closed-form frequency.

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
#include "tests/net_force_derivatives.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRho = 1025;

using ::testing::HasSubstr;
using testing::CollectingSink;
using testing::RunOk;
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

// The damping tangent against central differences of the damping force in
// the rates (step 1e-6 m/s: truncation ~1e-12 relative, rounding ~1e-10):
// within 1e-6 of the largest entry, which must not be trivial.
void ExpectDragTangentIsTheRateDerivative(MultibodyModel& model) {
  double size = 0;
  const double error = testing::DampingTangentError(model, Eigen::VectorXd(), 1e-6, &size);
  std::printf("tangent error %.3g of %.3g\n", error, size);
  EXPECT_GT(size, 1);
  EXPECT_LT(error, 1e-6 * size);
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
  ExpectDragTangentIsTheRateDerivative(*model);
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

// ---- Parts off the centre of mass (BodyHydrodynamics.center) -------------

// A part's centre from the body's natural coordinates, computed here from
// its definition r_p = r_c + c_1 e1 + c_2 e2 + c_3 e3 (the body is the
// scene's only one: its coordinates are the first 12), and the same map of
// the rates (its velocity).
Eigen::Vector3d PartPoint(const Eigen::VectorXd& x, const Eigen::Vector3d& c) {
  Eigen::Vector3d r = x.head<3>();
  for (int k = 0; k < 3; ++k) r += c(k) * x.segment<3>(3 + 3 * k);
  return r;
}

// A tilted body whose rod part sits off its centre of mass, piercing the
// surface in a wave: the generalised force is minus the gradient of the
// energy, and the stiffness the force's derivative, by central differences
// in every unknown (step 1e-6: truncation ~1e-12, rounding ~1e-10 of the
// largest term; tolerances 1e-6 and 1e-5 of it, as the bed's test).
TEST(BodyFluidPartsTest, OffCentrePartForceIsTheEnergysGradientAndItsTangentTheForces) {
  const Eigen::Vector3d c(1.5, -0.8, 2.2);
  const std::string json = BodyJson(
      R"({"z": -2.8})", R"({"x": 1, "y": 0.4, "z": 0.3})",
      absl::StrFormat(R"(, "hydrodynamics_parts": [{"diameter": 0.8, "height": 3,
           "drag_coefficient": 1.1, "added_mass": 0.9, "heave_added_mass": 0.3,
           "center": {"x": %.17g, "y": %.17g, "z": %.17g}}])",
                      c.x(), c.y(), c.z()),
      false);
  auto m = MultibodyModel::Build(SceneFromJson(json));
  ASSERT_TRUE(m.ok()) << m.status();
  const int n = m->dofs(), nq = m->coordinates();
  Eigen::VectorXd z = m->initial_z(), q(nq), f = Eigen::VectorXd::Zero(n);
  m->ToFull(z, &q);
  // The part pierces the still level (z = 0): its buoyancy varies.
  const double height = PartPoint(q, c).z();
  std::printf("part centre at z = %.6g m (half height 1.5 m)\n", height);
  ASSERT_LT(std::abs(height), 1.5);
  ASSERT_GT(std::abs(height), 0.1);
  const testing::NetForceDerivativeErrors e = testing::NetForceDerivatives(*m, 1e-6);
  std::printf("force error %.3g of %.3g, stiffness error %.3g of %.3g\n", e.force, e.force_size,
              e.matrix, e.matrix_size);
  EXPECT_LT(e.force, 1e-6 * e.force_size);
  EXPECT_LT(e.matrix, 1e-5 * e.matrix_size);
  m->NetForce(q, 1.0, &f);
  // The part's buoyancy turns the body: the force on the axes is not zero.
  EXPECT_GT(f.segment(3, 9).lpNorm<Eigen::Infinity>(), 1e-3 * e.force_size);
}

// The added mass of a part off the centre of mass is that of its centre:
// the body's kinetic energy with the part less the bare body's is
// (1/2) v_p^T rho V (C_ah (I - up up^T) + C_av up up^T) v_p, v_p = rdot_c +
// sum c_k edot_k computed here, for rates that turn and move the body (to
// rounding, 1e-12). The part is wholly under water (V its whole volume).
TEST(BodyFluidPartsTest, OffCentrePartAddedMassIsThatOfItsCentre) {
  const Eigen::Vector3d c(0.7, 1.9, -1.3);
  const double d = 0.6, length = 2.5, ca = 0.8, ca_v = 0.35;
  auto json = [&](bool part) {
    return BodyJson(R"({"z": -20})", R"({"x": 1, "y": -0.3, "z": 0.6})",
                    part ? absl::StrFormat(R"(, "hydrodynamics_parts": [{"diameter": %.17g,
                               "height": %.17g, "added_mass": %.17g, "heave_added_mass": %.17g,
                               "center": {"x": %.17g, "y": %.17g, "z": %.17g}}])",
                                           d, length, ca, ca_v, c.x(), c.y(), c.z())
                         : "",
                    false);
  };
  auto with = MultibodyModel::Build(SceneFromJson(json(true)));
  auto bare = MultibodyModel::Build(SceneFromJson(json(false)));
  ASSERT_TRUE(with.ok()) << with.status();
  ASSERT_TRUE(bare.ok()) << bare.status();
  const int nq = with->coordinates(), n = with->dofs();
  Eigen::VectorXd q(nq), qd(nq), zdot(n);
  with->ToFull(with->initial_z(), &q);
  for (int i = 0; i < n; ++i) zdot(i) = 0.5 * std::sin(0.9 * i + 0.3);
  with->RateToFull(zdot, &qd);
  const Eigen::Vector3d v = PartPoint(qd, c);
  ASSERT_GT(v.norm(), 0.1);
  const Eigen::Matrix3d vertical = Eigen::Vector3d::UnitZ() * Eigen::Vector3d::UnitZ().transpose();
  const double volume = kPi * d * d / 4 * length;
  const Eigen::Matrix3d ma =
      kRho * volume * (ca * (Eigen::Matrix3d::Identity() - vertical) + ca_v * vertical);
  const double expected = 0.5 * v.dot(ma * v);
  const double got = with->Energy(q, qd, 1).kinetic - bare->Energy(q, qd, 1).kinetic;
  std::printf("added kinetic energy %.15g J, closed form %.15g J\n", got, expected);
  EXPECT_NEAR(got, expected, 1e-12 * with->Energy(q, qd, 1).kinetic);
  // Off the centre, the rotation alone moves the part: rates of the axes
  // only (r_c at rest) still carry its added mass.
  Eigen::VectorXd spin = qd;
  spin.head<3>().setZero();
  const Eigen::Vector3d vs = PartPoint(spin, c);
  EXPECT_NEAR(with->Energy(q, spin, 1).kinetic - bare->Energy(q, spin, 1).kinetic,
              0.5 * vs.dot(ma * vs), 1e-12 * with->Energy(q, spin, 1).kinetic);
}

// The drag and inertia of a part off the centre of mass, with waves and a
// current: the damping tangent is the rate derivative (central differences,
// as DragTangentIsTheRateDerivative).
TEST(BodyFluidPartsTest, OffCentrePartDragTangentIsTheRateDerivative) {
  auto model = MultibodyModel::Build(SceneFromJson(BodyJson(
      R"({"z": -6})", R"({"x": 1, "y": 0.4, "z": 0.3})",
      absl::StrFormat(R"(, "hydrodynamics_parts": [%s, {"diameter": 0.5, "height": 2,
                          "drag_coefficient": 1.2, "heave_drag_coefficient": 0.8,
                          "center": {"x": -1.2, "y": 0.9, "z": 1.6}}])",
                      absl::StrReplaceAll(kPartB, {{R"("axis": {"y": 1, "z": 0.5}})",
                                                    R"("axis": {"y": 1, "z": 0.5},
                                                       "center": {"x": 2, "z": -0.5}})"}})))));
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->body_fluid_loads().size(), 2u);
  EXPECT_TRUE(model->body_fluid_loads()[0].has_offset());
  ExpectDragTangentIsTheRateDerivative(*model);
}

// A body pinned at its centre of mass to the ground, wholly under water,
// with a buoyant float (d 1 m, 2 m, C_a 1) at L = 2 m from the pin: the
// float's buoyancy F_b = rho g V is the only moment about the pin (the
// weight acts at the pin). Statics from a tilt of 45 degrees bring the float
// above the pin (to Newton's tolerance: 1e-7 m); about that equilibrium the
// body swings as a pendulum turned upside down, omega^2 = F_b L / (J +
// C_a rho V L^2) about each horizontal axis (its own J: 600 and 900 kg m^2;
// the float's added mass at its centre), and freely about the vertical
// (omega = 0). Closed forms of the small oscillation; MODAL's frequencies
// are those of the linearised model, so they agree to rounding (1e-9,
// relative). Without the offset's added inertia the frequencies would be 3.4
// and 2.9 times higher; without its moment the body would not swing.
TEST(BodyFluidPartsTest, FloatOffThePinRightsTheBodyAndSwingsAtTheClosedFormFrequency) {
  const double g = 9.81, d = 1, h = 2, ca = 1, length = 2;
  const double volume = kPi * d * d / 4 * h, fb = kRho * g * volume;
  auto scene = [&](const Eigen::Vector3d& c, const std::string& analysis) {
    return absl::StrFormat(R"({
      "gravity": {"z": -%.17g}, "fluid": {"density": %.17g},
      "bodies": [{"name": "b", "mass": 2000, "inertia": {"x": 600, "y": 900, "z": 500},
                  "position": {"z": -30},
                  "hydrodynamics_parts": [{"diameter": %.17g, "height": %.17g,
                     "added_mass": %.17g, "heave_added_mass": 0.5,
                     "center": {"x": %.17g, "y": %.17g, "z": %.17g}}]}],
      "joints": [{"type": "PIN", "a": {"body": "b"}}],
      "probes": [{"name": "float", "body": "b", "point": {"x": %.17g, "y": %.17g, "z": %.17g}}],
      "solver": {"analysis": "%s" %s}})",
                           g, kRho, d, h, ca, c.x(), c.y(), c.z(), c.x(), c.y(), c.z(), analysis,
                           analysis == "MODAL" ? R"(, "modes": 3)" : "");
  };
  {
    const Eigen::Vector3d tilted(length * std::sqrt(0.5), 0, length * std::sqrt(0.5));
    CollectingSink sink;
    RunOk(SceneFromJson(scene(tilted, "STATIC")), &sink);
    ASSERT_FALSE(sink.frames().empty());
    const Eigen::Vector3d r = sink.frames().back().probes[0].position_m;
    std::printf("float at (%.3g, %.3g, %.12g) m, above the pin at z = %.12g m\n", r.x(), r.y(),
                r.z(), -30 + length);
    EXPECT_NEAR(r.x(), 0, 1e-7);
    EXPECT_NEAR(r.y(), 0, 1e-7);
    EXPECT_NEAR(r.z(), -30 + length, 1e-7);
  }
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(scene(Eigen::Vector3d(0, 0, length), "MODAL")), &sink);
  ASSERT_EQ(s.frequencies_hz.size(), 3u);
  const double added = ca * kRho * volume * length * length;
  const double about_x = std::sqrt(fb * length / (600 + added)) / (2 * kPi);
  const double about_y = std::sqrt(fb * length / (900 + added)) / (2 * kPi);
  std::printf("frequencies %.12g %.12g %.12g Hz; closed form 0, %.12g, %.12g Hz\n",
              s.frequencies_hz[0], s.frequencies_hz[1], s.frequencies_hz[2], about_y, about_x);
  EXPECT_LT(std::abs(s.frequencies_hz[0]), 1e-6 * about_x);
  EXPECT_NEAR(s.frequencies_hz[1] / about_y, 1, 1e-9);
  EXPECT_NEAR(s.frequencies_hz[2] / about_x, 1, 1e-9);
}

// The same pendulum in the planar model (gravity -y, the float at (0, L)
// in the body's frame): omega^2 = F_b L / (J_z + C_a rho V L^2).
TEST(BodyFluidPartsTest, PlanarFloatOffThePinSwingsAtTheClosedFormFrequency) {
  const double g = 9.81, d = 1, h = 2, ca = 1, length = 2;
  const double volume = kPi * d * d / 4 * h, fb = kRho * g * volume;
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(absl::StrFormat(R"({
      "model": "PLANAR", "gravity": {"y": -%.17g}, "fluid": {"density": %.17g},
      "bodies": [{"name": "b", "mass": 2000, "inertia": {"x": 600, "y": 900, "z": 700},
                  "position": {"y": -30},
                  "hydrodynamics_parts": [{"diameter": %.17g, "height": %.17g,
                     "added_mass": %.17g, "center": {"y": %.17g}}]}],
      "joints": [{"type": "PIN", "a": {"body": "b"}}],
      "solver": {"analysis": "MODAL", "modes": 1}})",
                                                           g, kRho, d, h, ca, length)),
                             &sink);
  ASSERT_EQ(s.frequencies_hz.size(), 1u);
  const double expected = std::sqrt(fb * length / (700 + ca * kRho * volume * length * length)) /
                          (2 * kPi);
  std::printf("frequency %.12g Hz, closed form %.12g Hz\n", s.frequencies_hz[0], expected);
  EXPECT_NEAR(s.frequencies_hz[0] / expected, 1, 1e-9);
}

TEST(BodyFluidPartsTest, CenterWithDragAreasAndOutOfThePlaneAreNamed) {
  EXPECT_THAT(testing::SceneError(BodyJson(R"({"z": -5})", R"({"x": 1})",
                                           R"(, "hydrodynamics_parts": [{"diameter": 1,
                                                "height": 1, "center": {"x": 1},
                                                "drag_area": {"x": 0.5}}])")),
              HasSubstr("bodies[0].hydrodynamics_parts[0].center: not with drag_area"));
  auto model = MultibodyModel::Build(SceneFromJson(R"({
    "model": "PLANAR", "gravity": {"y": -9.81}, "fluid": {"density": 1025},
    "bodies": [{"name": "b", "mass": 500, "inertia": {"x": 40, "y": 60, "z": 70},
                "position": {"y": -5},
                "hydrodynamics": {"diameter": 0.3, "height": 3, "center": {"x": 1, "z": 1}}}],
    "solver": {"duration": 1}})"));
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(std::string(model.status().message()),
              HasSubstr("bodies[0].hydrodynamics.center.z"));
}

}  // namespace
}  // namespace cablesim
