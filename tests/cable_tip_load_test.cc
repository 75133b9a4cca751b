// The tip loads of a cable end (Hydrodynamics.start_tip, end_tip:
// engine/forces/cable_fluid_load.h, cable_added_mass.h), MoorDyn's rod of
// zero length: on one straight element, the drag along the tangent at a
// given velocity and current, the added mass along the tangent on a given
// acceleration, both against their closed forms; the drag's velocity
// Jacobian against central differences; nothing above the free surface;
// and the scene's field refused on a winch cable and by an explicit
// integrator, naming the field.

#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "convert/scene_from_proto.h"
#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/cable_added_mass.h"
#include "engine/forces/cable_fluid_load.h"
#include "engine/forces/wave_load.h"
#include "engine/forces/waves.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using Coords = ElementCoords<3>;
using Matrix = ElementMatrix<3>;

// A straight element of 2 m from (1, 2, -30) along `t` (unit), stretched
// by 1 %: node coordinates [r_0, r_0', r_1, r_1'].
Coords Straight(const Eigen::Vector3d& t) {
  Coords e;
  const Eigen::Vector3d r0(1, 2, -30);
  e << r0, 1.01 * t, r0 + 2 * 1.01 * t, 1.01 * t;
  return e;
}

const Eigen::Vector3d kTangent = Eigen::Vector3d(3, -1, 2).normalized();

TEST(CableTipLoadTest, DragAlongTheTangentAtTheTipNode) {
  const AncfCableElement<3> element(2, 1e6, 0, BendingModel::kNone);
  const Coords e = Straight(kTangent);
  Coords edot = Coords::Zero();
  // The end node (xi = 1) moves at v, the first node at something else.
  const Eigen::Vector3d v(0.4, -0.3, 0.9), u(0.2, 0.1, 0);
  edot.segment<3>(6) = v;
  edot.segment<3>(0) = Eigen::Vector3d(-1, 2, 0.5);
  const double k = 0.5 * 1025 * 1.1 * 0.0106;  // 1/2 rho C_d A [kg/m]
  CableFluidLoad::Element tip;
  tip.tip_drag[1] = k;
  CableFluidLoad load({tip}, nullptr, u);
  const ElementAt<3> at{element, 0, 0.0};
  Coords f = Coords::Zero();
  Matrix c = Matrix::Zero();
  const double power = load.AddElementDissipation(at, e, edot, &f, &c);
  const double w = (u - v).dot(kTangent);
  const Eigen::Vector3d expected = k * std::abs(w) * w * kTangent;
  // A handful of products of numbers of order 1: 1e-14 relative.
  EXPECT_NEAR((f.segment<3>(6) - expected).norm(), 0, 1e-14 * expected.norm());
  f.segment<3>(6).setZero();
  EXPECT_EQ(f.norm(), 0) << "only the tip node's position is loaded";
  EXPECT_NEAR(power, -v.dot(expected), 1e-14 * expected.norm());
  // -df/d(edot) by central differences: the force is quadratic in w (no
  // sign change within the step), so the difference is exact but for
  // rounding, about 1e-16 |f| / 1e-6; 1e-8 relative.
  const double step = 1e-6;
  for (int i = 0; i < 12; ++i) {
    Coords vp = edot, vm = edot, fp = Coords::Zero(), fm = Coords::Zero();
    vp(i) += step;
    vm(i) -= step;
    load.AddElementDissipation(at, e, vp, &fp, nullptr);
    load.AddElementDissipation(at, e, vm, &fm, nullptr);
    const Coords column = -(fp - fm) / (2 * step);
    EXPECT_NEAR((c.col(i) - column).norm(), 0, 1e-8 * c.norm()) << "column " << i;
  }
  EXPECT_GT(c.norm(), 0);
}

// In waves the flow at the tip is the current plus the waves' velocity,
// and the tip's added mass takes the flow's acceleration along t:
// f = k |w| w t + m (du/dt . t) t with u, du/dt from WaveField::At at the
// node (the same field the load holds); 1e-14 relative.
TEST(CableTipLoadTest, InWavesTheTipTakesTheFlowsVelocityAndAcceleration) {
  const AncfCableElement<3> element(2, 1e6, 0, BendingModel::kNone);
  const Coords e = Straight(kTangent);
  WaveField field(Eigen::Vector3d::UnitZ(), 0, 100, 9.81, 0);
  field.AddRegular(4, 8, Eigen::Vector3d(1, 0.5, 0), 0.3);
  const Eigen::Vector3d current(0.3, 0, 0);
  const auto waves = std::make_shared<const WaveLoad>(field, current);
  CableFluidLoad::Element tip;
  tip.tip_drag[1] = 6.5;
  tip.tip_inertia[1] = 0.84;
  CableFluidLoad load({tip}, waves, current);
  const double time = 1.7;
  const ElementAt<3> at{element, 0, time};
  Coords edot = Coords::Zero();
  const Eigen::Vector3d v(0.1, -0.2, 0.05);
  edot.segment<3>(6) = v;
  Coords f = Coords::Zero();
  load.AddElementDissipation(at, e, edot, &f, nullptr);
  const Eigen::Vector3d r = e.segment<3>(6);
  const WaveField::Kinematics k = field.At(r, time);
  const double w = (current + k.velocity_m_s - v).dot(kTangent);
  const Eigen::Vector3d expected =
      (6.5 * std::abs(w) * w + 0.84 * k.acceleration_m_s2.dot(kTangent)) * kTangent;
  ASSERT_GT(k.acceleration_m_s2.dot(kTangent) * k.acceleration_m_s2.dot(kTangent), 1e-6);
  EXPECT_NEAR((f.segment<3>(6) - expected).norm(), 0, 1e-14 * expected.norm());
}

