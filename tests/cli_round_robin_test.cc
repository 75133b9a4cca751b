// Clients across servers: a gRPC target naming three cablesim-servers
// (`ipv4:127.0.0.1:A,127.0.0.1:B,127.0.0.1:C`), used by the CLI's channel
// (client/service_client.h, gRPC's round_robin policy) and by the Python
// client (client/python/cablesim_client.py), spreads the calls over all
// three, and the calls go on succeeding when one server stops or crashes
// (the channels' retry policy: a call that failed UNAVAILABLE before any
// answer is sent again).
//
// Each server has a store of its own here, so that the jobs a server holds
// count the SubmitJob calls it answered (with a shared store, which
// server took a call would not show).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "client/service_client.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using testing::ServerProcess;

constexpr int kServers = 3;

int JobsHeld(const ServerProcess& server) {
  auto stub = server.Stub();
  grpc::ClientContext context;
  v1::ListJobsRequest request;
  request.set_page_size(1000);
  v1::ListJobsResponse response;
  const grpc::Status s = stub->ListJobs(&context, request, &response);
  EXPECT_TRUE(s.ok()) << s.error_message();
  return response.jobs_size();
}

class RoundRobinTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<std::string> addresses;
    for (int i = 0; i < kServers; ++i) {
      // A stop that does not wait for idle client connections.
      servers_.push_back(std::make_unique<ServerProcess>(
          testing::FreshDir(absl::StrCat("rr_", i)),
          std::vector<std::string>{"--shutdown-grace-s=0.1"}));
      ASSERT_GT(servers_.back()->port(), 0);
      addresses.push_back(servers_.back()->address());
    }
    target_ = absl::StrCat("ipv4:", absl::StrJoin(addresses, ","));
  }
  std::vector<int> Held() {
    std::vector<int> held;
    for (const auto& s : servers_) held.push_back(s->pid() > 0 ? JobsHeld(*s) : -1);
    return held;
  }
  // A job that is done at once (a short run).
  static v1::Scene Quick() { return testing::Pendulum(0.001, 1e-4, 0.001); }

  std::vector<std::unique_ptr<ServerProcess>> servers_;
  std::string target_;
};

TEST_F(RoundRobinTest, TheCliChannelSpreadsCallsAndSurvivesAServerStopping) {
  absl::StatusOr<std::unique_ptr<Connection>> c = Connect(target_, /*jobs=*/true, 0);
  ASSERT_TRUE(c.ok()) << c.status();
  // Until every server is connected (round_robin uses the ready ones).
  ASSERT_TRUE((*c)->channel->WaitForConnected(std::chrono::system_clock::now() +
                                              std::chrono::seconds(30)));
  absl::SleepFor(absl::Milliseconds(300));
  auto submit = [&] {
    grpc::ClientContext context;
    context.set_wait_for_ready(true);
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    v1::SubmitJobRequest request;
    *request.mutable_scene() = Quick();
    v1::Job job;
    return (*c)->stub->SubmitJob(&context, request, &job);
  };
  for (int i = 0; i < 30; ++i) ASSERT_TRUE(submit().ok());
  const std::vector<int> before = Held();
  std::cout << "30 calls through " << target_ << ": " << absl::StrJoin(before, " / ")
            << " per server" << std::endl;
  // round_robin over three ready servers: 10 each; at least 5 leaves room
  // for a connection that came up late.
  for (int i = 0; i < kServers; ++i) EXPECT_GE(before[i], 5) << "server " << i;
  EXPECT_EQ(before[0] + before[1] + before[2], 30);

  // Server 1 stops (SIGTERM): every further call succeeds on the others.
  servers_[1]->Kill(SIGTERM);
  for (int i = 0; i < 30; ++i) {
    const grpc::Status s = submit();
    EXPECT_TRUE(s.ok()) << "call " << i << " after the stop: " << s.error_message();
  }
  const std::vector<int> after = Held();
  std::cout << "30 calls with server 1 stopped: " << after[0] - before[0] << " / - / "
            << after[2] - before[2] << std::endl;
  EXPECT_EQ(after[0] - before[0] + after[2] - before[2], 30);
  EXPECT_GE(after[0] - before[0], 5);
  EXPECT_GE(after[2] - before[2], 5);

  // Server 2 crashes (SIGKILL: no goodbye to the clients). The channel
  // still holds its connection, so the next call can be written to a
  // closed socket and fail UNAVAILABLE ("Socket closed"); the channel's
  // retry policy sends it again, to server 0. Without that policy, 10 of
  // 20 runs of this test failed here (2026-11-28).
  servers_[2]->Kill(SIGKILL);
  for (int i = 0; i < 10; ++i) {
    const grpc::Status s = submit();
    EXPECT_TRUE(s.ok()) << "call " << i << " after the crash: " << s.error_message();
  }
  EXPECT_EQ(JobsHeld(*servers_[0]), after[0] + 10);

  // The command line, one process per call, with servers 1 and 2 down.
  for (int i = 0; i < 3; ++i) {
    const int status = std::system(
        absl::StrCat("'", CABLESIM_BIN_DIR, "/cablesim' validate '", CABLESIM_SOURCE_DIR,
                     "/scenes/falling-pendulum.json' --server ", target_, " > /dev/null")
            .c_str());
    EXPECT_EQ(status, 0) << "cablesim validate --server " << target_;
  }
}

