// The rounding floor of the forces and of the energy (newton_convergence.h,
// AncfCableElement::ElasticForce's `roundoff`, MultibodyModel::
// energy_roundoff): the bound holds where it is tested against a computation
// whose exact answer is known, and a scene at rest stays at rest.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/elements/ancf_cable_element.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// The elastic force is invariant to translation, so the same bent, stretched
// element computed near the origin and 1 km away must give the same force
// but for rounding; the far one's rounding bound must cover the difference.
// (Near the origin the rounding is about eps times the force; far away it is
// EA eps |r| / l, the part the bound is for.)
TEST(RoundingFloorTest, ElementForceBoundCoversTheRoundingOfAFarTranslation) {
  for (BendingModel bending : {BendingModel::kExact, BendingModel::kLinear, BendingModel::kNone}) {
    const double l = 1e-3;
    AncfCableElement<3> element(l, /*ea=*/1.57e7, /*ei=*/0.98, bending);
    AncfCableElement<3>::Coords near;
    near << 0, 0, 0, 1.001, 0.02, -0.01, 1.0009e-3, 2e-5, -1e-5, 0.999, 0.03, 0.005;
    AncfCableElement<3>::Coords far = near;
    const Eigen::Vector3d offset(1000.0, -700.0, 300.0);
    far.segment<3>(0) += offset;
    far.segment<3>(6) += offset;
    AncfCableElement<3>::Coords f_near = AncfCableElement<3>::Coords::Zero(), f_far = f_near,
                                bound = f_near;
    element.ElasticForce(near, &f_near, nullptr);
    element.ElasticForce(far, &f_far, nullptr, &bound);
    const double diff = (f_far - f_near).cwiseAbs().maxCoeff();
    EXPECT_GT(diff, 0) << "the test needs a translation that rounds";
    for (int i = 0; i < 12; ++i) {
      EXPECT_LE(std::abs(f_far(i) - f_near(i)), bound(i)) << "entry " << i;
    }
    // And the bound is a bound, not a blanket: within a few thousand times
    // the rounding it covers.
    EXPECT_LT(bound.maxCoeff(), 1e4 * diff);
  }
}

std::string SteelCable(int elements, const std::string& integrator, double gravity,
                       double duration, double step) {
  return absl::StrFormat(R"({
    "gravity": {"y": %g},
    "cables": [{"name": "steel", "length": 10, "elements": %d, "density": 7850,
                "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "steel", "s": 0}}],
    "probes": [{"name": "tip", "cable": "steel", "s": 10}],
    "solver": {"duration": %g, "step": %g, "integrator": "%s"}})",
                         gravity, elements, duration, step, integrator);
}

// A steel cable at rest with no gravity and no loads: every force is
// rounding, so the energy checks must not call the stepper unstable (they
// did: "total energy rose by 5.4e-23 J") and nothing may move.
TEST(RoundingFloorTest, SteelCableAtRestStaysAtRestWithEveryStepper) {
  for (const char* integrator : {"IMPLICIT_EULER", "HHT", "GENERALIZED_ALPHA"}) {
    CollectingSink sink;
    const RunSummary s =
        RunOk(SceneFromJson(SteelCable(100, integrator, 0, 0.05, 1e-3)), &sink);
    EXPECT_EQ(s.rejected_steps, 0) << integrator;
    for (const Frame& f : sink.frames()) {
      EXPECT_NEAR(f.probes[0].position_m.x(), 10, 1e-12) << integrator;
      EXPECT_NEAR(f.probes[0].position_m.y(), 0, 1e-12) << integrator;
    }
  }
}

// The issue's case: 2,000 elements of 5 mm stalled at a relative residual
// of 1e-4 and halved the first step 13 times. Every stepper now takes every
// step at h = 1e-4, and reports the floor it used.
TEST(RoundingFloorTest, TwoThousandSteelElementsTakeTheirFirstSteps) {
  for (const char* integrator : {"IMPLICIT_EULER", "HHT", "GENERALIZED_ALPHA"}) {
    CollectingSink sink;
    const RunSummary s =
        RunOk(SceneFromJson(SteelCable(2000, integrator, -9.81, 5e-4, 1e-4)), &sink);
    EXPECT_EQ(s.steps, 5) << integrator;
    EXPECT_EQ(s.rejected_steps, 0) << integrator;
    EXPECT_GT(s.max_residual_floor, 0) << integrator;
    // Accepted residuals sit at or below the floor (or below tol).
    EXPECT_LE(s.max_newton_residual, std::max(s.max_residual_floor + 1e-8, 1e-8)) << integrator;
  }
}

}  // namespace
}  // namespace cablesim
