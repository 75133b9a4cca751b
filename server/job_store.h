#ifndef CABLESIM_SERVER_JOB_STORE_H_
#define CABLESIM_SERVER_JOB_STORE_H_

// Durable jobs, sweeps and results in one SQLite database
// (DIR/cablesim.db, write-ahead log, synchronous=FULL): a job is stored
// before its id is returned, and a job's result and its final state are
// written in one transaction, so after `kill -9` and a restart every
// accepted job is either finished with its result or runs again, never
// both. Thread-safe (one connection behind a mutex).
//
// One server per directory: Open takes an exclusive flock on the database
// file itself (the kernel drops it when the process dies, even by kill -9;
// no file can be removed to get around it), so two servers can never run
// the same job.
//
// Integrity: the directory is made 0700 and the database files 0600.
// Open runs `PRAGMA quick_check` and refuses a damaged database
// (DATA_LOSS); DIR/store-id names the database the directory belongs to,
// so a database that was emptied, truncated or replaced is refused
// (FAILED_PRECONDITION) instead of starting afresh and reusing job ids.
// Each result is stored with a CRC-32 of its bytes, verified on every
// read: a mismatch is DATA_LOSS, never altered numbers.
//
// Ids: job `j-` and sweep `s-` followed by 128 random bits (22 URL-safe
// base64 characters), so that they cannot be guessed; rows stored before
// random ids keep theirs (`j-000042`). Rows are numbered internally
// (AUTOINCREMENT, never reused).

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "cablesim/v1/service.pb.h"

struct sqlite3;

namespace cablesim {

// A finished job's trajectory: the header (columns) and the rows.
struct StoredResult {
  v1::RunHeader header;
  std::vector<double> values;  // row-major, header.columns_size() per row
};

// What ApplyRetention deleted.
struct RetentionReport {
  int64_t jobs = 0;    // jobs, sweep items included
  int64_t sweeps = 0;  // whole sweeps
  int64_t bytes = 0;   // bytes of stored results freed
};

class JobStore {
 public:
  // Opens (creating if needed) DIR/cablesim.db; DIR must exist.
  static absl::StatusOr<std::unique_ptr<JobStore>> Open(const std::string& dir);
  ~JobStore();

  // Puts jobs left RUNNING by a crash or shutdown back to QUEUED; returns
  // how many.
  absl::StatusOr<int> RequeueRunning();

  // Stores a QUEUED job for `scene`, `end_time_s` the run's end (progress),
  // submitted by client address `peer`; ResourceExhausted (naming
  // max_queued_jobs_per_peer) when that peer would have more than
  // `max_unfinished` jobs queued or running.
  // `tenant`: the token's tenant that owns it ("" without tokens).
  absl::StatusOr<v1::Job> InsertJob(
      const v1::Scene& scene, double end_time_s, const std::string& peer = "",
      int64_t max_unfinished = std::numeric_limits<int64_t>::max(),
      const std::string& tenant = "");
  // Stores the sweep and its item jobs in one transaction (the items count
  // against `max_unfinished` as InsertJob).
  absl::StatusOr<v1::Sweep> InsertSweep(
      const v1::SubmitSweepRequest& request, const std::vector<v1::Scene>& items,
      const std::vector<double>& end_times_s, const std::string& peer = "",
      int64_t max_unfinished = std::numeric_limits<int64_t>::max(),
      const std::string& tenant = "");

  absl::StatusOr<v1::Job> GetJob(const std::string& id);
  absl::StatusOr<v1::Scene> GetScene(const std::string& id);
  // Newest first, at most `limit`, and with `tenant`, only that tenant's.
  // Paging: only jobs older than job `after_id` (InvalidArgument when no
  // such job).
  absl::StatusOr<std::vector<v1::Job>> ListJobs(v1::JobState state, const std::string& sweep_id,
                                                int limit, const std::string& after_id = "",
                                                const std::string* tenant = nullptr);
  // The tenant that owns job or sweep `id` (by its prefix); NotFound.
  absl::StatusOr<std::string> Tenant(const std::string& id);
  // Ids of QUEUED jobs, oldest first.
  absl::StatusOr<std::vector<std::string>> QueuedJobIds();

  // QUEUED -> RUNNING (attempts + 1); false when the job was not QUEUED.
  absl::StatusOr<bool> MarkRunning(const std::string& id);
  // RUNNING -> QUEUED (shutdown before it finished).
  absl::Status Requeue(const std::string& id);
  // QUEUED -> CANCELLED; false when the job was not QUEUED.
  absl::StatusOr<bool> CancelQueued(const std::string& id);
  // RUNNING -> `state` with the summary and the trajectory, in one
  // transaction; false when the job was not RUNNING.
  absl::StatusOr<bool> Finish(const std::string& id, v1::JobState state,
                              const v1::RunSummary& summary, const StoredResult& result);

  // NotFound when the job has no result.
  absl::StatusOr<StoredResult> GetResult(const std::string& id);

  // The sweep with its counts and job ids.
  absl::StatusOr<v1::Sweep> GetSweep(const std::string& id);

  // Deletes a finished job outside any sweep and its result; returns the
  // bytes of result freed. NotFound for no such job; FailedPrecondition
  // while it is queued or running, or when it is a sweep's item. Ids are
  // never reused (AUTOINCREMENT).
  absl::StatusOr<int64_t> DeleteJob(const std::string& id);
  // Deletes a sweep whose items have all finished, with its items and
  // their results; returns the bytes freed.
  absl::StatusOr<int64_t> DeleteSweep(const std::string& id);
  // Retention: deletes finished jobs (outside sweeps) and whole finished
  // sweeps, oldest finished first, while they finished before
  // `older_than_unix_ms` or the stored results take more than `max_bytes`.
  absl::StatusOr<RetentionReport> ApplyRetention(int64_t older_than_unix_ms, int64_t max_bytes);

 private:
  JobStore(sqlite3* db, int lock_fd) : db_(db), lock_fd_(lock_fd) {}
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
};

// The ids of rows made before ids were random (`j-000042`), which such
// rows keep.
std::string JobId(int64_t seq);
std::string SweepId(int64_t seq);
// Whether `id` names a sweep (`s-...`) rather than a job (`j-...`).
bool IsSweepId(const std::string& id);
int64_t NowUnixMs();

}  // namespace cablesim

#endif  // CABLESIM_SERVER_JOB_STORE_H_
