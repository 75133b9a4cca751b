#ifndef CABLESIM_SERVER_STORE_JOB_STORE_H_
#define CABLESIM_SERVER_STORE_JOB_STORE_H_

// Durable jobs, sweeps and results: the interface of the job stores
// (SqliteJobStore, one server's embedded database, the default;
// PostgresJobStore, one database shared by any number of servers). Both
// keep the same promises: a job is stored before its id is returned; a
// job's result and its final state are written in one transaction, by the
// one claim that holds the job, so every accepted job reaches one stored
// result, exactly once, whatever process dies when; each result is stored
// with a CRC-32 of its bytes, verified on every read (a mismatch is
// DATA_LOSS, never altered numbers). Thread-safe.
//
// Ids: job `j-` and sweep `s-` followed by 128 random bits (22 URL-safe
// base64 characters), so that they cannot be guessed; rows stored before
// random ids keep theirs (`j-000042`). Rows are numbered internally
// (AUTOINCREMENT, never reused).

#include <cstdint>
#include <limits>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "cablesim/v1/service.pb.h"

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

// A job taken by a worker: its id and the attempt this claim is (Finish
// and Requeue with the attempt act only while the claim still holds).
struct Claim {
  std::string id;
  int attempt = 0;
};

// A running job as its worker reports it (JobStore::Heartbeat).
struct RunningJob {
  std::string id;
  int attempt = 0;
  double progress_time_s = 0;
};

// What a heartbeat learnt about the jobs it renewed.
struct HeartbeatReply {
  // Jobs whose cancellation another server recorded (RequestCancel).
  std::vector<std::string> cancel;
  // Jobs whose claim no longer holds (the lease expired and another claim
  // took the job): their worker stops and stores nothing.
  std::vector<std::string> lost;
};

// How a store is opened.
struct StoreOptions {
  // Shared stores: a claim holds for this long after the last heartbeat;
  // after it, another server takes the job again.
  int64_t lease_ms = 10'000;
  // Shared stores: listen for other servers' changes (LISTEN/NOTIFY);
  // false: rely on polling alone (benchmarks measure the difference).
  bool notifications = true;
};

// The claim order of both stores (SQL for SQLite and PostgreSQL alike,
// over `jobs j`): first the jobs of the tenant (without a tenant: of the
// client address) whose latest start is oldest, a tenant that never ran
// anything first of all; then the oldest job. Serving whoever waited
// longest since their last start is round-robin across tenants.
inline constexpr char kFairShareOrder[] =
    "(CASE WHEN j.tenant <> '' "
    "THEN (SELECT COALESCE(MAX(s.started_ms), 0) FROM jobs s WHERE s.tenant = j.tenant) "
    "ELSE (SELECT COALESCE(MAX(s.started_ms), 0) FROM jobs s "
    "WHERE s.tenant = '' AND s.peer = j.peer) END), j.seq";

class JobStore {
 public:
  // `spec`: `sqlite:DIR` or a bare DIR (SqliteJobStore), or a libpq URL
  // `postgresql://[user[:password]@]host[:port]/database[?...]`
  // (PostgresJobStore).
  static absl::StatusOr<std::unique_ptr<JobStore>> Open(const std::string& spec,
                                                        const StoreOptions& options = {});
  virtual ~JobStore() = default;

  // What the store is, for logs (never a password).
  virtual std::string Describe() const = 0;
  // Whether other servers may use the same store (then the manager sends
  // heartbeats and polls for work queued elsewhere).
  virtual bool shared() const { return false; }

  // Puts jobs left RUNNING by a dead server back to QUEUED; returns how
  // many. (SQLite: every RUNNING job, as only this server can use it;
  // shared: those whose lease has expired.)
  virtual absl::StatusOr<int> RequeueRunning() = 0;

