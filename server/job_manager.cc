#include "server/job_manager.h"

#include <algorithm>
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
  // Another server's change: watchers look again, idle workers claim.
  if (store_->shared()) store_->SetChangeListener([this] { WorkArrived(); });
  ApplyRetention();
  for (int i = 0; i < workers_; ++i) threads_.emplace_back([this] { Work(); });
  SpaceFreed();  // whatever a previous run deleted and had not yet given back
  threads_.emplace_back([this] { Reclaims(); });
  if (store_->shared()) threads_.emplace_back([this] { Heartbeats(); });
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
  // The store may outlive this manager: no more calls into it.
  if (store_->shared()) store_->SetChangeListener(nullptr);
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

void JobManager::SpaceFreed() {
  absl::MutexLock lock(&mu_);
  reclaim_ = true;
}

void JobManager::Reclaims() {
  while (true) {
    {
      absl::MutexLock lock(&mu_);
      auto due = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return reclaim_ || stopping_; };
      mu_.Await(absl::Condition(&due));
      if (stopping_) return;
      reclaim_ = false;
    }
    // A step at a time, so that the store serves other calls in between.
    for (bool more = true; more && !shutting_down();) {
      absl::StatusOr<bool> step = store_->ReclaimSpace();
      if (!step.ok() && log_) {
        std::cerr << "cablesim-server: giving deleted space back: " << step.status() << "\n";
      }
      more = step.ok() && *step;
    }
  }
}

void JobManager::Changed() {
  absl::MutexLock lock(&mu_);
  ++version_;
}

void JobManager::WorkArrived() {
  absl::MutexLock lock(&mu_);
  ++work_;
  ++version_;
}

absl::StatusOr<v1::Job> JobManager::Submit(const v1::Scene& scene, const std::string& peer,
                                           const std::string& tenant,
                                           const std::function<bool()>& should_stop) {
  absl::StatusOr<CheckedScene> checked = CheckScene(scene, limits_, should_stop);
  if (!checked.ok()) return checked.status();
  absl::StatusOr<v1::Job> job =
      store_->InsertJob(scene, checked->end_time_s, peer, limits_.max_queued_jobs_per_peer,
                        tenant);
  if (!job.ok()) return job.status();
  WorkArrived();
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
  WorkArrived();
  return sweep;
}

absl::StatusOr<v1::Job> JobManager::Cancel(const std::string& id) {
  // The store first, then the running jobs, under claim_mu_: a worker
  // claims a job (QUEUED -> RUNNING) and enters it in running_ under the
  // same lock, so a job that is no longer QUEUED here is either finished,
  // running here, or (shared stores) running on another server. (Without
  // the lock a worker could claim the job between the two looks and the
  // cancel would be acknowledged but never carried out.)
  bool here = false;
  absl::StatusOr<bool> cancelled;
  {
    absl::MutexLock claim_lock(&claim_mu_);
    cancelled = store_->CancelQueued(id);
    if (!cancelled.ok()) return cancelled.status();
    absl::MutexLock lock(&mu_);
    if (auto it = running_.find(id); it != running_.end()) {
      it->second->stop = 1;
      here = true;
    }
  }
  // Elsewhere: its server learns it at its next heartbeat.
  if (!*cancelled && !here) {
    if (absl::Status s = store_->RequestCancel(id); !s.ok()) return s;
  }
  Changed();
  return Get(id);
}

absl::StatusOr<int64_t> JobManager::DeleteJob(const std::string& id) {
  absl::StatusOr<int64_t> freed = store_->DeleteJob(id);
  if (freed.ok()) {
    Changed();
    SpaceFreed();
  }
  return freed;
}

absl::StatusOr<int64_t> JobManager::DeleteSweep(const std::string& id) {
  absl::StatusOr<int64_t> freed = store_->DeleteSweep(id);
  if (freed.ok()) {
    Changed();
    SpaceFreed();
  }
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
    SpaceFreed();
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
  // Without notifications from other servers (or when one is missed), a
  // shared store is polled; an embedded one changes only through this
  // process, which wakes the workers itself.
  const absl::Duration poll = store_->shared() ? absl::Milliseconds(500) : absl::Seconds(5);
  while (true) {
    uint64_t seen;
    {
      absl::MutexLock lock(&mu_);
      if (stopping_) return;
      seen = work_;
    }
    std::optional<Claim> claim;
    auto running = std::make_shared<Running>();
    {
      absl::MutexLock claim_lock(&claim_mu_);
      absl::StatusOr<std::optional<Claim>> next = store_->ClaimNext();
      if (!next.ok()) {
        LogClaimError(next.status());
      } else if (LogClaimRecovered(), next->has_value()) {
        claim = **next;
        running->attempt = claim->attempt;
        absl::MutexLock lock(&mu_);
        // Still here from a claim this server lost (its lease expired
        // while the database was out of reach): that run stores nothing.
        if (auto it = running_.find(claim->id); it != running_.end()) it->second->stop = 3;
        running_[claim->id] = running;
        if (stopping_) running->stop = 2;
        ++version_;
      }
    }
    if (!claim.has_value()) {
      absl::MutexLock lock(&mu_);
      auto woken = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_ || work_ != seen; };
      mu_.AwaitWithTimeout(absl::Condition(&woken), poll);
      continue;
    }
    RunOne(*claim, std::move(running));
  }
}

