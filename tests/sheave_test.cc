// Sheaves (engine/forces/sheave.h): the contact's force and tangent are
// its energy's derivatives, damping and friction dissipate, bad input
// names the field. The closed-form scenes (Atwood machine, capstan, hook
// block) are in sheave_slow_test.cc.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/forces/sheave.h"
#include "engine/model/model_choice.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::SceneFromJson;
using ::testing::HasSubstr;

// An element of length 0.3 m bent over a wheel of radius 0.1 m at the
// origin (axis z, or tilted in the spatial case), partly inside it.
template <int D>
Eigen::Matrix<double, 4 * D, 1> BentElement() {
  Eigen::Matrix<double, 4 * D, 1> e;
  e.setZero();
  // From (-0.15, 0.06) to (0.15, 0.055), arching over the wheel's top but
  // not enough: its middle (y ~ 0.089) dips 1 cm into the wheel, its
  // ends are outside.
  e(0) = -0.15;
  e(1) = 0.06;
  e(D) = 0.9;
  e(D + 1) = 0.43;
  e(2 * D) = 0.15;
  e(2 * D + 1) = 0.055;
  e(3 * D) = 0.92;
  e(3 * D + 1) = -0.4;
  if constexpr (D == 3) {
    e(2) = 0.01;
    e(D + 2) = 0.05;
    e(2 * D + 2) = -0.02;
    e(3 * D + 2) = 0.04;
  }
  return e;
}

SheaveSpec Wheel(const Eigen::Vector3d& axis) {
  SheaveSpec spec;
  spec.radius_m = 0.1;
  spec.axis = axis.normalized();
  spec.stiffness_n_m2 = 1e6;
  spec.damping_n_s_m2 = 50;
  spec.friction = 0.3;
  spec.friction_speed_m_s = 0.01;
  return spec;
}

// Central differences of the energy and of its gradient, step 1e-7 m
// (error ~ h^2 U''' ~ 1e-14 relative plus rounding U eps / h ~ 1e-9):
// tolerance 1e-6 of the largest entry.
template <int D>
void CheckDerivatives(const Eigen::Vector3d& axis) {
  using Coords = Eigen::Matrix<double, 4 * D, 1>;
  using Matrix = Eigen::Matrix<double, 4 * D, 4 * D>;
  const Sheave wheel(Wheel(axis), /*exact_tangent=*/true);
  const double length = 0.3;
  const Coords e = BentElement<D>();
  double pieces[Sheave::kMaxPieces][2];
  ASSERT_GE(wheel.template ContactPieces<D>(e, length, pieces), 1) << "the element must touch the wheel";
  Coords grad = Coords::Zero();
  Matrix hess = Matrix::Zero();
  const double energy = wheel.template AddPotential<D>(e, length, &grad, &hess);
  ASSERT_GT(energy, 0);
  const double h = 1e-7;
  Coords fd_grad;
  Matrix fd_hess;
  for (int i = 0; i < 4 * D; ++i) {
    Coords ep = e, em = e;
    ep(i) += h;
    em(i) -= h;
    fd_grad(i) = (wheel.template Energy<D>(ep, length) - wheel.template Energy<D>(em, length)) / (2 * h);
    Coords gp = Coords::Zero(), gm = Coords::Zero();
    wheel.template AddPotential<D>(ep, length, &gp, nullptr);
    wheel.template AddPotential<D>(em, length, &gm, nullptr);
    fd_hess.col(i) = (gp - gm) / (2 * h);
  }
  EXPECT_LE((grad - fd_grad).template lpNorm<Eigen::Infinity>(), 1e-6 * grad.template lpNorm<Eigen::Infinity>());
  EXPECT_LE((hess - fd_hess).template lpNorm<Eigen::Infinity>(), 1e-6 * hess.template lpNorm<Eigen::Infinity>());
  EXPECT_LE((hess - hess.transpose()).template lpNorm<Eigen::Infinity>(),
            1e-12 * hess.template lpNorm<Eigen::Infinity>());
}

TEST(SheaveContactTest, ForceAndTangentAreTheEnergysDerivativesPlanar) {
  CheckDerivatives<2>(Eigen::Vector3d::UnitZ());
}

TEST(SheaveContactTest, ForceAndTangentAreTheEnergysDerivativesSpatial) {
  CheckDerivatives<3>(Eigen::Vector3d(0.1, -0.2, 1));
}