  // Stores a QUEUED job for `scene`, `end_time_s` the run's end (progress),
  // submitted by client address `peer`; ResourceExhausted (naming
  // max_queued_jobs_per_peer) when that peer would have more than
  // `max_unfinished` jobs queued or running.
  // `tenant`: the token's tenant that owns it ("" without tokens).
  virtual absl::StatusOr<v1::Job> InsertJob(
      const v1::Scene& scene, double end_time_s, const std::string& peer = "",
      int64_t max_unfinished = std::numeric_limits<int64_t>::max(),
      const std::string& tenant = "") = 0;
  // Stores the sweep and its item jobs in one transaction (the items count
  // against `max_unfinished` as InsertJob).
  virtual absl::StatusOr<v1::Sweep> InsertSweep(
      const v1::SubmitSweepRequest& request, const std::vector<v1::Scene>& items,
      const std::vector<double>& end_times_s, const std::string& peer = "",
      int64_t max_unfinished = std::numeric_limits<int64_t>::max(),
      const std::string& tenant = "") = 0;

  // The job; a RUNNING job of a shared store carries the progress its
  // server last reported.
  virtual absl::StatusOr<v1::Job> GetJob(const std::string& id) = 0;
  virtual absl::StatusOr<v1::Scene> GetScene(const std::string& id) = 0;
  // Newest first, at most `limit`, and with `tenant`, only that tenant's.
  // A row whose checksum fails (CheckRows) is listed as a placeholder:
  // a Job with only its state, JOB_STATE_UNSPECIFIED (and its key), which
  // callers skip; GetJob and GetSweep answer DataLoss for such rows.
  // Keyset paging: each job has an order key (its internal row number,
  // larger for newer jobs, never reused); with `after_key` > 0, only jobs
  // whose key is smaller (whether or not the job of `after_key` still
  // exists). `keys`, when given, receives the listed jobs' keys.
  virtual absl::StatusOr<std::vector<v1::Job>> ListJobs(
      v1::JobState state, const std::string& sweep_id, int limit, int64_t after_key = 0,
      const std::string* tenant = nullptr, std::vector<int64_t>* keys = nullptr) = 0;
  // The secret that authenticates this store's page tokens (page_token.h):
  // 32 random bytes made when the store was created and kept in it (table
  // `meta`), so that tokens survive restarts and every server of a shared
  // store accepts the others' tokens.
  virtual const std::string& page_token_secret() const = 0;
  // Gives the disk space of deleted rows back to the file system, a bounded
  // step at a time (SQLite: `PRAGMA incremental_vacuum`); true while more
  // remains. Nothing for PostgreSQL, whose autovacuum reuses the space.
  virtual absl::StatusOr<bool> ReclaimSpace() { return false; }
  // The tenant that owns job or sweep `id` (by its prefix); NotFound.
  virtual absl::StatusOr<std::string> Tenant(const std::string& id) = 0;
  // Every stored row checked against its checksum (job rows, sweep rows
  // and results): one line per damaged row (`job j-...: ...`), empty when
  // none is (cablesim-server --check).
  virtual absl::StatusOr<std::vector<std::string>> CheckRows() = 0;
  // Ids of QUEUED jobs, oldest first.
  virtual absl::StatusOr<std::vector<std::string>> QueuedJobIds() = 0;

  // Takes the next QUEUED job (shared stores: or a RUNNING one whose
  // lease has expired) for this store's owner: QUEUED -> RUNNING,
  // attempts + 1. Nullopt when there is none. Two claims never get the
  // same job (shared stores: FOR UPDATE SKIP LOCKED). Fair share
  // (kFairShareOrder): round-robin across tenants (without tokens, across
  // client addresses), oldest first within one, so that one tenant's
  // thousand queued jobs do not hold back another's one.
  virtual absl::StatusOr<std::optional<Claim>> ClaimNext() = 0;
  // QUEUED -> RUNNING (attempts + 1); false when the job was not QUEUED.
  virtual absl::StatusOr<bool> MarkRunning(const std::string& id) = 0;
  // RUNNING -> QUEUED (shutdown before it finished); with `attempt` > 0,
  // only while that claim holds.
  virtual absl::Status Requeue(const std::string& id, int attempt = 0) = 0;
  // QUEUED -> CANCELLED; false when the job was not QUEUED.
  virtual absl::StatusOr<bool> CancelQueued(const std::string& id) = 0;
  // Records that RUNNING job `id` should stop (its server learns it at its
  // next Heartbeat). Nothing to do for a store only one server uses.
  virtual absl::Status RequestCancel(const std::string& id) { return absl::OkStatus(); }
  // Renews the leases of this server's running jobs and stores their
  // progress. Nothing to do for a store only one server uses.
  virtual absl::StatusOr<HeartbeatReply> Heartbeat(const std::vector<RunningJob>& running) {
    return HeartbeatReply();
  }
  // RUNNING -> `state` with the summary and the trajectory, in one
  // transaction; false when the job was not RUNNING (or, with `attempt`
  // > 0, when that claim no longer holds).
  virtual absl::StatusOr<bool> Finish(const std::string& id, v1::JobState state,
                                      const v1::RunSummary& summary, const StoredResult& result,
                                      int attempt = 0) = 0;

