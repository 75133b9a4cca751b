#include "server/job_manager.h"

#include <filesystem>
#include <iostream>
#include <limits>
#include <set>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "convert/run_proto.h"
#include "convert/scene_from_proto.h"

namespace cablesim {
namespace {

// Keeps a job's frames in memory as rows and reports progress.
class CollectingSink : public FrameSink {
 public:
  CollectingSink(StoredResult* result, std::function<void(double)> progress)
      : result_(result), progress_(std::move(progress)) {}
  absl::Status OnStart(const ModelInfo& info) override {
    SetFrameHeader(info, &result_->header);
    probes_ = static_cast<int>(info.probe_names.size());
    return absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    scratch_.Clear();
    AppendFrameRow(frame, &scratch_);
    result_->values.insert(result_->values.end(), scratch_.begin(), scratch_.end());
    progress_(frame.t);
    return absl::OkStatus();
  }

 private:
  StoredResult* result_;
  std::function<void(double)> progress_;
  google::protobuf::RepeatedField<double> scratch_;
  int probes_ = 0;
};

v1::JobState StateOf(const RunSummary& s) {
  if (s.status == "ok") return v1::SUCCEEDED;
  if (s.status == "cancelled") return v1::CANCELLED;
  return v1::FAILED;
}

}  // namespace

JobManager::JobManager(JobStore* store, int workers, ServerLimits limits, bool log)
    : store_(store), workers_(std::max(1, workers)), limits_(limits), log_(log) {}

JobManager::~JobManager() { Shutdown(); }

absl::Status JobManager::Start() {
  absl::StatusOr<int> requeued = store_->RequeueRunning();
  if (!requeued.ok()) return requeued.status();
  absl::StatusOr<std::vector<std::string>> queued = store_->QueuedJobIds();
  if (!queued.ok()) return queued.status();
  if (log_ && (*requeued > 0 || !queued->empty())) {
    std::cerr << "cablesim-server: " << queued->size() << " queued jobs (" << *requeued
              << " interrupted and requeued)\n";
  }
  {
    // A job submitted between the server's start of listening and this
    // call is in queue_ already: queue each id once.
    absl::MutexLock lock(&mu_);
    const std::set<std::string> present(queue_.begin(), queue_.end());
    for (const std::string& id : *queued) {
      if (!present.count(id)) queue_.push_back(id);
    }
  }
  ApplyRetention();
  for (int i = 0; i < workers_; ++i) threads_.emplace_back([this] { Work(); });
  return absl::OkStatus();
}

void JobManager::Shutdown() {
  {
    absl::MutexLock lock(&mu_);
    if (stopping_ && threads_.empty()) return;
    stopping_ = true;
    for (auto& [id, r] : running_) r->stop = 2;
    ++version_;
  }
  for (std::thread& t : threads_) t.join();
  threads_.clear();
}

uint64_t JobManager::version() {
  absl::MutexLock lock(&mu_);
  return version_;
}

bool JobManager::shutting_down() {
  absl::MutexLock lock(&mu_);
  return stopping_;
}

void JobManager::WaitForChange(uint64_t seen, absl::Duration timeout) {
  absl::MutexLock lock(&mu_);
  auto changed = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return version_ > seen || stopping_; };
  mu_.AwaitWithTimeout(absl::Condition(&changed), timeout);
}

void JobManager::Changed() {
  absl::MutexLock lock(&mu_);
  ++version_;
}

void JobManager::Enqueue(const std::string& id) {
  absl::MutexLock lock(&mu_);
  queue_.push_back(id);
  ++version_;
}

absl::StatusOr<v1::Job> JobManager::Submit(const v1::Scene& scene, const std::string& peer,
                                           const std::string& tenant) {
  absl::StatusOr<CheckedScene> checked = CheckScene(scene, limits_);
  if (!checked.ok()) return checked.status();
  absl::StatusOr<v1::Job> job =
      store_->InsertJob(scene, checked->end_time_s, peer, limits_.max_queued_jobs_per_peer,
                        tenant);
  if (!job.ok()) return job.status();
  Enqueue(job->id());
  return job;
}

absl::StatusOr<v1::Sweep> JobManager::SubmitSweep(const v1::SubmitSweepRequest& request,
                                                  const std::string& peer,
                                                  const std::string& tenant) {
  std::vector<double> end_times;
  absl::StatusOr<std::vector<v1::Scene>> items = ExpandSweep(request, limits_, &end_times);
  if (!items.ok()) return items.status();
  absl::StatusOr<v1::Sweep> sweep = store_->InsertSweep(
      request, *items, end_times, peer, limits_.max_queued_jobs_per_peer, tenant);
  if (!sweep.ok()) return sweep.status();
  absl::MutexLock lock(&mu_);
  for (const std::string& id : sweep->job_ids()) queue_.push_back(id);
  ++version_;
  return sweep;
}

absl::StatusOr<v1::Job> JobManager::Cancel(const std::string& id) {
  // The store first, then the running jobs: a worker registers a job in
  // running_ before it claims it (QUEUED -> RUNNING), so a job that is no
  // longer QUEUED here is either finished or already in running_. (Asked in
  // the other order, a worker could claim the job between the two looks and
  // the cancel would be acknowledged but never carried out.)
  absl::StatusOr<bool> cancelled = store_->CancelQueued(id);
  if (!cancelled.ok()) return cancelled.status();
  {
    absl::MutexLock lock(&mu_);
    if (auto it = running_.find(id); it != running_.end()) it->second->stop = 1;
  }
  Changed();
  return Get(id);
}

