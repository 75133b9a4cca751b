// cablesim-server --metrics-listen: the Prometheus text endpoint
// (server/metrics_endpoint.h) against what the service itself says: jobs
// held at the test gate count as running, those behind them as queued, and
// once they finish the counters hold them and the sum of their summaries'
// steps (read from the jobs, not computed here).

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "server_test_util.h"

namespace cablesim {
namespace {

using testing::FreshDir;
using testing::JobGate;
using testing::ServerProcess;

// GET `path` on 127.0.0.1:`port`, plain HTTP/1.0: the whole response.
std::string HttpGet(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return "";
  }
  const std::string request = "GET " + path + " HTTP/1.0\r\nHost: test\r\n\r\n";
  ::send(fd, request.data(), request.size(), 0);
  std::string response;
  char buffer[4096];
  ssize_t n;
  while ((n = ::recv(fd, buffer, sizeof(buffer), 0)) > 0) response.append(buffer, n);
  ::close(fd);
  return response;
}

// The value of the series `name` (with its labels, e.g.
// `cablesim_jobs_finished_total{state="SUCCEEDED"}`); -1 when absent.
double Value(const std::string& text, const std::string& name) {
  const size_t at = text.find("\n" + name + " ");
  if (at == std::string::npos) return -1;
  return std::stod(text.substr(at + name.size() + 2));
}

int MetricsPort(const ServerProcess& server) {
  EXPECT_TRUE(server.WaitForLog("metrics on port "));
  std::ifstream in(server.log_path());
  const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::smatch m;
  return std::regex_search(log, m, std::regex("metrics on port ([0-9]+)")) ? std::stoi(m[1]) : 0;
}

TEST(MetricsEndpointTest, QueueRunningAndFinishedJobsAsTheServiceSeesThem) {
  const std::string dir = FreshDir("metrics_endpoint");
  JobGate gate(dir);
  ServerProcess server(dir, {"--workers=1", "--metrics-listen=127.0.0.1:0"}, {gate.env()});
  const int port = MetricsPort(server);
  ASSERT_GT(port, 0);
  auto stub = server.Stub();

  const std::string idle = HttpGet(port, "/metrics");
  EXPECT_THAT(idle, ::testing::StartsWith("HTTP/1.0 200 OK\r\n"));
  EXPECT_THAT(idle, ::testing::HasSubstr("Content-Type: text/plain; version=0.0.4"));
  EXPECT_EQ(Value(idle, "cablesim_jobs_queued"), 0);
  EXPECT_EQ(Value(idle, "cablesim_jobs_running"), 0);
  EXPECT_EQ(Value(idle, "cablesim_workers"), 1);
  EXPECT_EQ(Value(idle, "cablesim_steps_total"), 0);

  // One worker: the gated job runs (held after its first frame), the two
  // behind it wait.
  v1::Scene held = testing::Pendulum(0.05, 1e-3, 1e-2);
  held.set_name("gated-held");
  const v1::Job first = testing::Submit(stub.get(), held);
  testing::WaitForState(stub.get(), first.id(), v1::RUNNING);
  const v1::Job second = testing::Submit(stub.get(), testing::Pendulum(0.02, 1e-3, 1e-2));
  const v1::Job third = testing::Submit(stub.get(), testing::Pendulum(0.03, 1e-3, 1e-2));
  const std::string busy = HttpGet(port, "/metrics");
  EXPECT_EQ(Value(busy, "cablesim_jobs_running"), 1) << busy;
  EXPECT_EQ(Value(busy, "cablesim_jobs_queued"), 2) << busy;

  gate.Open(first.id());
  int64_t steps = 0;
  for (const v1::Job& job : {first, second, third}) {
    v1::Job last;
    ASSERT_EQ(testing::WaitForJob(stub.get(), job.id(), &last), v1::SUCCEEDED);
    steps += last.summary().steps();
  }
  EXPECT_EQ(steps, 50 + 20 + 30);  // duration / step each
  const std::string done = HttpGet(port, "/metrics");
  EXPECT_EQ(Value(done, "cablesim_jobs_queued"), 0) << done;
  EXPECT_EQ(Value(done, "cablesim_jobs_running"), 0) << done;
  EXPECT_EQ(Value(done, "cablesim_steps_total"), steps) << done;
  EXPECT_EQ(Value(done, "cablesim_jobs_finished_total{state=\"SUCCEEDED\"}"), 3) << done;
  EXPECT_EQ(Value(done, "cablesim_jobs_finished_total{state=\"FAILED\"}"), 0) << done;
  // Counted once: another scrape adds nothing.
  const std::string again = HttpGet(port, "/metrics");
  EXPECT_EQ(Value(again, "cablesim_steps_total"), steps);
  EXPECT_EQ(Value(again, "cablesim_jobs_finished_total{state=\"SUCCEEDED\"}"), 3);

  EXPECT_THAT(HttpGet(port, "/"), ::testing::StartsWith("HTTP/1.0 404"));
}

TEST(MetricsEndpointTest, OffByDefaultAndABadAddressIsRefused) {
  const std::string dir = FreshDir("metrics_endpoint_off");
  {
    ServerProcess server(dir);
    EXPECT_TRUE(server.WaitForLog("listening on port"));
    std::ifstream in(server.log_path());
    const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_THAT(log, ::testing::Not(::testing::HasSubstr("metrics on port")));
  }
  const std::string command = absl::StrCat(
      "timeout 60 '", CABLESIM_BIN_DIR, "/cablesim-server' --listen=127.0.0.1:0 --data-dir='",
      dir, "/bad' --metrics-listen=nowhere:9090 2> '", dir, "/bad.log'");
  const int status = std::system(command.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::ifstream in(dir + "/bad.log");
  const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(log, ::testing::HasSubstr("--metrics-listen nowhere:9090: expected an IPv4 HOST:PORT"));
}

}  // namespace
}  // namespace cablesim
