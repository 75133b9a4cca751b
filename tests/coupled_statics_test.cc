// The static equilibrium of a scene whose supports are coupled (a coupling
// session's points, engine/run/coupling.h: constraint rows rather than
// eliminated coordinates) is the one of the same scene with plain supports.
//
// tests/data/couple_floater_coupled.json: three lines from the seabed to
// one fairlead at the origin, line 1 exactly in the plane y = 0. When
// gravity is switched on its hanging part sags, pushing the part on the
// seabed into compression: the equilibrium Newton approaches in the plane
// (every y residual exactly 0) has a direction of negative curvature.
// Before the static solver stepped with the pivots' signs flipped under
// constraint rows too (SaddlePointSolver::SolveAbs; after 100 iterations
// of a load increment, StaticSolver's kShiftOnlyIterations), only a shift was used
// there, which stays about the negative curvature up to the solution, and
// Newton needed over 500 iterations: the coupled scene failed to start
// (issue 33). The reference is the same scene without `coupled`, whose
// supports are eliminated (no rows): its statics used the flipped step
// already. Both solves stop at Newton's tolerance, so the equilibria agree
// to about that tolerance; their energies (second order in the positions'
// difference near the equilibrium) to 1e-9 relative, the axial energy
// (first order) to 1e-7 relative: a different equilibrium (the line
// buckled out of the plane, 10 J lower) differs by over 1e-5.

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_replace.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

std::string CoupledScene() {
  std::ifstream in("tests/data/couple_floater_coupled.json");
  std::stringstream text;
  text << in.rdbuf();
  // The start only: one step after the statics.
  return absl::StrReplaceAll(text.str(), {{"\"duration\": 5", "\"duration\": 0.0025"},
                                          {"\"output_interval\": 0.2", "\"output_interval\": 0.0025"}});
}

TEST(CoupledStaticsTest, CoupledSupportsReachThePlainSupportsEquilibrium) {
  const std::string coupled = CoupledScene();
  ASSERT_NE(coupled.find("\"coupled\": true"), std::string::npos);
  ASSERT_NE(coupled.find("\"duration\": 0.0025"), std::string::npos);
  const std::string plain = absl::StrReplaceAll(coupled, {{",\n   \"coupled\": true", ""}});
  ASSERT_EQ(plain.find("\"coupled\":"), std::string::npos);
  CollectingSink a, b;
  const RunSummary sa = RunOk(SceneFromJson(coupled), &a);
  const RunSummary sb = RunOk(SceneFromJson(plain), &b);
  EXPECT_GT(sa.info.multipliers, 0);  // the coupled supports are rows
  EXPECT_EQ(sb.info.multipliers, 0);
  ASSERT_FALSE(a.frames().empty());
  ASSERT_FALSE(b.frames().empty());
  const EnergySample& ea = a.frames()[0].energy;
  const EnergySample& eb = b.frames()[0].energy;
  EXPECT_NEAR(ea.total, eb.total, 1e-9 * std::abs(eb.total));
  EXPECT_NEAR(ea.axial, eb.axial, 1e-7 * eb.axial);
}

}  // namespace
}  // namespace cablesim