  // NotFound when the job has no result.
  virtual absl::StatusOr<StoredResult> GetResult(const std::string& id) = 0;

  // The sweep with its counts and job ids.
  virtual absl::StatusOr<v1::Sweep> GetSweep(const std::string& id) = 0;

  // Deletes a finished job outside any sweep and its result; returns the
  // bytes of result freed. NotFound for no such job; FailedPrecondition
  // while it is queued or running, or when it is a sweep's item. Ids are
  // never reused.
  virtual absl::StatusOr<int64_t> DeleteJob(const std::string& id) = 0;
  // Deletes a sweep whose items have all finished, with its items and
  // their results; returns the bytes freed.
  virtual absl::StatusOr<int64_t> DeleteSweep(const std::string& id) = 0;
  // Retention: deletes finished jobs (outside sweeps) and whole finished
  // sweeps, oldest finished first, while they finished before
  // `older_than_unix_ms` or the stored results take more than `max_bytes`.
  virtual absl::StatusOr<RetentionReport> ApplyRetention(int64_t older_than_unix_ms,
                                                         int64_t max_bytes) = 0;

  // Shared stores: `listener` is called (from another thread) whenever
  // another server changes a job, so that watchers and idle workers need
  // not wait for their next poll; null stops the calls (once this
  // returns, none is under way). Nothing for SQLite.
  virtual void SetChangeListener(std::function<void()> listener) {}
};

// The ids of rows made before ids were random (`j-000042`), which such
// rows keep.
std::string JobId(int64_t seq);
std::string SweepId(int64_t seq);
// Whether `id` names a sweep (`s-...`) rather than a job (`j-...`).
bool IsSweepId(const std::string& id);
int64_t NowUnixMs();
// Shared by the implementations: a new public id (`j-`/`s-` and 128
// random bits), the CRC-32 of a result's header and values blob as
// stored, a result read back, whether a state is final, 128 random bits
// as hex.
absl::StatusOr<std::string> NewPublicId(char prefix);
int64_t ResultChecksum(const void* header, size_t header_bytes, const void* vals,
                       size_t vals_bytes);
// Job `id`'s result from its stored columns: DataLoss (never altered data)
// unless `checksum` matches the header and values blob as stored and the
// blob decodes by its `encoding` (result_codec.h).
// DataLoss for a job or sweep row whose checksum fails.
absl::Status DamagedRow(absl::string_view kind, absl::string_view id);

absl::StatusOr<StoredResult> CheckedResult(const std::string& id, const std::string& header,
                                           const std::string& vals, int64_t checksum,
                                           int64_t encoding);
bool IsFinished(v1::JobState state);
// ResourceExhausted: client `peer` has `unfinished` jobs and asks for
// `adding` more beyond `max_unfinished` (max_queued_jobs_per_peer).
absl::Status PeerLimitExceeded(const std::string& peer, int64_t unfinished, int64_t adding,
                               int64_t max_unfinished);
absl::StatusOr<std::string> RandomId();
// A new store's page-token secret: 256 random bits as hex.
absl::StatusOr<std::string> NewPageTokenSecret();
// Creates directory `dir` (0700; missing parents with the default mode)
// unless it exists; FailedPrecondition naming it and the reason when it
// cannot, or when `dir` is not a directory.
absl::Status CreateDataDir(const std::string& dir);

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_JOB_STORE_H_
