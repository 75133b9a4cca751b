// Deleting jobs and sweeps, and retention, against a real cablesim-server:
// DeleteJob / DeleteSweep free a finished job's or sweep's results and
// refuse work still queued or running; --retention-max-age-s and
// --retention-max-bytes delete the oldest finished results first; every
// job shows the bytes its result takes; the database file shrinks once
// results are deleted.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <string>
#include <vector>

#include "absl/time/clock.h"
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

// PRAGMA freelist_count of DIR/cablesim.db read through a connection of
// the test's own (a reader beside the server's writer, WAL); -1 on error.
int64_t FreePages(const std::string& dir) {
  sqlite3* db = nullptr;
  int64_t pages = -1;
  if (sqlite3_open_v2((dir + "/cablesim.db").c_str(), &db, SQLITE_OPEN_READONLY, nullptr) ==
      SQLITE_OK) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db, "PRAGMA freelist_count", -1, &s, nullptr) == SQLITE_OK &&
        sqlite3_step(s) == SQLITE_ROW) {
      pages = sqlite3_column_int64(s, 0);
    }
    sqlite3_finalize(s);
  }
  sqlite3_close(db);
  return pages;
}

TEST(ServerRetentionTest, DeletedResultsShrinkTheDatabaseFile) {
  const std::string dir = testing::FreshDir("retention_shrink");
  ServerProcess server(dir, {"--workers=2"});
  auto stub = server.Stub();
  // Two long trajectories (every step a frame): a few MB stored.
  std::vector<std::string> ids;
  for (int i = 0; i < 2; ++i) ids.push_back(Submit(stub.get(), Pendulum(20, 1e-3, 1e-3)).id());
  int64_t stored = 0;
  for (const std::string& id : ids) {
    v1::Job job;
    ASSERT_EQ(testing::WaitForJob(stub.get(), id, &job), v1::SUCCEEDED);
    stored += job.stored_bytes();
  }
  ASSERT_GT(stored, 1 << 20);
  const std::string db = dir + "/cablesim.db";
  // The results are on disk, in the file or still in the write-ahead log.
  std::error_code no_log;
  const auto log_bytes = std::filesystem::file_size(db + "-wal", no_log);
  EXPECT_GE(static_cast<int64_t>(std::filesystem::file_size(db) + (no_log ? 0 : log_bytes)),
            stored);
  for (const std::string& id : ids) ASSERT_TRUE(DeleteJob(stub.get(), id).ok());
  // The space comes back off the request path: wait for it (hang guard
  // 60 s; it takes milliseconds).
  const absl::Time give_up = absl::Now() + absl::Seconds(60);
  while (FreePages(dir) != 0 && absl::Now() < give_up) absl::SleepFor(absl::Milliseconds(20));
  EXPECT_EQ(FreePages(dir), 0);
  // What remains is the schema and the other tables' pages: far less than
  // the results that were deleted.
  int64_t size = 0;
  while ((size = static_cast<int64_t>(std::filesystem::file_size(db))) > stored / 4 &&
         absl::Now() < give_up) {
    absl::SleepFor(absl::Milliseconds(20));
  }
  EXPECT_LT(size, stored / 4) << "stored " << stored;
}

}  // namespace
}  // namespace cablesim
