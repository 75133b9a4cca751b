#ifndef CABLESIM_SERVER_JOB_MANAGER_H_
#define CABLESIM_SERVER_JOB_MANAGER_H_

// Runs the durable jobs of a JobStore on a pool of worker threads, oldest
// first: each worker claims the next job from the store (JobStore::
// ClaimNext), so with a shared store the servers together drain one queue.
// Cancelling a running job stops it at its next step (through the
// engine's RunControl); shutting down stops running jobs the same way but
// puts them back to QUEUED, so they run again after a restart. Watchers
// wait for changes (a job's state, or its progress at most every 200 ms).
//
// With a shared store a heartbeat thread renews the leases of the running
// jobs a few times per lease and stores their progress; it also carries
// cancellations made on other servers to the job, and stops a job whose
// claim was lost (its result would be refused). Idle workers wake on the
// store's notifications and poll besides (twice a second), which also
// retakes jobs whose server died once their lease has expired.
//
// Deleting jobs (DeleteJob, DeleteSweep, retention) wakes a thread that
// gives their space back to the file system (JobStore::ReclaimSpace), so
// that the call that deleted need not wait for it.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "server/store/job_store.h"
#include "server/request_checks.h"

namespace cablesim {

class JobManager {
 public:
  // `store` must outlive the manager.
  // `log`: report jobs on stderr.
  JobManager(JobStore* store, int workers, ServerLimits limits, bool log = true);
  ~JobManager();  // Shutdown()

  // Requeues jobs interrupted by a crash and starts the workers.
  absl::Status Start();
  // Stops the workers; running jobs go back to QUEUED. Idempotent.
  void Shutdown();

  // `peer`: the submitting client's address, for
  // limits().max_queued_jobs_per_peer.
  // `tenant`: the owner (JobStore::InsertJob). `should_stop`: CheckScene's.
  absl::StatusOr<v1::Job> Submit(const v1::Scene& scene, const std::string& peer = "",
                                 const std::string& tenant = "",
                                 const std::function<bool()>& should_stop = {});
  absl::StatusOr<v1::Sweep> SubmitSweep(const v1::SubmitSweepRequest& request,
                                        const std::string& peer = "",
                                        const std::string& tenant = "");
  absl::StatusOr<v1::Job> Cancel(const std::string& id);
  // JobStore::DeleteJob / DeleteSweep (watchers see the change).
  absl::StatusOr<int64_t> DeleteJob(const std::string& id);
  absl::StatusOr<int64_t> DeleteSweep(const std::string& id);
  // Deletes what limits().retention_max_age / retention_max_bytes no
  // longer keep (at start-up and after every finished job).
  void ApplyRetention();
  // The stored job with the progress of a running one.
  absl::StatusOr<v1::Job> Get(const std::string& id);
  void AddProgress(v1::Job* job);

  // A counter that grows at every change; WaitForChange returns when it
  // exceeds `seen`, after `timeout`, or at shutdown.
  uint64_t version();
  void WaitForChange(uint64_t seen, absl::Duration timeout);
  bool shutting_down();

  JobStore* store() { return store_; }
  const ServerLimits& limits() const { return limits_; }

  // TEST ONLY (set by cablesim-server from the environment variable
  // CABLESIM_TEST_ONLY_JOB_GATE, which no deployment sets): a job whose
  // scene name starts with "gated" stops after its first frame and waits
  // until the file DIR/<job id> exists (or it is cancelled or shut down),
  // so a test can choose the moment at which jobs are running and which
  // have finished. Empty (the default): no job ever waits. Call before
  // Start().
  void set_test_only_gate_dir(std::string dir) { gate_dir_ = std::move(dir); }
  // Shared stores: the lease the store gives a claim (StoreOptions); the
  // heartbeat runs every lease / 4, at most every second. Call before
  // Start().
  void set_lease(absl::Duration lease) { lease_ = lease; }

 private:
  struct Running {
    std::atomic<int> stop{0};  // 1 cancel, 2 shutdown, 3 claim lost
    std::atomic<double> t{0};
    int attempt = 0;
  };
  // New work may be waiting: wake an idle worker.
  void WorkArrived();
  void Work();
  void RunOne(const Claim& claim, std::shared_ptr<Running> running);
  void Heartbeats();
  void WaitAtTestGate(const std::string& id, const Running& running);
  void Changed();
  // Deleted rows' space may be given back: wake Reclaims.
  void SpaceFreed();
  // The thread that gives the space of deleted results back to the file
  // system (JobStore::ReclaimSpace), off the request path.
  void Reclaims();

  JobStore* store_;
  const int workers_;
  const ServerLimits limits_;
  const bool log_;
  std::string gate_dir_;
  absl::Duration lease_ = absl::Seconds(10);
  // Held while a job is claimed and entered in running_, and while a
  // cancel looks at the store and then at running_: a cancel sees every
  // job either still QUEUED or already running here.
  absl::Mutex claim_mu_ ABSL_ACQUIRED_BEFORE(mu_);
  // Failed claims (the store unreachable): logged once, then at most once
  // every kClaimErrorLogInterval with a count of those not shown, and once
  // more when the store answers again.
  static constexpr absl::Duration kClaimErrorLogInterval = absl::Seconds(10);
  void LogClaimError(const absl::Status& status) ABSL_EXCLUSIVE_LOCKS_REQUIRED(claim_mu_);
  void LogClaimRecovered() ABSL_EXCLUSIVE_LOCKS_REQUIRED(claim_mu_);
  bool claim_failing_ ABSL_GUARDED_BY(claim_mu_) = false;
  absl::Time claim_error_logged_ ABSL_GUARDED_BY(claim_mu_);
  int64_t claim_errors_unlogged_ ABSL_GUARDED_BY(claim_mu_) = 0;
  absl::Mutex mu_;
  std::map<std::string, std::shared_ptr<Running>> running_ ABSL_GUARDED_BY(mu_);
  uint64_t version_ ABSL_GUARDED_BY(mu_) = 0;
  uint64_t work_ ABSL_GUARDED_BY(mu_) = 0;
  bool stopping_ ABSL_GUARDED_BY(mu_) = false;
  bool reclaim_ ABSL_GUARDED_BY(mu_) = false;
  std::vector<std::thread> threads_;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_JOB_MANAGER_H_
