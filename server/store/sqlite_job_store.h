#ifndef CABLESIM_SERVER_STORE_SQLITE_JOB_STORE_H_
#define CABLESIM_SERVER_STORE_SQLITE_JOB_STORE_H_

// The embedded job store, the default: one SQLite database
// (DIR/cablesim.db, write-ahead log, synchronous=FULL) that one server
// uses. After `kill -9` and a restart every accepted job is either
// finished with its result or runs again, never both. One connection
// behind a mutex.
//
// One server per directory: Open takes an exclusive flock on the database
// file itself (the kernel drops it when the process dies, even by kill -9;
// no file can be removed to get around it), so two servers can never run
// the same job.
//
// Integrity: the directory is created when missing and made 0700, the
// database files 0600. Open runs `PRAGMA quick_check` and refuses a
// damaged database (DATA_LOSS); DIR/store-id names the database the
// directory belongs to, so a database that was emptied, truncated or
// replaced is refused (FAILED_PRECONDITION) instead of starting afresh
// and reusing job ids.
//
// Disk space: the database is in auto_vacuum=INCREMENTAL mode (a database
// made before is switched by one VACUUM at its next Open), so the space of
// deleted results goes back to the file system through ReclaimSpace,
// which the JobManager calls off the request path after deletions.
//
// Ids: job `j-` and sweep `s-` followed by 128 random bits (22 URL-safe
// base64 characters), so that they cannot be guessed; rows stored before
// random ids keep theirs (`j-000042`). Rows are numbered internally
// (AUTOINCREMENT, never reused).

#include <memory>
#include <string>
#include <vector>

#include "absl/synchronization/mutex.h"
#include "server/store/job_store.h"

struct sqlite3;

namespace cablesim {

class SqliteJobStore final : public JobStore {
 public:
  // Opens (creating if needed) DIR/cablesim.db; creates DIR (0700) when
  // missing, FailedPrecondition naming it when it cannot.
  static absl::StatusOr<std::unique_ptr<SqliteJobStore>> Open(const std::string& dir);
  ~SqliteJobStore() override;

  std::string Describe() const override { return "sqlite:" + dir_; }
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
  absl::StatusOr<bool> Finish(const std::string& id, v1::JobState state,
                              const v1::RunSummary& summary, const StoredResult& result,
                              int attempt) override;
  absl::StatusOr<StoredResult> GetResult(const std::string& id) override;
  absl::StatusOr<v1::Sweep> GetSweep(const std::string& id) override;
  absl::StatusOr<int64_t> DeleteJob(const std::string& id) override;
  absl::StatusOr<int64_t> DeleteSweep(const std::string& id) override;
  absl::StatusOr<RetentionReport> ApplyRetention(int64_t older_than_unix_ms,
                                                 int64_t max_bytes) override;
  // `PRAGMA incremental_vacuum` of at most 4096 pages (16 MiB), and once
  // no free page is left, a checkpoint that truncates the database file
  // and empties the write-ahead log.
  absl::StatusOr<bool> ReclaimSpace() override;

 private:
  SqliteJobStore(sqlite3* db, int lock_fd, std::string dir)
      : db_(db), lock_fd_(lock_fd), dir_(std::move(dir)) {}
  absl::Status Exec(const char* sql);
  // Open's checks (quick_check, the store id), the schema and migrations.
  absl::Status CheckAndMigrate(const std::string& dir);
  // The row of job or sweep `id` (by its prefix), -1 when none; mu_ held.
  int64_t LookUpSeq(const std::string& id);
  // Deletes the jobs matching `where` (with ?1 bound to `key`) and their
  // results; in the caller's transaction, mu_ held.
  absl::Status DeleteJobRows(const std::string& where, int64_t key);
  // ResourceExhausted when `peer` has unfinished jobs and `adding` more
  // would exceed `max_unfinished`; mu_ held.
  absl::Status CheckPeerRoom(const std::string& peer, int64_t adding, int64_t max_unfinished);

  absl::Mutex mu_;
  sqlite3* db_;
  int lock_fd_;
  const std::string dir_;
  std::string page_token_secret_;  // set by CheckAndMigrate
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_SQLITE_JOB_STORE_H_
