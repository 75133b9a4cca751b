#ifndef CABLESIM_SERVER_STORE_SQL_JOB_STORE_H_
#define CABLESIM_SERVER_STORE_SQL_JOB_STORE_H_

// What the two job stores share: every transaction whose shape is the same
// in SQLite and PostgreSQL (insert, claim, finish, requeue, cancel, list
// with page keys, sweeps, deletion, retention, row checks), written once
// here over a small per-dialect table of statements (SqlStatements). A
// dialect (SqliteJobStore, PostgresJobStore) supplies the statements, runs
// one statement with named parameters (SqlJobStore::Run), and keeps what
// only it has (opening and migrations; leases and notifications for
// PostgreSQL; disk space for SQLite).
//
// Statements name their parameters `@name`; the shared layer binds them
// by name, and a statement that does not use one ignores it. Job states
// are bound as SqlState: SQLite receives the contract's number, which its
// jobs table stores; PostgreSQL receives the state's name (`RUNNING`) and
// maps it with the SQL function cablesim_state (migration 6), so no query
// spells a state as a bare integer and the stored integers stay as they
// were.

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "server/store/job_store.h"

namespace cablesim {

// A parameter's value. Text and bytes are both std::string: SqlBytes marks
// binary data (blobs, bytea).
struct SqlBytes {
  std::string data;
};
struct SqlState {
  v1::JobState state;
};
using SqlValue = std::variant<int64_t, double, std::string, SqlBytes, SqlState>;
// Named parameters, names without the `@`.
using SqlParams = std::vector<std::pair<const char*, SqlValue>>;

// The rows one statement returned (all of them, read after the statement
// ran), and how many rows it changed.
class SqlRows {
 public:
  virtual ~SqlRows() = default;
  virtual int size() const = 0;
  // NULL reads as 0 and as "".
  virtual int64_t Int(int row, int col) const = 0;
  virtual double Real(int row, int col) const = 0;
  virtual std::string Bytes(int row, int col) const = 0;
  // Rows an INSERT, UPDATE or DELETE changed.
  virtual int64_t changed() const = 0;
};

// The statements of one dialect. Job rows (job_by_id, list_jobs) have the
// columns JobFromRow reads: seq, state, name, created_ms, started_ms,
// finished_ms, attempts, end_time_s, summary, sweep_seq (0 outside
// sweeps), sweep_index, result bytes, pid, sweep pid, progress_time_s,
// intact (1 when the row passes its checksum).
// Parameters each may use: @id (a public id), @seq, @owner and @lease_ms
// (the claim, for shared stores), @now_ms (this server's clock), states
// @queued, @running, @succeeded, @failed, @cancelled, @state, and the ones
// named beside each.
struct SqlStatements {
  std::string begin;  // starts a write transaction (COMMIT and ROLLBACK end it)
  // -> changed; RUNNING jobs nobody runs any longer back to QUEUED.
  std::string requeue_running;
  // -> count of @peer's unfinished jobs; peer_lock (may be empty) first,
  // in the same transaction.
  std::string peer_lock;
  std::string peer_unfinished;
  // @name, @scene, @end_time_s, @peer, @tenant; insert_item also
  // @sweep_seq, @sweep_index. insert_sweep (@name, @axes, @tenant) -> seq.
  std::string insert_job;
  std::string insert_sweep;
  std::string insert_item;
  std::string job_by_id;    // -> job columns
  std::string scene_by_id;  // -> scene
  std::string sweep_seq_by_id;  // -> seq
  // @any_state, @state, @sweep_seq, @before_seq, @any_tenant, @tenant,
  // @limit -> job columns, newest first.
  std::string list_jobs;
  std::string tenant_of_job;    // -> tenant, intact
  std::string tenant_of_sweep;  // -> tenant, intact
  // -> kind ('job' or 'sweep'), seq, pid of rows that fail their checksum.
  std::string damaged_rows;
  // -> job_seq, pid, header, vals, checksum, encoding of every result.
  std::string all_results;
  std::string queued_ids;  // -> pid, oldest first
  // -> pid, attempts of the job claimed (none when there is none).
  std::string claim_next;
  std::string mark_running;   // -> a row when the job was QUEUED
  std::string requeue;        // @attempt
  std::string cancel_queued;  // -> a row when cancelled
  // @state, @summary, @attempt -> seq when the claim held.
  std::string finish;
  // @seq, @header, @vals, @checksum, @encoding (replaces any).
  std::string store_result;
  std::string result_by_id;  // -> header, vals, checksum, encoding
  std::string sweep_by_id;   // -> name, axes, created_ms, seq, intact
  std::string sweep_items;   // @seq -> pid, state, intact, by index
  // -> state, sweep_seq (0 outside sweeps), result bytes, sweep pid, seq;
  // locks the row where the dialect can.
  std::string job_for_delete;
  std::string sweep_for_delete;   // -> seq; locks the row
  std::string sweep_unfinished;   // @seq -> unfinished items, result bytes
  std::string delete_job_results;    // @seq: of that finished job outside sweeps
  std::string delete_job;            // @seq -> changed
  std::string delete_sweep_results;  // @seq
  std::string delete_sweep_jobs;     // @seq -> changed
  std::string delete_sweep;          // @seq
  std::string results_bytes;         // -> total bytes of stored results
  // -> is sweep (0/1), seq, finished_ms, bytes of what retention may
  // delete, oldest finished first.
  std::string retention_candidates;
};

class SqlJobStore : public JobStore {
 public:
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

 protected:
  // `sql` outlives the store (a static table).
  explicit SqlJobStore(const SqlStatements& sql) : sql_(sql) {}

  // Runs one statement with `params` bound by name (those it does not
  // name are ignored); mu_ held.
  virtual absl::StatusOr<std::unique_ptr<SqlRows>> Run(const std::string& sql,
                                                       const SqlParams& params) = 0;
  // Before each call's first statement (PostgreSQL: reconnects when the
  // server dropped the connection); mu_ held.
  virtual void Ready() {}
  // After a change other servers should learn of, in the change's
  // transaction when there is one (PostgreSQL: NOTIFY); mu_ held.
  virtual void Changed() {}
  // The claim's owner and lease (shared stores).
  virtual std::string owner_param() const { return ""; }
  virtual int64_t lease_ms_param() const { return 0; }

  // Runs `sql` with the common parameters (@owner, @lease_ms, @now_ms,
  // the states) and `params`; mu_ held.
  absl::StatusOr<std::unique_ptr<SqlRows>> Query(const std::string& sql,
                                                 const SqlParams& params = {});

  absl::Mutex mu_;
  std::string page_token_secret_;  // set by the dialect's Open

 private:
  class SqlTransaction;
  // ResourceExhausted when `peer` has unfinished jobs and `adding` more
  // would exceed `max_unfinished`; in the caller's transaction, mu_ held.
  absl::Status CheckPeerRoom(const std::string& peer, int64_t adding, int64_t max_unfinished);
  absl::StatusOr<v1::Job> GetJobLocked(const std::string& id);
  absl::StatusOr<v1::Sweep> GetSweepLocked(const std::string& id);

  const SqlStatements& sql_;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_SQL_JOB_STORE_H_
