#include "server/store/sql_job_store.h"

#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "server/result_codec.h"

namespace cablesim {
namespace {

// The columns of a job row (SqlStatements).
enum JobColumn {
  kSeq, kState, kName, kCreated, kStarted, kFinished, kAttempts, kEndTime, kSummary,
  kSweepSeq, kSweepIndex, kResultBytes, kPid, kSweepPid, kProgress, kIntact,
};

v1::Job JobFromRow(const SqlRows& r, int row) {
  v1::Job job;
  job.set_id(r.Bytes(row, kPid));
  job.set_state(static_cast<v1::JobState>(r.Int(row, kState)));
  job.set_name(r.Bytes(row, kName));
  job.set_created_unix_ms(r.Int(row, kCreated));
  job.set_started_unix_ms(r.Int(row, kStarted));
  job.set_finished_unix_ms(r.Int(row, kFinished));
  job.set_attempts(static_cast<int>(r.Int(row, kAttempts)));
  job.set_end_time_s(r.Real(row, kEndTime));
  const std::string summary = r.Bytes(row, kSummary);
  if (!summary.empty()) job.mutable_summary()->ParseFromString(summary);
  if (r.Int(row, kSweepSeq) > 0) {
    job.set_sweep_id(r.Bytes(row, kSweepPid));
    job.set_sweep_index(static_cast<int>(r.Int(row, kSweepIndex)));
  }
  job.set_stored_bytes(r.Int(row, kResultBytes));
  if (job.state() == v1::RUNNING) job.set_progress_time_s(r.Real(row, kProgress));
  return job;
}

absl::Status NoJob(const std::string& id) {
  return absl::NotFoundError(absl::StrCat("no job \"", id, "\""));
}
absl::Status NoSweep(const std::string& id) {
  return absl::NotFoundError(absl::StrCat("no sweep \"", id, "\""));
}

}  // namespace

// A write transaction: `begin` at construction, ROLLBACK at destruction
// unless committed.
class SqlJobStore::SqlTransaction {
 public:
  explicit SqlTransaction(SqlJobStore* store) : store_(store) {
    absl::StatusOr<std::unique_ptr<SqlRows>> r = store_->Run(store_->sql_.begin, {});
    begun_ = r.status();
  }
  ~SqlTransaction() {
    if (begun_.ok() && !done_) store_->Run("ROLLBACK", {}).IgnoreError();
  }
  const absl::Status& begun() const { return begun_; }
  absl::Status Commit() {
    done_ = true;
    absl::StatusOr<std::unique_ptr<SqlRows>> r = store_->Run("COMMIT", {});
    if (!r.ok()) store_->Run("ROLLBACK", {}).IgnoreError();
    return r.status();
  }

 private:
  SqlJobStore* store_;
  absl::Status begun_;
  bool done_ = false;
};

absl::StatusOr<std::unique_ptr<SqlRows>> SqlJobStore::Query(const std::string& sql,
                                                            const SqlParams& params) {
  SqlParams all = {{"owner", owner_param()},
                   {"lease_ms", lease_ms_param()},
                   {"now_ms", NowUnixMs()},
                   {"queued", SqlState{v1::QUEUED}},
                   {"running", SqlState{v1::RUNNING}},
                   {"succeeded", SqlState{v1::SUCCEEDED}},
                   {"failed", SqlState{v1::FAILED}},
                   {"cancelled", SqlState{v1::CANCELLED}}};
  all.insert(all.end(), params.begin(), params.end());
  return Run(sql, all);
}

absl::StatusOr<int> SqlJobStore::RequeueRunning() {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.requeue_running);
  if (!r.ok()) return r.status();
  return static_cast<int>((*r)->changed());
}