// Dissipation: the power is -Q . edot, and is >= 0.
TEST(SheaveContactTest, DampingAndFrictionDissipate) {
  using Coords = Eigen::Matrix<double, 12, 1>;
  const Sheave wheel(Wheel(Eigen::Vector3d(0.1, -0.2, 1)));
  const Coords e = BentElement<3>();
  Coords edot;
  for (int i = 0; i < 12; ++i) edot(i) = 0.3 * std::sin(1.7 * i + 0.4);
  Coords q = Coords::Zero();
  Eigen::Matrix<double, 12, 12> c = Eigen::Matrix<double, 12, 12>::Zero();
  const double power = wheel.AddDissipation<3>(e, edot, 0.3, &q, &c);
  EXPECT_GT(power, 0);
  EXPECT_NEAR(power, -q.dot(edot), 1e-12 * q.lpNorm<1>());
  // The tangent is symmetric positive semi-definite.
  EXPECT_LE((c - c.transpose()).lpNorm<Eigen::Infinity>(), 1e-12 * c.lpNorm<Eigen::Infinity>());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 12, 12>> eig(c);
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * c.lpNorm<Eigen::Infinity>());
}

// Bad input names the field.
TEST(SheaveValidationTest, NamesTheField) {
  const std::string base = R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rope", "length": 1, "density": 1000, "youngs_modulus": 1e9,
                "diameter": 0.01}], "sheaves": [)";
  auto error = [&](const std::string& sheave) {
    auto proto = ParseSceneJson(base + sheave + "]}");
    EXPECT_TRUE(proto.ok()) << proto.status();
    auto scene = SceneFromProto(*proto);
    EXPECT_FALSE(scene.ok());
    return scene.ok() ? std::string() : std::string(scene.status().message());
  };
  EXPECT_THAT(error(R"({"radius": 0})"), HasSubstr("sheaves[0].radius: must be > 0"));
  EXPECT_THAT(error(R"({"radius": 0.1, "friction": -1})"),
              HasSubstr("sheaves[0].friction: must be >= 0"));
  EXPECT_THAT(error(R"({"radius": 0.1, "damping": -1})"),
              HasSubstr("sheaves[0].damping: must be >= 0"));
  EXPECT_THAT(error(R"({"radius": 0.1, "stiffness": 0})"),
              HasSubstr("sheaves[0].stiffness: must be > 0"));
  EXPECT_THAT(error(R"({"radius": 0.1, "friction_speed": 0})"),
              HasSubstr("sheaves[0].friction_speed: must be > 0"));
  EXPECT_THAT(error(R"({"radius": 0.1, "axis": {}})"), HasSubstr("sheaves[0].axis: must be non-zero"));
  EXPECT_THAT(error(R"({"radius": 0.1, "cables": ["rop"]})"),
              HasSubstr("sheaves[0].cables[0]: no cable named \"rop\""));
  EXPECT_THAT(error(R"({"radius": 0.1}, {"radius": -2})"), HasSubstr("sheaves[1].radius"));
  EXPECT_THAT(error(R"({"radius": 0.1, "body": "hook"})"),
              HasSubstr("sheaves[0].body: no body named \"hook\""));
}

// A wheel on a body is centred on it: a position beside it is refused.
TEST(SheaveValidationTest, WheelOnABodyTakesNoPosition) {
  auto proto = ParseSceneJson(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rope", "length": 1, "density": 1000, "youngs_modulus": 1e9,
                "diameter": 0.01}],
    "bodies": [{"name": "hook", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1}}],
    "sheaves": [{"radius": 0.1, "body": "hook", "position": {"x": 1}}],
    "solver": {"duration": 1}})");
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("sheaves[0].position: not with body"));
}

// A tilted axis makes the scene spatial; the default stiffness is
// EA / R^2.
TEST(SheaveValidationTest, TiltedAxisIsSpatialAndStiffnessDefaults) {
  const Scene scene = SceneFromJson(R"({"gravity": {"y": -9.81},
    "cables": [{"name": "rope", "length": 1, "density": 1000, "youngs_modulus": 1e9,
                "area": 1e-4, "bending": "NONE"}],
    "sheaves": [{"radius": 0.2, "axis": {"x": 1, "z": 1}}],
    "solver": {"duration": 1}})");
  ASSERT_EQ(scene.sheaves.size(), 1u);
  EXPECT_NEAR(scene.sheaves[0].stiffness_n_m2, 1e9 * 1e-4 / 0.04, 1e-6);
  EXPECT_EQ(OutOfPlaneField(scene), "sheaves[0].axis.x");
}

}  // namespace
}  // namespace cablesim
