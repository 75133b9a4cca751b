// The run summary JSON line.

#include "client/summary_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "client/json_line.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

RunSummary OkSummary() {
  RunSummary s;
  s.analysis = "DYNAMIC";
  s.integrator = "IMPLICIT_EULER";
  s.linear_solver = "MINRES";
  s.info.model = "planar";
  s.info.coordinates = 52;
  s.info.dofs = 50;
  s.info.multipliers = 2;
  s.info.elements = 12;
  s.info.nodes = 13;
  s.frames = 1001;
  s.steps = 10000;
  s.newton_iterations = 30000;
  s.linear_iterations = 123456789012;
  s.min_step_s = 1e-4;
  s.end_time_s = 1;
  s.wall_seconds = 0.25;
  s.energy_initial = 1.5;
  s.energy_final = 1.25;
  s.energy_dissipated = 0.25;
  s.max_constraint_violation = 3e-12;
  return s;
}

TEST(SummaryJsonTest, OkSummary) {
  const std::string json = SummaryToJson(OkSummary());
  EXPECT_THAT(json, StartsWith(R"({"status":"ok","model":"planar","analysis":"DYNAMIC",)"));
  EXPECT_THAT(json, Not(HasSubstr("\n")));
  EXPECT_THAT(json, Not(HasSubstr("\"error\"")));
  EXPECT_THAT(json, Not(HasSubstr("failure_time_s")));
  for (const char* key : {"dofs",
                          "steps",
                          "newton_iterations",
                          "linear_iterations",
                          "wall_seconds",
                          "energy_initial",
                          "energy_final",
                          "max_constraint_violation",
                          "integrator",
                          "linear_solver",
                          "coordinates",
                          "multipliers",
                          "elements",
                          "nodes",
                          "frames",
                          "rejected_steps",
                          "min_step_s",
                          "end_time_s",
                          "energy_dissipated",
                          "energy_max_increase",
                          "max_newton_residual",
                          "max_residual_floor",
                          "max_linear_residual"}) {
    EXPECT_THAT(json, HasSubstr(std::string("\"") + key + "\":")) << key;
  }
  EXPECT_THAT(json, HasSubstr(R"("dofs":50,)"));
  EXPECT_THAT(json, HasSubstr(R"("linear_iterations":123456789012,)"));
  EXPECT_THAT(json, HasSubstr(R"("min_step_s":1e-04,)"));  // shortest round trip
  EXPECT_THAT(json, HasSubstr(R"("max_constraint_violation":3e-12,)"));
  EXPECT_THAT(json, HasSubstr(R"("energy_final":1.25,)"));
  EXPECT_EQ(json.back(), '}');
}

TEST(SummaryJsonTest, DynamicRunsAddStepperKeys) {
  RunSummary s = OkSummary();
  s.integrator = "HHT";
  s.linear_solver = "AUTO";
  s.linear_solver_used = "DIRECT";
  s.max_step_s = 2e-3;
  s.factorizations = 7;
  s.adaptive = true;
  s.rho_infinity = 0.7;
  s.has_error_estimate = true;
  s.error_estimate_m = 1.5e-4;
  s.error_estimate_method = "Richardson";
  const std::string json = SummaryToJson(s);
  for (const char* key : {"linear_solver_used", "accepted_steps", "max_step_s", "factorizations",
                          "direct_fallbacks", "adaptive", "rho_infinity", "error_estimate_m",
                          "error_estimate_method", "error_estimate_seconds"}) {
    EXPECT_THAT(json, HasSubstr(std::string("\"") + key + "\":")) << key;
  }
  EXPECT_THAT(json, HasSubstr(R"("linear_solver":"AUTO",)"));
  EXPECT_THAT(json, HasSubstr(R"("linear_solver_used":"DIRECT",)"));
  EXPECT_THAT(json, HasSubstr(R"("error_estimate_m":0.00015,)"));
  EXPECT_THAT(json, HasSubstr(R"("adaptive":true,)"));
  // No estimate could be made: the method says why, and no number.
  s.error_estimate_m = -1;
  EXPECT_THAT(SummaryToJson(s), Not(HasSubstr("\"error_estimate_m\":")));
  // Backward Euler has no rho_infinity.
  s.integrator = "IMPLICIT_EULER";
  EXPECT_THAT(SummaryToJson(s), Not(HasSubstr("rho_infinity")));
}

TEST(SummaryJsonTest, FailedSummaryHasErrorAndTime) {
  RunSummary s = OkSummary();
  s.status = "failed";
  s.error = "Newton did not converge at t = 0.5 \"step\"\n";
  s.failure_time_s = 0.5;
  s.energy_final = std::numeric_limits<double>::quiet_NaN();
  s.max_newton_residual = std::numeric_limits<double>::infinity();
  const std::string json = SummaryToJson(s);
  EXPECT_THAT(
      json,
      StartsWith(R"({"status":"failed","error":"Newton did not converge at t = 0.5 \"step\"\n",)"
                 R"("failure_time_s":0.5,)"));
  EXPECT_THAT(json, HasSubstr(R"("energy_final":null,)"));
  EXPECT_THAT(json, HasSubstr(R"("max_newton_residual":null,)"));
}

TEST(JsonLineTest, Escaping) {
  EXPECT_EQ(JsonLine::Quote("a\"b\\c\td\x01"), R"("a\"b\\c\td\u0001")");
  EXPECT_EQ(JsonLine::Quote("caf\xc3\xa9"), "\"caf\xc3\xa9\"");  // UTF-8 kept
  // Invalid UTF-8 (a lone byte 0xff) becomes U+FFFD: the line stays JSON.
  EXPECT_EQ(JsonLine::Quote("a\xff"), "\"a\xef\xbf\xbd\"");
  EXPECT_EQ(JsonLine().ToString(), "{}");
  EXPECT_EQ(JsonLine().Add("a", 1).Add("b", true).Add("c", 0.1).Add("d", "x").ToString(),
            R"({"a":1,"b":true,"c":0.1,"d":"x"})");
  EXPECT_EQ(JsonLine::Number(1e300), "1e+300");
  EXPECT_EQ(JsonLine::Number(-std::numeric_limits<double>::infinity()), "null");
}

}  // namespace
}  // namespace cablesim