absl::Status SqlJobStore::CheckPeerRoom(const std::string& peer, int64_t adding,
                                        int64_t max_unfinished) {
  if (max_unfinished == std::numeric_limits<int64_t>::max()) return absl::OkStatus();
  if (!sql_.peer_lock.empty()) {
    if (absl::Status st = Query(sql_.peer_lock, {{"peer", peer}}).status(); !st.ok()) return st;
  }
  absl::StatusOr<std::unique_ptr<SqlRows>> c = Query(sql_.peer_unfinished, {{"peer", peer}});
  if (!c.ok()) return c.status();
  const int64_t unfinished = (*c)->Int(0, 0);
  if (unfinished + adding > max_unfinished) {
    return PeerLimitExceeded(peer, unfinished, adding, max_unfinished);
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::Job> SqlJobStore::InsertJob(const v1::Scene& scene, double end_time_s,
                                               const std::string& peer, int64_t max_unfinished,
                                               const std::string& tenant) {
  absl::StatusOr<std::string> pid = NewPublicId('j');
  if (!pid.ok()) return pid.status();
  absl::MutexLock lock(&mu_);
  Ready();
  {
    SqlTransaction tx(this);
    if (!tx.begun().ok()) return tx.begun();
    if (absl::Status st = CheckPeerRoom(peer, 1, max_unfinished); !st.ok()) return st;
    absl::StatusOr<std::unique_ptr<SqlRows>> r =
        Query(sql_.insert_job, {{"name", scene.name()},
                                {"scene", SqlBytes{scene.SerializeAsString()}},
                                {"end_time_s", end_time_s},
                                {"peer", peer},
                                {"tenant", tenant},
                                {"id", *pid}});
    if (!r.ok()) return r.status();
    Changed();
    if (absl::Status st = tx.Commit(); !st.ok()) return st;
  }
  return GetJobLocked(*pid);
}

absl::StatusOr<v1::Sweep> SqlJobStore::InsertSweep(const v1::SubmitSweepRequest& request,
                                                   const std::vector<v1::Scene>& items,
                                                   const std::vector<double>& end_times_s,
                                                   const std::string& peer,
                                                   int64_t max_unfinished,
                                                   const std::string& tenant) {
  absl::StatusOr<std::string> sweep_pid = NewPublicId('s');
  if (!sweep_pid.ok()) return sweep_pid.status();
  absl::MutexLock lock(&mu_);
  Ready();
  {
    SqlTransaction tx(this);
    if (!tx.begun().ok()) return tx.begun();
    if (absl::Status st = CheckPeerRoom(peer, static_cast<int64_t>(items.size()), max_unfinished);
        !st.ok()) {
      return st;
    }
    v1::Sweep axes;
    *axes.mutable_axes() = request.axes();
    *axes.mutable_thresholds() = request.thresholds();  // kept with the axes
    const int64_t now = NowUnixMs();
    absl::StatusOr<std::unique_ptr<SqlRows>> s =
        Query(sql_.insert_sweep, {{"name", request.name()},
                                  {"axes", SqlBytes{axes.SerializeAsString()}},
                                  {"created_ms", now},
                                  {"tenant", tenant},
                                  {"id", *sweep_pid}});
    if (!s.ok()) return s.status();
    if ((*s)->size() != 1) return absl::InternalError("the sweep's row number is missing");
    const int64_t sweep_seq = (*s)->Int(0, 0);
    for (size_t i = 0; i < items.size(); ++i) {
      absl::StatusOr<std::string> item_pid = NewPublicId('j');
      if (!item_pid.ok()) return item_pid.status();
      absl::StatusOr<std::unique_ptr<SqlRows>> r =
          Query(sql_.insert_item, {{"name", items[i].name()},
                                   {"scene", SqlBytes{items[i].SerializeAsString()}},
                                   {"end_time_s", end_times_s[i]},
                                   {"created_ms", now},
                                   {"sweep_seq", sweep_seq},
                                   {"sweep_index", static_cast<int64_t>(i)},
                                   {"peer", peer},
                                   {"tenant", tenant},
                                   {"id", *item_pid}});
      if (!r.ok()) return r.status();
    }
    Changed();
    if (absl::Status st = tx.Commit(); !st.ok()) return st;
  }
  return GetSweepLocked(*sweep_pid);
}

absl::StatusOr<v1::Job> SqlJobStore::GetJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  return GetJobLocked(id);
}

absl::StatusOr<v1::Job> SqlJobStore::GetJobLocked(const std::string& id) {
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.job_by_id, {{"id", id}});
  if (!r.ok()) return r.status();
  if ((*r)->size() == 0) return NoJob(id);
  if ((*r)->Int(0, kIntact) != 1) return DamagedRow("job", id);
  return JobFromRow(**r, 0);
}

absl::StatusOr<v1::Scene> SqlJobStore::GetScene(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.scene_by_id, {{"id", id}});
  if (!r.ok()) return r.status();
  if ((*r)->size() == 0) return NoJob(id);
  v1::Scene scene;
  if (!scene.ParseFromString((*r)->Bytes(0, 0))) {
    return absl::DataLossError("stored scene unreadable");
  }
  return scene;
}

