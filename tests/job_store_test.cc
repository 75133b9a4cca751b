// The job store's state machine: a job is finished at most once, with its
// result in the same transaction; what a restart requeues; a second store
// on the same directory is refused.

#include "server/job_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

std::string FreshDir(const std::string& name) {
  const std::string dir = absl::StrCat(::testing::TempDir(), "/job_store_test_", name, "_", ::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

v1::Scene Named(const std::string& name) {
  v1::Scene scene;
  scene.set_name(name);
  return scene;
}

TEST(JobStoreTest, AJobFinishesOnceWithItsResult) {
  auto store = *JobStore::Open(FreshDir("once"));
  const v1::Job job = *store->InsertJob(Named("a"), 2.0);
  // 128 random bits, URL-safe: nothing to guess from.
  EXPECT_THAT(job.id(), ::testing::MatchesRegex("j-[A-Za-z0-9_-]{22}"));
  EXPECT_EQ(job.state(), v1::QUEUED);
  EXPECT_EQ(job.end_time_s(), 2.0);
  EXPECT_EQ(store->GetScene(job.id())->name(), "a");
  EXPECT_FALSE(*store->Finish(job.id(), v1::SUCCEEDED, {}, {}));  // not running yet
  ASSERT_TRUE(*store->MarkRunning(job.id()));
  EXPECT_FALSE(*store->MarkRunning(job.id()));  // already claimed

  StoredResult result;
  result.header.add_columns("t");
  result.header.add_columns("x");
  result.values = {0, 1, 0.5, 2};
  v1::RunSummary summary;
  summary.set_status("ok");
  summary.set_frames(2);
  ASSERT_TRUE(*store->Finish(job.id(), v1::SUCCEEDED, summary, result));
  // A second finish (a worker that lost the race) changes nothing.
  EXPECT_FALSE(*store->Finish(job.id(), v1::FAILED, {}, {}));
  const v1::Job done = *store->GetJob(job.id());
  EXPECT_EQ(done.state(), v1::SUCCEEDED);
  EXPECT_EQ(done.attempts(), 1);
  EXPECT_EQ(done.summary().frames(), 2);
  const StoredResult kept = *store->GetResult(job.id());
  EXPECT_EQ(kept.values, result.values);
  EXPECT_EQ(kept.header.columns_size(), 2);
}

TEST(JobStoreTest, AResultWithoutFramesIsKept) {
  // A run can end before its first frame (e.g. a STATIC run failing in its
  // first increment): the empty trajectory is stored, not NULL.
  auto store = *JobStore::Open(FreshDir("empty"));
  const v1::Job job = *store->InsertJob(Named("b"), 1.0);
  ASSERT_TRUE(*store->MarkRunning(job.id()));
  v1::RunSummary summary;
  summary.set_status("failed");
  ASSERT_TRUE(*store->Finish(job.id(), v1::FAILED, summary, {}));
  EXPECT_EQ(store->GetJob(job.id())->state(), v1::FAILED);
  EXPECT_TRUE(store->GetResult(job.id())->values.empty());
}

TEST(JobStoreTest, RestartRequeuesRunningJobsAndKeepsTheRest) {
  const std::string dir = FreshDir("restart");
  std::string queued, running, cancelled;
  {
    auto store = *JobStore::Open(dir);
    queued = store->InsertJob(Named("q"), 1)->id();
    running = store->InsertJob(Named("r"), 1)->id();
    cancelled = store->InsertJob(Named("c"), 1)->id();
    ASSERT_TRUE(*store->MarkRunning(running));
    ASSERT_TRUE(*store->CancelQueued(cancelled));
    EXPECT_FALSE(*store->CancelQueued(running));  // running: the worker stops it
  }                                               // as if the process died here
  auto store = *JobStore::Open(dir);
  EXPECT_EQ(*store->RequeueRunning(), 1);
  EXPECT_EQ(*store->QueuedJobIds(), (std::vector<std::string>{queued, running}));
  EXPECT_EQ(store->GetJob(cancelled)->state(), v1::CANCELLED);
  EXPECT_EQ(store->GetJob(running)->attempts(), 1);
  EXPECT_EQ(store->GetJob("j-000999").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store->GetJob("nonsense").status().code(), absl::StatusCode::kNotFound);
}

TEST(JobStoreTest, ASecondStoreOnTheSameDirectoryIsRefused) {
  const std::string dir = FreshDir("lock");
  auto first = JobStore::Open(dir);
  ASSERT_TRUE(first.ok());
  auto second = JobStore::Open(dir);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kFailedPrecondition);
  first->reset();
  EXPECT_TRUE(JobStore::Open(dir).ok());  // the lock went with the first
}

TEST(JobStoreTest, SweepStoresItsItemsInOrder) {
  auto store = *JobStore::Open(FreshDir("sweep"));
  v1::SubmitSweepRequest request;
  request.set_name("s");
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("solver.step");
  axis->add_values(1);
  axis->add_values(2);
  const v1::Sweep sweep = *store->InsertSweep(request, {Named("x"), Named("y")}, {1, 2});
  EXPECT_THAT(sweep.id(), ::testing::MatchesRegex("s-[A-Za-z0-9_-]{22}"));
  EXPECT_EQ(sweep.items(), 2);
  EXPECT_EQ(sweep.finished(), 0);
  ASSERT_EQ(sweep.job_ids_size(), 2);
  EXPECT_EQ(store->GetJob(sweep.job_ids(1))->sweep_index(), 1);
  EXPECT_EQ(store->GetJob(sweep.job_ids(1))->sweep_id(), sweep.id());
  ASSERT_TRUE(*store->CancelQueued(sweep.job_ids(0)));
  const v1::Sweep later = *store->GetSweep(sweep.id());
  EXPECT_EQ(later.finished(), 1);
  EXPECT_EQ(later.failed(), 1);
  EXPECT_EQ(later.axes_size(), 1);
}

}  // namespace
}  // namespace cablesim
