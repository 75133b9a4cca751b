// A run that meets a non-finite value names the force term and the place
// it came from (MultibodyModel::DescribeNonFinite; issue 30, item 6): the
// implicit steppers' Newton loop, the explicit steppers' acceleration and
// the static solver put it into their failure reason, which reaches the
// summary's error. The non-finite value is injected: a test contributor
// registered on a built model (AddContributor) that adds NaN to one
// coordinate once the time passes kPoisonTime, and states with a NaN or an
// overflowing coordinate. Names and places are exact strings: the place is
// computed here from the model's layout (a single cable's nodes come first
// in the full coordinates, 2 D per node: position, slope), independently of
// DescribeCoordinate.

#include <limits>
#include <memory>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/forces/force_contributor.h"
#include "engine/model/multibody_model.h"
#include "engine/run/dynamic_run.h"
#include "engine/run/frame_recorder.h"
#include "engine/steppers/make_stepper.h"
#include "tests/energy_momentum_scenes.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::SceneFromJson;

constexpr double kPoisonTime = 0.025;
constexpr int kNode = 7;

// NaN on coordinate `coord` from kPoisonTime on (as a conservative force).
class PoisonContributor : public ForceContributor {
 public:
  explicit PoisonContributor(int coord) : coord_(coord) {}
  std::string_view name() const override { return "test_poison"; }
  bool time_dependent() const override { return true; }
  void AddConservative(const ForceState& s, ForceOutput* out) const override {
    if (s.time >= kPoisonTime && out->full)
      (*out->full)(coord_) += std::numeric_limits<double>::quiet_NaN();
  }

 private:
  int coord_;
};

// The falling pendulum (12 elements, planar: D = 2) with `solver` fields,
// and its node kNode's first coordinate.
struct Poisoned {
  Scene scene;
  MultibodyModel model;
};
Poisoned Build(const std::string& solver) {
  Scene scene = SceneFromJson(testing::FallingPendulumWithSolver(0.1, 0.01, solver));
  auto model = MultibodyModel::Build(scene);
  EXPECT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->Info().model, "planar");
  model->AddContributor(std::make_unique<PoisonContributor>(4 * kNode));
  return {scene, *std::move(model)};
}

const std::string kExpected =
    absl::StrFormat("non-finite force from contributor 'test_poison' (cables[0] node %d)", kNode);

// The run's summary error for `solver`.
RunSummary RunPoisoned(const std::string& solver) {
  Poisoned p = Build(solver);
  testing::CollectingSink sink;
  RunSummary summary;
  summary.info = p.model.Info();
  EXPECT_TRUE(sink.OnStart(summary.info).ok());
  FrameRecorder recorder(&p.model, &sink, &summary);
  RunDynamic(&p.model, p.scene.solver, RunControl{}, &recorder, &summary);
  return summary;
}

TEST(NonFiniteSourceTest, ImplicitSteppersNameTheContributorAndNode) {
  for (const char* integrator : {"HHT", "GENERALIZED_ALPHA", "IMPLICIT_EULER", "ENERGY_MOMENTUM"}) {
    SCOPED_TRACE(integrator);
    const RunSummary s = RunPoisoned(absl::StrFormat(R"("integrator": "%s", "step": 0.005)", integrator));
    EXPECT_EQ(s.status, "failed");
    EXPECT_THAT(s.error, HasSubstr(kExpected));
    // The failure is at the poisoned time, not before (the step that
    // reaches it, whose end or midpoint is evaluated there).
    EXPECT_GE(s.end_time_s, kPoisonTime - 0.005 - 1e-9);
    EXPECT_LE(s.end_time_s, kPoisonTime + 1e-9);
  }
}

TEST(NonFiniteSourceTest, ExplicitSteppersNameTheContributorAndNode) {
  for (const char* integrator : {"CENTRAL_DIFFERENCE", "DORMAND_PRINCE"}) {
    SCOPED_TRACE(integrator);
    const RunSummary s = RunPoisoned(absl::StrFormat(R"("integrator": "%s", "step": 1e-5)", integrator));
    EXPECT_EQ(s.status, "failed");
    EXPECT_THAT(s.error, HasSubstr(kExpected));
  }
}

TEST(NonFiniteSourceTest, StatesAndElasticForce) {
  Poisoned p = Build(R"("step": 0.005)");
  MultibodyModel& m = p.model;
  Eigen::VectorXd q(m.coordinates());
  m.ToFull(m.initial_z(), &q);
  m.SetTime(0);
  // Every term finite: nothing to name.
  EXPECT_EQ(m.DescribeNonFinite(q, nullptr, 1.0), "");
  // A NaN in the state: the state is named, not a force.
  Eigen::VectorXd bad = q;
  bad(4 * kNode + 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(m.DescribeNonFinite(bad, nullptr, 1.0),
            absl::StrFormat("non-finite position (cables[0] node %d)", kNode));
  // A finite position whose strain overflows (|r'|^2 ~ 1e400): the elastic
  // force of the first element that holds the node, element kNode - 1.
  bad = q;
  bad(4 * kNode) = 1e200;
  EXPECT_EQ(m.DescribeNonFinite(bad, nullptr, 1.0),
            absl::StrFormat("elastic force, cables[0] element %d", kNode - 1));
  // The contributor once it poisons.
  m.SetTime(kPoisonTime);
  EXPECT_EQ(m.DescribeNonFinite(q, nullptr, 1.0), kExpected);
}

}  // namespace
}  // namespace cablesim