absl::StatusOr<std::vector<v1::Job>> SqlJobStore::ListJobs(v1::JobState state,
                                                           const std::string& sweep_id, int limit,
                                                           int64_t after_key,
                                                           const std::string* tenant,
                                                           std::vector<int64_t>* keys) {
  absl::MutexLock lock(&mu_);
  Ready();
  // 0: any sweep; -1: a sweep that does not exist (nothing listed).
  int64_t sweep_seq = 0;
  if (!sweep_id.empty()) {
    sweep_seq = -1;
    if (IsSweepId(sweep_id)) {
      absl::StatusOr<std::unique_ptr<SqlRows>> r =
          Query(sql_.sweep_seq_by_id, {{"id", sweep_id}});
      if (!r.ok()) return r.status();
      if ((*r)->size() > 0) sweep_seq = (*r)->Int(0, 0);
    }
  }
  const bool any_state = state == v1::JOB_STATE_UNSPECIFIED;
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(
      sql_.list_jobs,
      {{"any_state", int64_t{any_state}},
       // Any state the filter ignores still needs a name PostgreSQL knows.
       {"state", SqlState{any_state ? v1::QUEUED : state}},
       {"sweep_seq", sweep_seq},
       {"before_seq", after_key > 0 ? after_key : std::numeric_limits<int64_t>::max()},
       {"any_tenant", int64_t{tenant == nullptr}},
       {"tenant", tenant != nullptr ? *tenant : std::string()},
       {"limit", int64_t{limit}}});
  if (!r.ok()) return r.status();
  std::vector<v1::Job> jobs;
  if (keys != nullptr) keys->clear();
  for (int i = 0; i < (*r)->size(); ++i) {
    // A damaged row: a placeholder (JobStore::ListJobs).
    jobs.push_back((*r)->Int(i, kIntact) == 1 ? JobFromRow(**r, i) : v1::Job());
    if (keys != nullptr) keys->push_back((*r)->Int(i, kSeq));
  }
  return jobs;
}

absl::StatusOr<std::string> SqlJobStore::Tenant(const std::string& id) {
  const bool sweep = IsSweepId(id);
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r =
      Query(sweep ? sql_.tenant_of_sweep : sql_.tenant_of_job, {{"id", id}});
  if (!r.ok()) return r.status();
  if ((*r)->size() == 0) return sweep ? NoSweep(id) : NoJob(id);
  // A damaged row's tenant cannot be trusted: DataLoss for everyone.
  if ((*r)->Int(0, 1) != 1) return DamagedRow(sweep ? "sweep" : "job", id);
  return (*r)->Bytes(0, 0);
}

absl::StatusOr<std::vector<std::string>> SqlJobStore::CheckRows() {
  absl::MutexLock lock(&mu_);
  Ready();
  std::vector<std::string> damaged;
  absl::StatusOr<std::unique_ptr<SqlRows>> rows = Query(sql_.damaged_rows);
  if (!rows.ok()) return rows.status();
  for (int i = 0; i < (*rows)->size(); ++i) {
    damaged.push_back(absl::StrCat((*rows)->Bytes(i, 0), " ", (*rows)->Bytes(i, 2), " (row ",
                                   (*rows)->Int(i, 1), "): the row fails its checksum"));
  }
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.all_results);
  if (!r.ok()) return r.status();
  for (int i = 0; i < (*r)->size(); ++i) {
    const std::string id = (*r)->Bytes(i, 1);
    absl::StatusOr<StoredResult> result = CheckedResult(
        id, (*r)->Bytes(i, 2), (*r)->Bytes(i, 3), (*r)->Int(i, 4), (*r)->Int(i, 5));
    if (!result.ok()) {
      damaged.push_back(absl::StrCat("result of job ", id, " (row ", (*r)->Int(i, 0),
                                     "): ", result.status().message()));
    }
  }
  return damaged;
}

absl::StatusOr<std::vector<std::string>> SqlJobStore::QueuedJobIds() {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.queued_ids);
  if (!r.ok()) return r.status();
  std::vector<std::string> ids;
  for (int i = 0; i < (*r)->size(); ++i) ids.push_back((*r)->Bytes(i, 0));
  return ids;
}

absl::StatusOr<std::optional<Claim>> SqlJobStore::ClaimNext() {
  absl::MutexLock lock(&mu_);
  Ready();
  // One statement takes the job (SqlStatements::claim_next): no other
  // claim can take it between the look and the update.
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.claim_next);
  if (!r.ok()) return r.status();
  if ((*r)->size() == 0) return std::nullopt;
  Changed();
  return Claim{(*r)->Bytes(0, 0), static_cast<int>((*r)->Int(0, 1))};
}