absl::StatusOr<int64_t> JobManager::DeleteJob(const std::string& id) {
  absl::StatusOr<int64_t> freed = store_->DeleteJob(id);
  if (freed.ok()) Changed();
  return freed;
}

absl::StatusOr<int64_t> JobManager::DeleteSweep(const std::string& id) {
  absl::StatusOr<int64_t> freed = store_->DeleteSweep(id);
  if (freed.ok()) Changed();
  return freed;
}

void JobManager::ApplyRetention() {
  const bool by_age = limits_.retention_max_age != absl::InfiniteDuration();
  if (!by_age && limits_.retention_max_bytes == std::numeric_limits<int64_t>::max()) return;
  const int64_t older_than =
      by_age ? NowUnixMs() - absl::ToInt64Milliseconds(limits_.retention_max_age)
             : std::numeric_limits<int64_t>::min();
  absl::StatusOr<RetentionReport> report =
      store_->ApplyRetention(older_than, limits_.retention_max_bytes);
  if (!report.ok()) {
    if (log_) std::cerr << "cablesim-server: retention: " << report.status() << "\n";
    return;
  }
  if (report->jobs > 0) {
    if (log_) {
      std::cerr << "cablesim-server: retention deleted " << report->jobs << " jobs ("
                << report->sweeps << " sweeps), " << report->bytes << " bytes of results\n";
    }
    Changed();
  }
}

absl::StatusOr<v1::Job> JobManager::Get(const std::string& id) {
  absl::StatusOr<v1::Job> job = store_->GetJob(id);
  if (job.ok()) AddProgress(&*job);
  return job;
}

void JobManager::AddProgress(v1::Job* job) {
  if (job->state() == v1::SUCCEEDED || job->state() == v1::FAILED) {
    job->set_progress_time_s(job->summary().end_time_s());
    return;
  }
  absl::MutexLock lock(&mu_);
  if (auto it = running_.find(job->id()); it != running_.end()) {
    job->set_progress_time_s(it->second->t.load());
  }
}

void JobManager::Work() {
  while (true) {
    std::string id;
    {
      absl::MutexLock lock(&mu_);
      auto ready = [&]()
                       ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || !queue_.empty(); };
      mu_.Await(absl::Condition(&ready));
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
    }
    RunOne(id);
  }
}

void JobManager::RunOne(const std::string& id) {
  auto running = std::make_shared<Running>();
  {
    absl::MutexLock lock(&mu_);
    if (stopping_) return;
    // Another worker has this job (an id queued twice): leave its entry,
    // which cancel and shutdown need, alone.
    if (!running_.emplace(id, running).second) return;
  }
  auto forget = [&] {
    absl::MutexLock lock(&mu_);
    running_.erase(id);
    ++version_;
  };
  absl::StatusOr<bool> claimed = store_->MarkRunning(id);
  if (!claimed.ok() || !*claimed) {  // cancelled meanwhile, or already run
    if (!claimed.ok() && log_)
      std::cerr << "cablesim-server: " << id << ": " << claimed.status() << "\n";
    forget();
    return;
  }
  Changed();
  StoredResult result;
  RunSummary summary;
  absl::StatusOr<v1::Scene> proto = store_->GetScene(id);
  absl::StatusOr<Scene> scene =
      proto.ok() ? SceneFromProto(*proto) : absl::StatusOr<Scene>(proto.status());
  if (scene.ok()) {
    absl::Time last_report = absl::InfinitePast();
    bool gated = !gate_dir_.empty() && scene->name.rfind("gated", 0) == 0;
    CollectingSink sink(&result, [&](double t) {
      if (gated) {
        gated = false;
        WaitAtTestGate(id, *running);
      }
      running->t = t;
      const absl::Time now = absl::Now();
      if (now - last_report > absl::Milliseconds(200)) {
        last_report = now;
        Changed();
      }
    });
    RunControl control;
    control.should_stop = [&] { return running->stop.load() != 0; };
    // Rejected steps count too: allow the nominal limit twice over.
    control.max_steps = 2 * limits_.max_steps;
    absl::StatusOr<RunSummary> ran = RunSceneWithinMemory(*scene, &sink, control);
    if (ran.ok()) {
      summary = std::move(*ran);
    } else {
      summary.status = "failed";
      summary.error = std::string(ran.status().message());
    }
  } else {
    summary.status = "failed";
    summary.error = std::string(scene.status().message());
  }
  if (running->stop.load() == 2) {
    // Shutdown: leave the job for the next start.
    if (absl::Status s = store_->Requeue(id); !s.ok()) {
      if (log_) std::cerr << "cablesim-server: " << id << ": " << s << "\n";
    }
    forget();
    return;
  }
  const v1::JobState state = StateOf(summary);
  absl::StatusOr<bool> finished = store_->Finish(id, state, SummaryToProto(summary), result);
  if (!finished.ok() && log_)
    std::cerr << "cablesim-server: " << id << ": " << finished.status() << "\n";
  if (log_)
    std::cerr << "cablesim-server: job " << id << " " << v1::JobState_Name(state) << " ("
              << summary.frames << " frames, " << summary.wall_seconds << " s)\n";
  forget();
  ApplyRetention();
}

void JobManager::WaitAtTestGate(const std::string& id, const Running& running) {
  if (log_) std::cerr << "cablesim-server: TEST ONLY: job " << id << " waits at the gate\n";
  const std::filesystem::path open = std::filesystem::path(gate_dir_) / id;
  std::error_code unused;
  while (running.stop.load() == 0 && !std::filesystem::exists(open, unused)) {
    absl::SleepFor(absl::Milliseconds(5));
  }
}

}  // namespace cablesim
