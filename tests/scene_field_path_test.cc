// Setting scene fields by path (sweep axes) and the energy report of a
// trajectory.

#include "convert/scene_field_path.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "convert/run_proto.h"
#include "server/energy_report.h"
#include "server/request_checks.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

v1::Scene TwoCables() {
  v1::Scene scene;
  scene.add_cables()->set_name("a");
  scene.add_cables()->set_name("b");
  return scene;
}

TEST(SceneFieldPathTest, SetsNestedIndexedAndEnumFields) {
  v1::Scene scene = TwoCables();
  ASSERT_TRUE(SetSceneField(&scene, "cables[1].elements", 7).ok());
  ASSERT_TRUE(SetSceneField(&scene, "solver.step", 2.5e-4).ok());
  ASSERT_TRUE(SetSceneField(&scene, "gravity.y", -3).ok());
  ASSERT_TRUE(SetSceneField(&scene, "cables[0].bending", v1::LINEAR).ok());
  EXPECT_EQ(scene.cables(1).elements(), 7);
  EXPECT_TRUE(scene.cables(1).has_elements());  // optional: explicitly set
  EXPECT_FALSE(scene.cables(0).has_elements());
  EXPECT_EQ(scene.solver().step(), 2.5e-4);
  EXPECT_EQ(scene.gravity().y(), -3);
  EXPECT_EQ(scene.cables(0).bending(), v1::LINEAR);
}

TEST(SceneFieldPathTest, ErrorsSayWhatIsWrong) {
  v1::Scene scene = TwoCables();
  auto message = [&](const char* path, double value) {
    absl::Status s = SetSceneField(&scene, path, value);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << path;
    return std::string(s.message());
  };
  EXPECT_THAT(message("solver.stepp", 1), HasSubstr("no field \"stepp\" in Solver"));
  EXPECT_THAT(message("cables[2].elements", 1), HasSubstr("cables[2] does not exist (2 in"));
  EXPECT_THAT(message("cables.elements", 1), HasSubstr("give an index"));
  EXPECT_THAT(message("solver[0].step", 1), HasSubstr("is not repeated"));
  EXPECT_THAT(message("cables[0].elements", 2.5), HasSubstr("not a whole number"));
  EXPECT_THAT(message("cables[0].bending", 9), HasSubstr("9 is not a value of Bending"));
  EXPECT_THAT(message("cables[0].name", 1), HasSubstr("not a number, boolean or enum"));
  EXPECT_THAT(message("cables[x].elements", 1), HasSubstr("bad index"));
  EXPECT_THAT(message("", 1), HasSubstr("empty"));
}

TEST(SweepAxisValuesTest, LastAxisVariesFastest) {
  google::protobuf::RepeatedPtrField<v1::SweepAxis> axes;
  v1::SweepAxis* a = axes.Add();
  a->add_values(1);
  a->add_values(2);
  v1::SweepAxis* b = axes.Add();
  b->add_values(10);
  b->add_values(20);
  b->add_values(30);
  EXPECT_EQ(SweepAxisValues(axes, 0), (std::vector<double>{1, 10}));
  EXPECT_EQ(SweepAxisValues(axes, 2), (std::vector<double>{1, 30}));
  EXPECT_EQ(SweepAxisValues(axes, 3), (std::vector<double>{2, 10}));
  EXPECT_EQ(SweepAxisValues(axes, 5), (std::vector<double>{2, 30}));
}