absl::StatusOr<bool> SqlJobStore::MarkRunning(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.mark_running, {{"id", id}});
  if (!r.ok()) return r.status();
  return (*r)->size() == 1;
}

absl::Status SqlJobStore::Requeue(const std::string& id, int attempt) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r =
      Query(sql_.requeue, {{"id", id}, {"attempt", int64_t{attempt}}});
  if (!r.ok()) return r.status();
  Changed();
  return absl::OkStatus();
}

absl::StatusOr<bool> SqlJobStore::CancelQueued(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.cancel_queued, {{"id", id}});
  if (!r.ok()) return r.status();
  if ((*r)->size() == 1) Changed();
  return (*r)->size() == 1;
}

absl::StatusOr<bool> SqlJobStore::Finish(const std::string& id, v1::JobState state,
                                         const v1::RunSummary& summary,
                                         const StoredResult& result, int attempt) {
  std::string header = result.header.SerializeAsString();
  EncodedValues vals = EncodeValues(result.values, result.header.columns_size());
  const int64_t checksum =
      ResultChecksum(header.data(), header.size(), vals.blob.data(), vals.blob.size());
  absl::MutexLock lock(&mu_);
  Ready();
  SqlTransaction tx(this);
  if (!tx.begun().ok()) return tx.begun();
  absl::StatusOr<std::unique_ptr<SqlRows>> u =
      Query(sql_.finish, {{"id", id},
                          {"state", SqlState{state}},
                          {"summary", SqlBytes{summary.SerializeAsString()}},
                          {"attempt", int64_t{attempt}}});
  if (!u.ok()) return u.status();
  if ((*u)->size() != 1) return false;
  absl::StatusOr<std::unique_ptr<SqlRows>> r =
      Query(sql_.store_result, {{"seq", (*u)->Int(0, 0)},
                                {"header", SqlBytes{std::move(header)}},
                                {"vals", SqlBytes{std::move(vals.blob)}},
                                {"checksum", checksum},
                                {"encoding", int64_t{vals.encoding}}});
  if (!r.ok()) return r.status();
  Changed();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return true;
}

absl::StatusOr<StoredResult> SqlJobStore::GetResult(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.result_by_id, {{"id", id}});
  if (!r.ok()) return r.status();
  if ((*r)->size() == 0) {
    return absl::NotFoundError(absl::StrCat("job \"", id, "\" has no result"));
  }
  // Never serve altered data: the checksum written with the result must
  // still match.
  return CheckedResult(id, (*r)->Bytes(0, 0), (*r)->Bytes(0, 1), (*r)->Int(0, 2),
                       (*r)->Int(0, 3));
}

absl::StatusOr<v1::Sweep> SqlJobStore::GetSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  return GetSweepLocked(id);
}

absl::StatusOr<v1::Sweep> SqlJobStore::GetSweepLocked(const std::string& id) {
  if (!IsSweepId(id)) return NoSweep(id);
  absl::StatusOr<std::unique_ptr<SqlRows>> s = Query(sql_.sweep_by_id, {{"id", id}});
  if (!s.ok()) return s.status();
  if ((*s)->size() == 0) return NoSweep(id);
  if ((*s)->Int(0, 4) != 1) return DamagedRow("sweep", id);
  v1::Sweep sweep;
  sweep.ParseFromString((*s)->Bytes(0, 1));
  sweep.set_id(id);
  sweep.set_name((*s)->Bytes(0, 0));
  sweep.set_created_unix_ms((*s)->Int(0, 2));
  absl::StatusOr<std::unique_ptr<SqlRows>> r = Query(sql_.sweep_items, {{"seq", (*s)->Int(0, 3)}});
  if (!r.ok()) return r.status();
  int finished = 0, failed = 0;
  for (int i = 0; i < (*r)->size(); ++i) {
    // A damaged item: the sweep's ids and counts cannot be served whole.
    if ((*r)->Int(i, 2) != 1) {
      return absl::DataLossError(absl::StrCat("sweep ", id, ": the stored row of item ", i,
                                              " fails its checksum (the database is damaged); "
                                              "cablesim-server --check lists it"));
    }
    sweep.add_job_ids((*r)->Bytes(i, 0));
    const auto state = static_cast<v1::JobState>((*r)->Int(i, 1));
    if (IsFinished(state)) ++finished;
    if (state == v1::FAILED || state == v1::CANCELLED) ++failed;
  }
  sweep.set_items((*r)->size());
  sweep.set_finished(finished);
  sweep.set_failed(failed);
  return sweep;
}

