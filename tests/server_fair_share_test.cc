// Fair share against a real cablesim-server: one client address cannot
// hold every stream slot (--max-streams-per-peer) nor fill the queue
// (--max-queued-jobs-per-peer); ListJobs pages and never answers more
// than the message limit.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::Pendulum;
using testing::ServerProcess;

TEST(ServerFairShareTest, OneClientCannotHoldEveryStreamSlot) {
  ServerProcess server(testing::FreshDir("fair_streams"),
                       {"--max-streams=4", "--max-streams-per-peer=1"});
  // The first stream stays open (as in ServerLimitTest): its client reads
  // only the header.
  grpc::ChannelArguments small_window;
  small_window.SetInt("grpc.http2.bdp_probe", 0);
  auto stub = v1::CablesimService::NewStub(server.Channel(small_window));
  grpc::ClientContext first;
  v1::RunRequest request;
  *request.mutable_scene() = Pendulum(15, 1e-3, 1e-3);
  auto reader = stub->Run(&first, request);
  v1::RunEvent event;
  ASSERT_TRUE(reader->Read(&event));
  ASSERT_TRUE(event.has_header());
  // The same address again (another connection): refused although the
  // server has 3 slots free.
  auto other = server.Stub();
  grpc::ClientContext context;
  v1::RunRequest small;
  *small.mutable_scene() = Pendulum(0.01, 1e-3, 1e-3);
  auto second = other->Run(&context, small);
  while (second->Read(&event)) {
  }
  const grpc::Status status = second->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("(max_streams_per_peer)"));
  EXPECT_THAT(status.error_message(), HasSubstr("127.0.0.1"));
  first.TryCancel();
  while (reader->Read(&event)) {
  }
  reader->Finish();
}

TEST(ServerFairShareTest, OneClientCannotFillTheQueue) {
  const std::string dir = testing::FreshDir("fair_queue");
  testing::JobGate gate(dir);
  ServerProcess server(dir, {"--workers=1", "--max-queued-jobs-per-peer=2"}, {gate.env()});
  auto stub = server.Stub();
  auto submit = [&](const v1::Scene& scene, v1::Job* job) {
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    *request.mutable_scene() = scene;
    return stub->SubmitJob(&context, request, job);
  };
  v1::Scene gated = Pendulum(0.05, 1e-3, 1e-2);
  gated.set_name("gated fair");
  v1::Job running, queued, refused;
  ASSERT_TRUE(submit(gated, &running).ok());
  ASSERT_TRUE(submit(Pendulum(0.05, 1e-3, 1e-2), &queued).ok());
  grpc::Status s = submit(Pendulum(0.05, 1e-3, 1e-2), &refused);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(s.error_message(), HasSubstr("(max_queued_jobs_per_peer)"));
  {
    grpc::ClientContext context;
    v1::SubmitSweepRequest request;
    *request.mutable_base() = Pendulum(0.05, 1e-3, 1e-2);
    request.add_axes()->set_path("gravity.y");
    request.mutable_axes(0)->add_values(-9.81);
    v1::Sweep sweep;
    s = stub->SubmitSweep(&context, request, &sweep);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_THAT(s.error_message(), HasSubstr("(max_queued_jobs_per_peer)"));
  }
  // Room again once they have finished.
  gate.Open(running.id());
  ASSERT_EQ(testing::WaitForJob(stub.get(), running.id()), v1::SUCCEEDED);
  ASSERT_EQ(testing::WaitForJob(stub.get(), queued.id()), v1::SUCCEEDED);
  s = submit(Pendulum(0.05, 1e-3, 1e-2), &refused);
  EXPECT_TRUE(s.ok()) << s.error_message();
}