TEST(EnergyReportTest, ReportFollowsItsDefinition) {
  // Three hand-made frames without probes: (t, kinetic, potential, axial,
  // bending, total, violation, damped). The report's numbers follow by hand:
  // scale = max(kinetic + axial + bending) = 4 + 1 + 0.5 = 5.5,
  // drift = (final - initial) / scale = (-0.5 - 0) / 5.5.
  // The columns of a trajectory stored before the energy per part was
  // recorded: no part series, the report the same.
  v1::RunHeader header;
  for (const char* c : {"t", "energy.kinetic", "energy.potential", "energy.axial",
                        "energy.bending", "energy.total", "constraint.violation",
                        "energy.damped"}) {
    header.add_columns(c);
  }
  const std::vector<double> rows = {0,   0,   0, 0,   0,   0,    0,     0,    //
                                    0.5, 4,   -5, 1,  0.5, 0.5,  1e-9,  0.25, //
                                    1.0, 2.0, -3, 0.4, 0.1, -0.5, 2e-10, 0.5};
  v1::RunSummary summary;
  summary.set_energy_dissipated(0.5);
  summary.set_energy_damped(0.75);
  const v1::EnergyResponse r = EnergyFromTrajectory(header, rows, summary);
  ASSERT_EQ(r.t_size(), 3);
  EXPECT_EQ(r.kinetic(1), 4);
  EXPECT_EQ(r.potential(2), -3);
  EXPECT_EQ(r.damped(1), 0.25);
  const v1::EnergyReport& e = r.report();
  EXPECT_EQ(e.initial(), 0);
  EXPECT_EQ(e.final(), -0.5);
  EXPECT_EQ(e.min(), -0.5);
  EXPECT_EQ(e.max(), 0.5);
  EXPECT_EQ(e.scale(), 5.5);
  EXPECT_DOUBLE_EQ(e.relative_drift(), -0.5 / 5.5);
  EXPECT_EQ(e.max_constraint_violation(), 1e-9);
  EXPECT_EQ(e.energy_dissipated(), 0.5);
  EXPECT_EQ(e.energy_damped(), 0.75);
  EXPECT_EQ(r.cables_size(), 0);
  EXPECT_EQ(r.loads_size(), 0);
}

TEST(EnergyReportTest, SeriesAreFoundByName) {
  // A cable and a body, the columns in a scrambled order (a reader that
  // went by position would read other numbers): each series is its column.
  ModelInfo info;
  info.cable_names = {"rope"};
  info.body_names = {"weight"};
  std::vector<std::string> columns = FrameColumns(info);
  std::reverse(columns.begin(), columns.end());
  v1::RunHeader header;
  *header.mutable_info() = ModelInfoToProto(info);
  for (const std::string& c : columns) header.add_columns(c);
  std::vector<double> rows;
  for (int r = 0; r < 2; ++r)
    for (size_t c = 0; c < columns.size(); ++c) rows.push_back(100 * r + static_cast<double>(c));
  const v1::EnergyResponse e = EnergyFromTrajectory(header, rows, v1::RunSummary());
  auto column = [&](const std::string& name, int r) {
    return 100.0 * r + (std::find(columns.begin(), columns.end(), name) - columns.begin());
  };
  ASSERT_EQ(e.t_size(), 2);
  ASSERT_EQ(e.cables_size(), 1);
  ASSERT_EQ(e.bodies_size(), 1);
  EXPECT_EQ(e.cables(0).name(), "rope");
  EXPECT_EQ(e.bodies(0).name(), "weight");
  EXPECT_EQ(e.bodies(0).axial_size(), 0);
  for (int r = 0; r < 2; ++r) {
    EXPECT_EQ(e.t(r), column("t", r));
    EXPECT_EQ(e.total(r), column("energy.total", r));
    EXPECT_EQ(e.cables(0).kinetic(r), column("cables[0].energy.kinetic", r));
    EXPECT_EQ(e.cables(0).gravity(r), column("cables[0].energy.gravity", r));
    EXPECT_EQ(e.cables(0).axial(r), column("cables[0].energy.axial", r));
    EXPECT_EQ(e.cables(0).bending(r), column("cables[0].energy.bending", r));
    EXPECT_EQ(e.bodies(0).kinetic(r), column("bodies[0].energy.kinetic", r));
    EXPECT_EQ(e.bodies(0).gravity(r), column("bodies[0].energy.gravity", r));
    EXPECT_EQ(e.loads(r), column("loads.energy.potential", r));
    EXPECT_EQ(e.damped(r), column("energy.damped", r));
  }
}

}  // namespace
}  // namespace cablesim