absl::StatusOr<int64_t> SqlJobStore::DeleteJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  SqlTransaction tx(this);
  if (!tx.begun().ok()) return tx.begun();
  absl::StatusOr<std::unique_ptr<SqlRows>> s =
      Query(sql_.job_for_delete, {{"id", IsSweepId(id) ? std::string() : id}});
  if (!s.ok()) return s.status();
  if ((*s)->size() == 0) return NoJob(id);
  const auto state = static_cast<v1::JobState>((*s)->Int(0, 0));
  if (!IsFinished(state)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "job \"", id, "\" is ", v1::JobState_Name(state), "; cancel it before deleting it"));
  }
  if ((*s)->Int(0, 1) > 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("job \"", id, "\" is an item of sweep \"", (*s)->Bytes(0, 3),
                     "\"; delete the sweep (DeleteSweep) instead"));
  }
  const int64_t seq = (*s)->Int(0, 4);
  for (const std::string* sql : {&sql_.delete_job_results, &sql_.delete_job}) {
    if (absl::Status st = Query(*sql, {{"seq", seq}}).status(); !st.ok()) return st;
  }
  Changed();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return (*s)->Int(0, 2);
}

absl::StatusOr<int64_t> SqlJobStore::DeleteSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Ready();
  SqlTransaction tx(this);
  if (!tx.begun().ok()) return tx.begun();
  absl::StatusOr<std::unique_ptr<SqlRows>> s =
      Query(sql_.sweep_for_delete, {{"id", IsSweepId(id) ? id : std::string()}});
  if (!s.ok()) return s.status();
  if ((*s)->size() == 0) return NoSweep(id);
  const int64_t seq = (*s)->Int(0, 0);
  absl::StatusOr<std::unique_ptr<SqlRows>> c = Query(sql_.sweep_unfinished, {{"seq", seq}});
  if (!c.ok()) return c.status();
  if (const int64_t unfinished = (*c)->Int(0, 0); unfinished > 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("sweep \"", id, "\" has ", unfinished,
                     " unfinished items; cancel them before deleting it"));
  }
  for (const std::string* sql :
       {&sql_.delete_sweep_results, &sql_.delete_sweep_jobs, &sql_.delete_sweep}) {
    if (absl::Status st = Query(*sql, {{"seq", seq}}).status(); !st.ok()) return st;
  }
  Changed();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return (*c)->Int(0, 1);
}

absl::StatusOr<RetentionReport> SqlJobStore::ApplyRetention(int64_t older_than_unix_ms,
                                                            int64_t max_bytes) {
  absl::MutexLock lock(&mu_);
  Ready();
  absl::StatusOr<std::unique_ptr<SqlRows>> t = Query(sql_.results_bytes);
  if (!t.ok()) return t.status();
  if ((*t)->size() != 1) return absl::InternalError("the results' size is missing");
  int64_t total = (*t)->Int(0, 0);
  // What can go: finished jobs outside sweeps, and sweeps whose items have
  // all finished (a sweep goes as a whole), oldest finished first.
  absl::StatusOr<std::unique_ptr<SqlRows>> c = Query(sql_.retention_candidates);
  if (!c.ok()) return c.status();
  RetentionReport report;
  for (int i = 0; i < (*c)->size(); ++i) {
    const bool sweep = (*c)->Int(i, 0) != 0;
    const int64_t seq = (*c)->Int(i, 1), finished_ms = (*c)->Int(i, 2), bytes = (*c)->Int(i, 3);
    if (finished_ms >= older_than_unix_ms && total <= max_bytes) break;
    SqlTransaction tx(this);
    if (!tx.begun().ok()) return tx.begun();
    absl::Status st = Query(sweep ? sql_.delete_sweep_results : sql_.delete_job_results,
                            {{"seq", seq}})
                          .status();
    // Another server may have deleted it meanwhile: count what goes here.
    int64_t jobs = 0;
    if (st.ok()) {
      absl::StatusOr<std::unique_ptr<SqlRows>> d =
          Query(sweep ? sql_.delete_sweep_jobs : sql_.delete_job, {{"seq", seq}});
      st = d.status();
      if (d.ok()) jobs = (*d)->changed();
    }
    if (st.ok() && sweep) st = Query(sql_.delete_sweep, {{"seq", seq}}).status();
    if (st.ok()) st = tx.Commit();
    if (!st.ok()) return st;
    total -= bytes;
    report.jobs += jobs;
    report.sweeps += sweep ? 1 : 0;
    report.bytes += bytes;
  }
  if (report.jobs > 0) Changed();
  return report;
}

}  // namespace cablesim
