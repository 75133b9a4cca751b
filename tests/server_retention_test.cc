// Deleting jobs and sweeps, and retention, against a real cablesim-server:
// DeleteJob / DeleteSweep free a finished job's or sweep's results and
// refuse work still queued or running; --retention-max-age-s and
// --retention-max-bytes delete the oldest finished results first; every
// job shows the bytes its result takes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::Pendulum;
using testing::ServerProcess;
using testing::DeleteJob;
using testing::DeleteSweep;
using testing::Submit;

grpc::Status GetJob(v1::CablesimService::Stub* stub, const std::string& id, v1::Job* job) {
  grpc::ClientContext context;
  v1::GetJobRequest request;
  request.set_id(id);
  return stub->GetJob(&context, request, job);
}

v1::Sweep SubmitSweep(v1::CablesimService::Stub* stub, const v1::Scene& base) {
  grpc::ClientContext context;
  v1::SubmitSweepRequest request;
  request.set_name("retention");
  *request.mutable_base() = base;
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("gravity.y");
  axis->add_values(-9.81);
  axis->add_values(-1.62);
  v1::Sweep sweep;
  const grpc::Status s = stub->SubmitSweep(&context, request, &sweep);
  EXPECT_TRUE(s.ok()) << s.error_message();
  return sweep;
}