TEST_F(RoundRobinTest, ThePythonClientSpreadsCallsAndSurvivesAServerStopping) {
  const std::string python = "/usr/bin/python3";
  if (std::system(absl::StrCat(python, " -c 'import grpc' 2>/dev/null").c_str()) != 0) {
    GTEST_SKIP() << "no Debian python3 with python3-grpcio";
  }
  const std::string dir = testing::FreshDir("rr_python");
  const std::string script = dir + "/rr.py";
  // 30 calls, then server 1 is stopped (SIGTERM; the script waits until
  // its port refuses connections), then 30 more calls on the same channel,
  // then server 2 crashes (SIGKILL) and 10 more calls follow.
  std::ofstream(script) << R"(import os, signal, socket, sys, time
import cablesim_client as c
target, scene_path, pid, port, pid2 = (sys.argv[1], sys.argv[2], int(sys.argv[3]),
                                       int(sys.argv[4]), int(sys.argv[5]))
stub = c.connect(target)
scene = c.load_scene(scene_path)
scene.solver.duration = 0.001
scene.solver.output_interval = 0.001
for i in range(30):
    c.submit(stub, scene)
os.kill(pid, signal.SIGTERM)
for _ in range(1000):
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
        time.sleep(0.01)
    except OSError:
        break
for i in range(30):
    c.submit(stub, scene)
os.kill(pid2, signal.SIGKILL)  # a crash: no goodbye to the channel
for i in range(10):
    c.submit(stub, scene)
print("ok")
)";
  const std::vector<int> none = Held();
  const int status = std::system(
      absl::StrCat("PYTHONPATH='", CABLESIM_BIN_DIR, "/../python:", CABLESIM_SOURCE_DIR,
                   "/client/python' ", python, " '", script, "' '", target_, "' '",
                   CABLESIM_SOURCE_DIR, "/scenes/falling-pendulum.json' ", servers_[1]->pid(),
                   " ", servers_[1]->port(), " ", servers_[2]->pid())
          .c_str());
  ASSERT_EQ(status, 0);
  EXPECT_EQ(none, (std::vector<int>{0, 0, 0}));
  for (int i : {1, 2}) {
    servers_[i]->Kill(SIGTERM);  // reaps it
    servers_[i]->Restart();      // to count the calls it answered
  }
  const std::vector<int> held = Held();
  std::cout << "70 Python calls through " << target_
            << ", server 1 stopped after 30, server 2 crashed after 60: "
            << absl::StrJoin(held, " / ") << std::endl;
  for (int i = 0; i < kServers; ++i) EXPECT_GE(held[i], 1) << "server " << i;
  EXPECT_EQ(held[0] + held[1] + held[2], 70);
  // Server 1 answered some of the first 30 only, server 2 none of the last 10.
  EXPECT_LE(held[1], 30);
  EXPECT_LE(held[2], 60 - held[1]);
  EXPECT_GE(held[0], 10);
}

}  // namespace
}  // namespace cablesim
