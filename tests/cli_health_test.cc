// `cablesim health --server HOST:PORT`: the gRPC health check the container
// health checks of deploy/ run (exit 0 only when the server is SERVING).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "client/cli.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

TEST(CliHealthTest, ServingUntilTheServerStops) {
  const std::string dir = testing::FreshDir("cli_health");
  testing::ServerProcess server(dir);
  const std::string address = server.address();
  std::ostringstream out, err;
  EXPECT_EQ(RunCli({"health", "--server", address}, out, err), 0) << err.str();
  EXPECT_EQ(out.str(), absl::StrCat(R"({"server":")", address, R"(","status":"SERVING"})", "\n"));

  server.Kill(SIGKILL);
  std::ostringstream out2, err2;
  EXPECT_EQ(RunCli({"health", "--server", address}, out2, err2), 1);
  EXPECT_EQ(out2.str(), "");
  EXPECT_THAT(err2.str(), HasSubstr("cablesim: health of " + address));

  std::ostringstream out3, err3;
  EXPECT_EQ(RunCli({"health"}, out3, err3), 2);  // needs --server
  EXPECT_THAT(err3.str(), HasSubstr("health: needs --server"));
}

}  // namespace
}  // namespace cablesim