void JobManager::LogClaimError(const absl::Status& status) {
  const absl::Time now = absl::Now();
  if (claim_failing_ && now - claim_error_logged_ < kClaimErrorLogInterval) {
    ++claim_errors_unlogged_;
    return;
  }
  if (log_) {
    std::cerr << "cablesim-server: "
              << (absl::IsUnavailable(status)
                      ? "the job store is unreachable (jobs wait until it answers again): "
                      : "claiming a job: ")
              << status;
    if (claim_errors_unlogged_ > 0) {
      std::cerr << " (" << claim_errors_unlogged_ << " more failed claims in the last "
                << absl::FormatDuration(now - claim_error_logged_) << " not shown)";
    }
    std::cerr << "\n";
  }
  claim_failing_ = true;
  claim_error_logged_ = now;
  claim_errors_unlogged_ = 0;
}

void JobManager::LogClaimRecovered() {
  if (!claim_failing_) return;
  if (log_) {
    std::cerr << "cablesim-server: the job store answers again";
    if (claim_errors_unlogged_ > 0) {
      std::cerr << " (" << claim_errors_unlogged_ << " failed claims not shown)";
    }
    std::cerr << "\n";
  }
  claim_failing_ = false;
  claim_errors_unlogged_ = 0;
}

void JobManager::Heartbeats() {
  const absl::Duration every = std::min(lease_ / 4, absl::Seconds(1));
  bool failing = false;
  while (true) {
    std::vector<RunningJob> jobs;
    {
      absl::MutexLock lock(&mu_);
      auto stop = [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stopping_; };
      if (mu_.AwaitWithTimeout(absl::Condition(&stop), every)) return;
      for (const auto& [id, r] : running_) jobs.push_back({id, r->attempt, r->t.load()});
    }
    absl::StatusOr<HeartbeatReply> reply = store_->Heartbeat(jobs);
    if (!reply.ok()) {
      if (log_ && !failing) std::cerr << "cablesim-server: heartbeat: " << reply.status() << "\n";
      failing = true;
      continue;
    }
    failing = false;
    absl::MutexLock lock(&mu_);
    for (const auto& [ids, stop] : {std::pair{&reply->cancel, 1}, std::pair{&reply->lost, 3}}) {
      for (const std::string& id : *ids) {
        if (auto it = running_.find(id); it != running_.end()) {
          int none = 0;
          it->second->stop.compare_exchange_strong(none, stop);
        }
      }
    }
  }
}

void JobManager::RunOne(const Claim& claim, std::shared_ptr<Running> running) {
  const std::string& id = claim.id;
  auto forget = [&] {
    absl::MutexLock lock(&mu_);
    // Only this run's entry (a later claim of the same job has its own).
    if (auto it = running_.find(id); it != running_.end() && it->second == running) {
      running_.erase(it);
    }
    ++version_;
  };
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
    absl::StatusOr<RunSummary> ran = RunSceneWithinMemory(*scene, &sink, control, limits_.compute_nice);
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
    // Shutdown: leave the job for the next start (or another server).
    if (absl::Status s = store_->Requeue(id, claim.attempt); !s.ok()) {
      if (log_) std::cerr << "cablesim-server: " << id << ": " << s << "\n";
    }
    forget();
    return;
  }
  const v1::JobState state = StateOf(summary);
  absl::StatusOr<bool> finished =
      running->stop.load() == 3
          ? absl::StatusOr<bool>(false)
          : store_->Finish(id, state, SummaryToProto(summary), result, claim.attempt);
  if (!finished.ok()) {
    if (log_) std::cerr << "cablesim-server: " << id << ": " << finished.status() << "\n";
  } else if (!*finished) {
    if (log_) {
      std::cerr << "cablesim-server: job " << id << " attempt " << claim.attempt
                << ": result discarded, the claim no longer holds (its lease expired and "
                   "another claim took the job)\n";
    }
  } else if (log_) {
    std::cerr << "cablesim-server: job " << id << " " << v1::JobState_Name(state) << " ("
              << summary.frames << " frames, " << summary.wall_seconds << " s)\n";
  }
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