TEST(ServerFairShareTest, WithTokensTheShareIsPerTenant) {
  // Two tenants behind one address: each has its own share of the queue.
  const std::string dir = testing::FreshDir("fair_tenants");
  testing::JobGate gate(dir);
  const std::string tokens = dir + "/tokens";
  const std::string alice = "tok-alice-0123456789", bob = "tok-bob-0123456789ab";
  testing::WritePrivateFile(tokens, absl::StrCat(alice, " alice\n", bob, " bob\n"));
  ServerProcess server(dir,
                       {"--workers=1", "--max-queued-jobs-per-peer=1", "--token-file=" + tokens},
                       {gate.env()});
  auto stub = server.Stub();
  auto submit = [&](const std::string& token, const std::string& name, v1::Job* job) {
    grpc::ClientContext context;
    context.AddMetadata("authorization", "Bearer " + token);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = Pendulum(0.05, 1e-3, 1e-2);
    request.mutable_scene()->set_name(name);
    return stub->SubmitJob(&context, request, job);
  };
  v1::Job a, refused, b;
  ASSERT_TRUE(submit(alice, "gated alice", &a).ok());
  grpc::Status s = submit(alice, "alice again", &refused);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(s.error_message(), HasSubstr("tenant alice"));
  s = submit(bob, "gated bob", &b);
  EXPECT_TRUE(s.ok()) << s.error_message();
  gate.Open(a.id());
  gate.Open(b.id());
}

}  // namespace
}  // namespace cablesim

namespace cablesim {
namespace {

TEST(ServerListJobsTest, PagesStayUnderTheMessageLimitAndCoverEveryJob) {
  const std::string dir = testing::FreshDir("list_pages");
  // A small message limit: 40 finished jobs with their summaries do not
  // fit in one response.
  ServerProcess server(dir, {"--workers=2", "--max-message-bytes=8192"});
  auto stub = server.Stub();
  v1::Sweep sweep;
  {
    grpc::ClientContext context;
    v1::SubmitSweepRequest request;
    *request.mutable_base() = Pendulum(0.02, 1e-3, 1e-2);
    v1::SweepAxis* axis = request.add_axes();
    axis->set_path("gravity.y");
    for (int i = 0; i < 40; ++i) axis->add_values(-1.0 - i);
    ASSERT_TRUE(stub->SubmitSweep(&context, request, &sweep).ok());
  }
  for (const std::string& id : sweep.job_ids()) {
    ASSERT_EQ(testing::WaitForJob(stub.get(), id), v1::SUCCEEDED);
  }
  std::vector<std::string> seen;
  std::string token;
  int pages = 0;
  do {
    grpc::ClientContext context;
    v1::ListJobsRequest request;
    request.set_limit(1000);
    request.set_page_token(token);
    v1::ListJobsResponse response;
    const grpc::Status s = stub->ListJobs(&context, request, &response);
    ASSERT_TRUE(s.ok()) << s.error_message();
    EXPECT_LE(response.ByteSizeLong(), 8192u);
    ASSERT_GT(response.jobs_size(), 0);
    for (const v1::Job& job : response.jobs()) seen.push_back(job.id());
    token = response.next_page_token();
    ASSERT_LT(++pages, 40);
  } while (!token.empty());
  EXPECT_GT(pages, 1);
  // Every job once, newest first.
  std::vector<std::string> expected(sweep.job_ids().rbegin(), sweep.job_ids().rend());
  EXPECT_EQ(seen, expected);

  // page_size pages exactly.
  grpc::ClientContext context;
  v1::ListJobsRequest request;
  request.set_page_size(3);
  v1::ListJobsResponse response;
  ASSERT_TRUE(stub->ListJobs(&context, request, &response).ok());
  ASSERT_EQ(response.jobs_size(), 3);
  ASSERT_FALSE(response.next_page_token().empty());
  {
    grpc::ClientContext next_context;
    request.set_page_token(response.next_page_token());
    v1::ListJobsResponse next;
    ASSERT_TRUE(stub->ListJobs(&next_context, request, &next).ok());
    ASSERT_EQ(next.jobs_size(), 3);
    EXPECT_EQ(next.jobs(0).id(), expected[3]);
  }
  grpc::ClientContext bad_context;
  request.set_page_token("not a token");
  EXPECT_EQ(stub->ListJobs(&bad_context, request, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

}  // namespace
}  // namespace cablesim
