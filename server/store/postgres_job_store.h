#ifndef CABLESIM_SERVER_STORE_POSTGRES_JOB_STORE_H_
#define CABLESIM_SERVER_STORE_POSTGRES_JOB_STORE_H_

// The shared job store: one PostgreSQL database (libpq) that any number
// of servers use at once, as one queue.
//
// Claiming: a worker takes the oldest QUEUED job with
// `SELECT ... FOR UPDATE SKIP LOCKED` inside the UPDATE that marks it
// RUNNING, so two servers never take the same job and neither waits for
// the other's lock. The claim records its owner (this store's instance,
// `host:pid:random`) and a lease, `lease_until_ms`, in the database's
// clock (no skew between servers): the owner's heartbeats (Heartbeat, a
// few times per lease) extend it and store the job's progress. A job
// whose lease has expired, because its server died (even by `kill -9`)
// or lost the database, is claimed again by any server, as a new attempt.
//
// Exactly once: Finish writes the result and the final state in one
// transaction, and only while the claim (owner and attempt) still holds;
// an old claim that comes back after its job was retaken stores nothing.
// So every accepted job reaches one stored result.
//
// Any server answers for any job: everything a call reads is in the
// database, progress included; servers learn of each other's changes by
// `LISTEN cablesim` / `NOTIFY` (a listener connection and thread calling
// the change listener), and poll besides.
//
// Schema migrations are versioned: table `schema_migrations` lists those
// applied; Open applies the missing ones in order, in one transaction
// under an advisory lock (servers starting together apply each once), and
// refuses a database whose schema is newer than this build knows.
//
// Results carry the CRC-32 of their bytes, checked on every read, as in
// SqliteJobStore. One connection for calls (behind a mutex; reconnected
// once when the server has dropped it) and one for notifications.

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "server/store/job_store.h"

typedef struct pg_conn PGconn;

namespace cablesim {

class PostgresJobStore final : public JobStore {
 public:
  // `url`: a libpq connection URL (postgresql://user@host:port/db).
  static absl::StatusOr<std::unique_ptr<PostgresJobStore>> Open(const std::string& url,
                                                                const StoreOptions& options);
  ~PostgresJobStore() override;

  std::string Describe() const override { return describe_; }
  bool shared() const override { return true; }
  // This store's claims are made as `owner()`.
  const std::string& owner() const { return owner_; }
  // The schema version after Open's migrations.
  static int LatestSchemaVersion();

  absl::StatusOr<int> RequeueRunning() override;
  absl::StatusOr<v1::Job> InsertJob(const v1::Scene& scene, double end_time_s,
                                    const std::string& peer, int64_t max_unfinished,
                                    const std::string& tenant) override;
  absl::StatusOr<v1::Sweep> InsertSweep(const v1::SubmitSweepRequest& request,
                                        const std::vector<v1::Scene>& items,
                                        const std::vector<double>& end_times_s,
                                        const std::string& peer, int64_t max_unfinished,
                                        const std::string& tenant) override;
  absl::StatusOr<v1::Job> GetJob(const std::string& id) override;
  absl::StatusOr<v1::Scene> GetScene(const std::string& id) override;
  absl::StatusOr<std::vector<v1::Job>> ListJobs(v1::JobState state, const std::string& sweep_id,
                                                int limit, int64_t after_key,
                                                const std::string* tenant,
                                                std::vector<int64_t>* keys) override;
  const std::string& page_token_secret() const override { return page_token_secret_; }
  absl::StatusOr<std::string> Tenant(const std::string& id) override;
  absl::StatusOr<std::vector<std::string>> CheckRows() override;
  absl::StatusOr<std::vector<std::string>> QueuedJobIds() override;
  absl::StatusOr<std::optional<Claim>> ClaimNext() override;
  absl::StatusOr<bool> MarkRunning(const std::string& id) override;
  absl::Status Requeue(const std::string& id, int attempt) override;
  absl::StatusOr<bool> CancelQueued(const std::string& id) override;
  absl::Status RequestCancel(const std::string& id) override;
  absl::StatusOr<HeartbeatReply> Heartbeat(const std::vector<RunningJob>& running) override;
  absl::StatusOr<bool> Finish(const std::string& id, v1::JobState state,
                              const v1::RunSummary& summary, const StoredResult& result,
                              int attempt) override;
  absl::StatusOr<StoredResult> GetResult(const std::string& id) override;
  absl::StatusOr<v1::Sweep> GetSweep(const std::string& id) override;
  absl::StatusOr<int64_t> DeleteJob(const std::string& id) override;
  absl::StatusOr<int64_t> DeleteSweep(const std::string& id) override;
  absl::StatusOr<RetentionReport> ApplyRetention(int64_t older_than_unix_ms,
                                                 int64_t max_bytes) override;
  void SetChangeListener(std::function<void()> listener) override;

 private:
  PostgresJobStore(PGconn* conn, std::string url, const StoreOptions& options);
  // Applies the missing schema migrations; mu_ held.
  absl::Status Migrate();
  // Reconnects when the server dropped the connection; mu_ held.
  void EnsureConnected();
  // Runs `sql` (several statements allowed, no parameters); mu_ held.
  absl::Status Exec(const std::string& sql);
  // ResourceExhausted as SqliteJobStore; in the caller's transaction.
  absl::Status CheckPeerRoom(const std::string& peer, int64_t adding, int64_t max_unfinished);
  // NOTIFY the other servers (payload: owner_); mu_ held.
  void Notify();
  void Listen();
  void CallListener();

  const std::string url_;
  const StoreOptions options_;
  std::string owner_;
  std::string describe_;
  absl::Mutex mu_;
  PGconn* conn_ ABSL_GUARDED_BY(mu_);
  // Set and called under listener_mu_, so that clearing it (a manager
  // shutting down) waits for a call under way.
  absl::Mutex listener_mu_;
  std::function<void()> listener_ ABSL_GUARDED_BY(listener_mu_);
  std::atomic<bool> stop_{false};
  std::thread listen_thread_;
  std::string page_token_secret_;  // set by Open

};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_POSTGRES_JOB_STORE_H_