TEST(CableTipLoadTest, NoTipLoadAboveTheFreeSurface) {
  const AncfCableElement<3> element(2, 1e6, 0, BendingModel::kNone);
  Coords e = Straight(kTangent);
  CableFluidLoad::Element tip;
  tip.tip_drag[0] = 3;
  FreeSurface surface;
  surface.enabled = true;
  CableFluidLoad load({tip}, nullptr, Eigen::Vector3d(1, 0, 0), surface);
  const ElementAt<3> at{element, 0, 0.0};
  Coords f = Coords::Zero();
  load.AddElementDissipation(at, e, Coords::Zero(), &f, nullptr);
  EXPECT_GT(f.norm(), 0) << "under water, the current drags the start tip";
  e.segment<3>(0).z() = 0.5;  // the start node above the still level
  f.setZero();
  load.AddElementDissipation(at, e, Coords::Zero(), &f, nullptr);
  EXPECT_EQ(f.norm(), 0);
}

TEST(CableTipLoadTest, AddedMassAlongTheTangentAtTheTipNode) {
  const AncfCableElement<3> element(2, 1e6, 0, BendingModel::kNone);
  const Coords e = Straight(kTangent);
  const double m = 0.84;  // [kg], a riser's 0.116 m rod's two ends
  CableAddedMass::Element tip;
  tip.tip_mass[0] = m;
  CableAddedMass added({tip}, FreeSurface{}, nullptr);
  ASSERT_TRUE(added.ActsOn(0));
  Coords edd = Coords::Zero();
  const Eigen::Vector3d a(1.5, 0.2, -0.7);
  edd.segment<3>(0) = a;
  edd.segment<3>(6) = Eigen::Vector3d(5, 5, 5);
  Coords f = Coords::Zero();
  Matrix mm = Matrix::Zero();
  added.Add<3>(element, 0, e, edd, 0.0, &f, &mm);
  const Eigen::Vector3d expected = -m * kTangent.dot(a) * kTangent;
  EXPECT_NEAR((f.segment<3>(0) - expected).norm(), 0, 1e-15 * m * a.norm());
  f.segment<3>(0).setZero();
  EXPECT_EQ(f.norm(), 0) << "only the tip node's position is loaded";
  const Eigen::Matrix3d expected_m = m * kTangent * kTangent.transpose();
  EXPECT_NEAR((mm.block<3, 3>(0, 0) - expected_m).norm(), 0, 1e-15 * m);
  mm.block<3, 3>(0, 0).setZero();
  EXPECT_EQ(mm.norm(), 0);
}

// A 20 m cable hanging in water with a tip load at its lower end.
std::string TipScene(const std::string& tip, const std::string& solver) {
  return R"({"gravity": {"z": -9.81}, "fluid": {"density": 1025},
    "cables": [{"name": "c", "points": [{"z": -10}, {"z": -30}], "elements": 4,
      "density": 7800, "youngs_modulus": 2e11, "area": 1e-3, "bending": "NONE",
      "hydrodynamics": {"normal_drag": 1, ")" + tip + R"(}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": )" + solver + "}";
}

TEST(CableTipLoadTest, SceneFieldsAreCheckedByName) {
  const std::string dynamic = R"({"analysis": "DYNAMIC", "duration": 0.1, "step": 0.01)";
  EXPECT_TRUE(testing::BuildStatus(TipScene(R"(end_tip": {"drag_area": 0.01, "added_mass": 1})",
                                            dynamic + "}"))
                  .ok());
  EXPECT_NE(testing::SceneError(TipScene(R"(end_tip": {"drag_area": -1})", dynamic + "}"))
                .find("cables[0].hydrodynamics.end_tip.drag_area"),
            std::string::npos);
  // An explicit integrator does not take an added mass along the tangent.
  const absl::Status explicit_status = testing::BuildStatus(TipScene(
      R"(start_tip": {"added_mass": 1})", dynamic + R"(, "integrator": "CENTRAL_DIFFERENCE"})"));
  ASSERT_FALSE(explicit_status.ok());
  EXPECT_NE(explicit_status.message().find("cables[0].hydrodynamics.start_tip.added_mass"),
            std::string::npos)
      << explicit_status;
}

}  // namespace
}  // namespace cablesim