TEST(ServerRetentionTest, DeleteJobAndDeleteSweepFreeFinishedResults) {
  const std::string dir = testing::FreshDir("retention_delete");
  testing::JobGate gate(dir);
  ServerProcess server(dir, {"--workers=1"}, {gate.env()});
  auto stub = server.Stub();
  const v1::Job job = Submit(stub.get(), Pendulum(0.05, 1e-3, 1e-2));
  v1::Job finished;
  ASSERT_EQ(testing::WaitForJob(stub.get(), job.id(), &finished), v1::SUCCEEDED);
  // The disk its result takes: 6 frames of doubles and the header.
  ASSERT_TRUE(GetJob(stub.get(), job.id(), &finished).ok());
  EXPECT_GT(finished.stored_bytes(), 6 * 8);

  int64_t freed = 0;
  ASSERT_TRUE(DeleteJob(stub.get(), job.id(), &freed).ok());
  EXPECT_EQ(freed, finished.stored_bytes());
  v1::Job gone;
  EXPECT_EQ(GetJob(stub.get(), job.id(), &gone).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(testing::ReadJobResult(stub.get(), job.id()).status.error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(DeleteJob(stub.get(), job.id()).error_code(), grpc::StatusCode::NOT_FOUND);
  // Its id is not given to the next job.
  v1::Scene gated = Pendulum(0.05, 1e-3, 1e-2);
  gated.set_name("gated delete");
  const v1::Job running = Submit(stub.get(), gated);
  EXPECT_NE(running.id(), job.id());

  // Work still to do is not deleted.
  ASSERT_EQ(testing::WaitForState(stub.get(), running.id(), v1::RUNNING).state(), v1::RUNNING);
  grpc::Status refused = DeleteJob(stub.get(), running.id());
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr("cancel it"));
  const v1::Sweep sweep = SubmitSweep(stub.get(), Pendulum(0.05, 1e-3, 1e-2));
  ASSERT_EQ(sweep.job_ids_size(), 2);
  EXPECT_EQ(DeleteSweep(stub.get(), sweep.id()).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
  gate.Open(running.id());
  ASSERT_EQ(testing::WaitForJob(stub.get(), running.id()), v1::SUCCEEDED);
  for (const std::string& id : sweep.job_ids()) {
    ASSERT_EQ(testing::WaitForJob(stub.get(), id), v1::SUCCEEDED);
  }
  // A sweep's item goes with its sweep only.
  refused = DeleteJob(stub.get(), sweep.job_ids(0));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr(sweep.id()));
  ASSERT_TRUE(DeleteSweep(stub.get(), sweep.id(), &freed).ok());
  EXPECT_GT(freed, 0);
  for (const std::string& id : sweep.job_ids()) {
    EXPECT_EQ(GetJob(stub.get(), id, &gone).error_code(), grpc::StatusCode::NOT_FOUND) << id;
  }
  {
    grpc::ClientContext context;
    v1::GetSweepResultsRequest request;
    request.set_id(sweep.id());
    v1::SweepResults results;
    EXPECT_EQ(stub->GetSweepResults(&context, request, &results).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  EXPECT_EQ(DeleteSweep(stub.get(), sweep.id()).error_code(), grpc::StatusCode::NOT_FOUND);
  // Deleted for good: not back after a restart.
  stub.reset();
  server.Kill(SIGKILL);
  server.Restart();
  stub = server.Stub();
  EXPECT_EQ(GetJob(stub.get(), job.id(), &gone).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(GetJob(stub.get(), running.id(), &gone).ok());
}

TEST(ServerRetentionTest, TheOldestResultsGoFirstBeyondTheByteLimit) {
  const std::string dir = testing::FreshDir("retention_bytes");
  int64_t bytes = 0;
  std::string first_id;
  {
    ServerProcess server(dir, {"--workers=1"});
    auto stub = server.Stub();
    const v1::Job job = Submit(stub.get(), Pendulum(0.05, 1e-3, 1e-2));
    v1::Job finished;
    ASSERT_EQ(testing::WaitForJob(stub.get(), job.id(), &finished), v1::SUCCEEDED);
    ASSERT_TRUE(GetJob(stub.get(), job.id(), &finished).ok());
    bytes = finished.stored_bytes();
    first_id = job.id();
  }
  // Room for one result and a half: the second one pushes the first out.
  ServerProcess server(dir, {"--workers=1", absl::StrCat("--retention-max-bytes=", bytes * 3 / 2)});
  auto stub = server.Stub();
  v1::Job kept;
  ASSERT_TRUE(GetJob(stub.get(), first_id, &kept).ok());  // within the limit at start-up
  const v1::Job second = Submit(stub.get(), Pendulum(0.05, 1e-3, 1e-2));
  ASSERT_EQ(testing::WaitForJob(stub.get(), second.id()), v1::SUCCEEDED);
  ASSERT_TRUE(server.WaitForLog("retention deleted 1 jobs"));
  EXPECT_EQ(GetJob(stub.get(), first_id, &kept).error_code(), grpc::StatusCode::NOT_FOUND);
  ASSERT_TRUE(GetJob(stub.get(), second.id(), &kept).ok());
  EXPECT_TRUE(testing::ReadJobResult(stub.get(), second.id()).status.ok());
  grpc::ClientContext context;
  v1::ServerInfo info;
  ASSERT_TRUE(stub->GetServerInfo(&context, v1::GetServerInfoRequest(), &info).ok());
  EXPECT_EQ(info.retention_max_bytes(), bytes * 3 / 2);
}

TEST(ServerRetentionTest, FinishedWorkOlderThanTheMaximumAgeIsDeletedAtStartUp) {
  const std::string dir = testing::FreshDir("retention_age");
  testing::JobGate gate(dir);
  std::string done_id, queued_id;
  v1::Sweep sweep;
  {
    ServerProcess server(dir, {"--workers=1", "--shutdown-grace-s=0"}, {gate.env()});
    auto stub = server.Stub();
    done_id = Submit(stub.get(), Pendulum(0.05, 1e-3, 1e-2)).id();
    sweep = SubmitSweep(stub.get(), Pendulum(0.05, 1e-3, 1e-2));
    for (const std::string& id : sweep.job_ids()) {
      ASSERT_EQ(testing::WaitForJob(stub.get(), id), v1::SUCCEEDED);
    }
    v1::Scene gated = Pendulum(0.05, 1e-3, 1e-2);
    gated.set_name("gated age");
    queued_id = Submit(stub.get(), gated).id();
    ASSERT_EQ(testing::WaitForState(stub.get(), queued_id, v1::RUNNING).state(), v1::RUNNING);
    stub.reset();
    EXPECT_EQ(server.Kill(SIGTERM), 0);  // the gated job goes back to the queue
  }
  // Everything finished is older than 1 ms by the time the server starts.
  ServerProcess server(dir, {"--workers=1", "--retention-max-age-s=0.001"}, {gate.env()});
  ASSERT_TRUE(server.WaitForLog("retention deleted 3 jobs (1 sweeps)"));
  auto stub = server.Stub();
  v1::Job job;
  EXPECT_EQ(GetJob(stub.get(), done_id, &job).error_code(), grpc::StatusCode::NOT_FOUND);
  for (const std::string& id : sweep.job_ids()) {
    EXPECT_EQ(GetJob(stub.get(), id, &job).error_code(), grpc::StatusCode::NOT_FOUND) << id;
  }
  // Unfinished work is never deleted: the requeued job runs (and waits at
  // the gate again, so that nothing finishes while the test looks).
  EXPECT_EQ(testing::WaitForState(stub.get(), queued_id, v1::RUNNING).state(), v1::RUNNING);
}

}  // namespace
}  // namespace cablesim
