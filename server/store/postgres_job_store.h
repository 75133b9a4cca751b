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
#include "server/store/sql_job_store.h"

typedef struct pg_conn PGconn;

namespace cablesim {

class PostgresJobStore final : public SqlJobStore {
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

  absl::Status RequestCancel(const std::string& id) override;
  absl::StatusOr<HeartbeatReply> Heartbeat(const std::vector<RunningJob>& running) override;
  void SetChangeListener(std::function<void()> listener) override;

 protected:
  absl::StatusOr<std::unique_ptr<SqlRows>> Run(const std::string& sql,
                                               const SqlParams& params) override;
  void Ready() override { EnsureConnected(); }
  void Changed() override { Notify(); }
  std::string owner_param() const override { return owner_; }
  int64_t lease_ms_param() const override { return options_.lease_ms; }

 private:
  PostgresJobStore(PGconn* conn, std::string url, const StoreOptions& options);
  // Applies the missing schema migrations; mu_ held.
  absl::Status Migrate();
  // Reconnects when the server dropped the connection; mu_ held.
  void EnsureConnected();
  // Runs `sql` (several statements allowed, no parameters); mu_ held.
  absl::Status Exec(const std::string& sql);
  // NOTIFY the other servers (payload: owner_); mu_ held.
  void Notify();
  void Listen();
  void CallListener();

  const std::string url_;
  const StoreOptions options_;
  std::string owner_;
  std::string describe_;
  PGconn* conn_ ABSL_GUARDED_BY(mu_);
  // Set and called under listener_mu_, so that clearing it (a manager
  // shutting down) waits for a call under way.
  absl::Mutex listener_mu_;
  std::function<void()> listener_ ABSL_GUARDED_BY(listener_mu_);
  std::atomic<bool> stop_{false};
  std::thread listen_thread_;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_POSTGRES_JOB_STORE_H_
