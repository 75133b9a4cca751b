// The service carries the engine's RunSummary and ModelInfo as protos
// (convert/run_proto.h); the CLI prints the summary from the proto it gets
// back. A field left out of either direction would silently vanish from
// `cablesim run`'s summary line, so every field is set to a distinct
// non-default value and must survive the round trip.

#include <gtest/gtest.h>

#include "client/summary_json.h"
#include "convert/run_proto.h"
#include "engine/output/frame_columns.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

RunSummary EveryFieldSet() {
  RunSummary s;
  s.status = "failed";
  s.error = "why";
  s.failure_time_s = 1.5;
  s.analysis = "DYNAMIC";
  s.integrator = "HHT";
  s.integrator_requested = "AUTO";
  s.integrator_reason = "HHT: the scene has 1 constraint rows";
  s.linear_solver = "AUTO";
  s.info.model = "spatial";
  s.info.coordinates = 7;
  s.info.dofs = 6;
  s.info.multipliers = 5;
  s.info.elements = 4;
  s.info.nodes = 3;
  s.info.probe_names = {"a", "b"};
  s.frames = 11;
  s.steps = 12;
  s.rejected_steps = 13;
  s.newton_iterations = 14;
  s.linear_iterations = 15;
  s.min_step_s = 0.016;
  s.wall_seconds = 0.017;
  s.end_time_s = 0.018;
  s.energy_initial = 19;
  s.energy_final = 20;
  s.energy_dissipated = 21;
  s.energy_damped = 0.035;
  s.energy_max_increase = 22;
  s.max_constraint_violation = 23;
  s.max_newton_residual = 24;
  s.max_linear_residual = 25;
  s.max_residual_floor = 0.034;
  s.frequencies_hz = {26, 27};
  s.linear_solver_used = "DIRECT";
  s.factorizations = 28;
  s.direct_fallbacks = 29;
  s.linear_solves = 41;
  s.inexact_linear_solves = 42;
  s.max_step_s = 0.03;
  s.adaptive = true;
  s.rho_infinity = 0.31;
  s.has_error_estimate = true;
  s.error_estimate_m = 0.032;
  s.error_estimate_method = "richardson";
  s.error_estimate_seconds = 0.033;
  s.has_statistics = true;
  s.statistics.columns = {{"tip.y", 43, -0.44, 0.45, 0.046, 0.047, -0.048, 0.049},
                          {"energy.total", 43, 1.5, 0.1, 2.5, 0.2, 2.0, 0.3}};
  s.statistics.sn_slope = 3.5;
  s.statistics.equivalent_cycles = 1e7;
  s.statistics.rainflow = {{"tip.y", 4.5, 3, 0.51, 0.052}};
  s.local_error_estimate_m = 0.036;
  s.error_tolerance_m = 0.037;
  s.accumulated_error_estimate_m = 0.0385;
  s.warnings = {"one", "two \"quoted\""};
  s.releases = {{1, "fairlead", 10.5, 1234.5, "time"}, {3, "", 12.25, 98.5, "breaking_load"}};
  s.integrator_segments = {{"CENTRAL_DIFFERENCE", 0, 120, "fits"}, {"HHT", 0.25, 64, "stiffer"}};
  return s;
}

TEST(RunProtoTest, SummaryRoundTripKeepsEveryKeyOfTheSummaryLine) {
  RunSummary s = EveryFieldSet();
  EXPECT_EQ(SummaryToJson(SummaryFromProto(SummaryToProto(s))), SummaryToJson(s));
  // (The summary line prints the releases.)
  EXPECT_NE(SummaryToJson(s).find(R"("releases":[{"joint":1,"name":"fairlead","time_s":10.5,)"),
            std::string::npos)
      << SummaryToJson(s);
  EXPECT_NE(SummaryToJson(s).find(
                R"("integrator_segments":[{"integrator":"CENTRAL_DIFFERENCE","start_s":0,)"
                R"("steps":120,"reason":"fits"},{"integrator":"HHT","start_s":0.25,"steps":64,)"),
            std::string::npos)
      << SummaryToJson(s);
  s.analysis = "MODAL";  // frequencies_hz is printed for MODAL only
  EXPECT_EQ(SummaryToJson(SummaryFromProto(SummaryToProto(s))), SummaryToJson(s));
  EXPECT_NE(SummaryToJson(s).find(
                R"("statistics":{"columns":[{"column":"tip.y","count":43,"min":-0.44,"min_t":0.45,)"
                R"("max":0.046,"max_t":0.047,"mean":-0.048,"stddev":0.049},)"),
            std::string::npos)
      << SummaryToJson(s);
  EXPECT_NE(SummaryToJson(s).find(
                R"("sn_slope":3.5,"equivalent_cycles":1e+07,"rainflow":[{"column":"tip.y",)"
                R"("cycles":4.5,"half_cycles":3,"max_range":0.51,"damage_equivalent_load":0.052}]}})"),
            std::string::npos)
      << SummaryToJson(s);
}

// Every field of the statistics reaches the proto, and back.
TEST(RunProtoTest, StatisticsCarryEveryField) {
  const v1::RunStatistics p = StatisticsToProto(EveryFieldSet().statistics);
  for (const google::protobuf::Message* m :
       {static_cast<const google::protobuf::Message*>(&p),
        static_cast<const google::protobuf::Message*>(&p.columns(0)),
        static_cast<const google::protobuf::Message*>(&p.rainflow(0))}) {
    const auto* d = m->GetDescriptor();
    for (int i = 0; i < d->field_count(); ++i) {
      const auto* f = d->field(i);
      if (f->is_repeated()) {
        EXPECT_GT(m->GetReflection()->FieldSize(*m, f), 0) << f->full_name();
      } else {
        EXPECT_TRUE(m->GetReflection()->HasField(*m, f)) << f->full_name();
      }
    }
  }
  EXPECT_EQ(StatisticsToProto(StatisticsFromProto(p)).SerializeAsString(), p.SerializeAsString());
}

TEST(RunProtoTest, ProtoCarriesEveryFieldTheStructHas) {
  // Independent of what the summary line prints: every proto field is set.
  const v1::RunSummary p = SummaryToProto(EveryFieldSet());
  const auto* d = p.GetDescriptor();
  const auto* r = p.GetReflection();
  for (int i = 0; i < d->field_count(); ++i) {
    const auto* f = d->field(i);
    if (f->is_repeated()) {
      EXPECT_GT(r->FieldSize(p, f), 0) << f->name();
    } else {
      EXPECT_TRUE(r->HasField(p, f)) << f->name() << " is not set by SummaryToProto";
    }
  }
}

// Joint names and the reactions' layout survive ModelInfo's round trip, and
// a frame row written with them reads back into the same reactions.
TEST(RunProtoTest, JointReactionsRoundTrip) {
  ModelInfo info;
  info.joint_names = {"anchor", "", "weld"};
  info.joint_reaction_values = {3, 0, 6};
  const ModelInfo back = ModelInfoFromProto(ModelInfoToProto(info));
  EXPECT_EQ(back.joint_names, info.joint_names);
  EXPECT_EQ(back.joint_reaction_values, info.joint_reaction_values);
  const std::vector<std::string> columns = FrameColumns(back);
  const std::vector<std::string> tail(columns.end() - 9, columns.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"joints[0].fx", "joints[0].fy", "joints[0].fz",
                                            "joints[2].fx", "joints[2].fy", "joints[2].fz",
                                            "joints[2].mx", "joints[2].my", "joints[2].mz"}));
  Frame frame;
  frame.energy_parts.loads = 0.5;
  frame.reactions.resize(3);
  for (int j = 0; j < 3; ++j) {
    frame.reactions[j].values = info.joint_reaction_values[j];
    frame.reactions[j].force = Eigen::Vector3d(j + 1, j + 2, j + 3);
    frame.reactions[j].moment = Eigen::Vector3d(-j, -2 * j, -3 * j);
  }
  std::vector<double> row;
  ForEachFrameValue(frame, [&row](double v) { row.push_back(v); });
  ASSERT_EQ(row.size(), columns.size());
  Frame read;
  FrameReader(back, columns).Read(row, &read);
  ASSERT_EQ(read.reactions.size(), 3u);
  EXPECT_EQ(read.reactions[0].force, frame.reactions[0].force);
  EXPECT_EQ(read.reactions[1].force, Eigen::Vector3d::Zero());  // SLIDE: no columns
  EXPECT_EQ(read.reactions[2].force, frame.reactions[2].force);
  EXPECT_EQ(read.reactions[2].moment, frame.reactions[2].moment);
}

// The joints that may let go survive ModelInfo's round trip, each with a
// column joints[i].released at the row's end that reads back.
TEST(RunProtoTest, ReleasedJointsRoundTrip) {
  ModelInfo info;
  info.joint_names = {"a", "b", "c"};
  info.release_joints = {0, 2};
  const ModelInfo back = ModelInfoFromProto(ModelInfoToProto(info));
  EXPECT_EQ(back.release_joints, info.release_joints);
  const std::vector<std::string> columns = FrameColumns(back);
  const std::vector<std::string> tail(columns.end() - 2, columns.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"joints[0].released", "joints[2].released"}));
  Frame frame;
  frame.joint_released = {0, 1};
  std::vector<double> row;
  ForEachFrameValue(frame, [&row](double v) { row.push_back(v); });
  ASSERT_EQ(row.size(), columns.size());
  Frame read;
  FrameReader(back, columns).Read(row, &read);
  EXPECT_EQ(read.joint_released, frame.joint_released);
}

}  // namespace
}  // namespace cablesim
