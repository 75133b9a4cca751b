#include "server/store/postgres_job_store.h"

#include <endian.h>
#include <libpq-fe.h>
#include <poll.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "server/result_codec.h"

namespace cablesim {
namespace {

// SQL with the job states named: {QUEUED}, {RUNNING}, {SUCCEEDED},
// {FAILED} and {CANCELLED} become the numbers of the contract's JobState
// (service.proto), which is what the jobs table stores, so no query spells
// a state as a bare integer.
std::string NamedStates(absl::string_view sql) {
  return absl::StrReplaceAll(
      sql, {{"{QUEUED}", absl::StrCat(static_cast<int>(v1::QUEUED))},
            {"{RUNNING}", absl::StrCat(static_cast<int>(v1::RUNNING))},
            {"{SUCCEEDED}", absl::StrCat(static_cast<int>(v1::SUCCEEDED))},
            {"{FAILED}", absl::StrCat(static_cast<int>(v1::FAILED))},
            {"{CANCELLED}", absl::StrCat(static_cast<int>(v1::CANCELLED))}});
}

// The database's clock in Unix milliseconds: leases are compared with one
// clock, whichever server looks.
constexpr char kNowMs[] = "(extract(epoch from clock_timestamp()) * 1000)::bigint";

// Schema migrations, applied in order; a version is never edited once
// released, a change is a new version.
struct Migration {
  int version;
  const char* description;
  const char* sql;
};
constexpr Migration kMigrations[] = {
    {1, "jobs, sweeps, results and the store id", R"sql(
CREATE TABLE sweeps (
  seq BIGSERIAL PRIMARY KEY,
  pid TEXT NOT NULL UNIQUE,        -- the public id, `s-` and 128 random bits
  name TEXT NOT NULL,
  axes BYTEA NOT NULL,             -- cablesim.v1.Sweep with only the axes
  created_ms BIGINT NOT NULL,
  tenant TEXT NOT NULL DEFAULT '');
CREATE TABLE jobs (
  seq BIGSERIAL PRIMARY KEY,
  pid TEXT NOT NULL UNIQUE,        -- the public id, `j-` and 128 random bits
  state INTEGER NOT NULL,          -- cablesim.v1.JobState
  name TEXT NOT NULL,
  scene BYTEA NOT NULL,            -- cablesim.v1.Scene
  end_time_s DOUBLE PRECISION NOT NULL,
  created_ms BIGINT NOT NULL,
  started_ms BIGINT NOT NULL DEFAULT 0,
  finished_ms BIGINT NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  summary BYTEA,                   -- cablesim.v1.RunSummary once finished
  sweep_seq BIGINT REFERENCES sweeps(seq),  -- NULL outside sweeps
  sweep_index INTEGER NOT NULL DEFAULT 0,
  peer TEXT NOT NULL DEFAULT '',
  tenant TEXT NOT NULL DEFAULT '');
CREATE INDEX jobs_by_state ON jobs(state, seq);
CREATE INDEX jobs_by_sweep ON jobs(sweep_seq, sweep_index);
CREATE INDEX jobs_by_peer ON jobs(peer, state);
CREATE TABLE results (
  job_seq BIGINT PRIMARY KEY REFERENCES jobs(seq) ON DELETE CASCADE,
  header BYTEA NOT NULL,           -- cablesim.v1.RunHeader
  vals BYTEA NOT NULL,             -- row-major doubles, little-endian (encoding 0)
  checksum BIGINT NOT NULL);       -- CRC-32 of header then vals
CREATE TABLE meta (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL);
INSERT INTO meta (key, value) VALUES ('store_id', md5(random()::text || clock_timestamp()::text));
)sql"},
    {2, "leases: the claim's owner and expiry, cancel requests, progress", R"sql(
ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT '';
ALTER TABLE jobs ADD COLUMN lease_until_ms BIGINT NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN cancel_requested BOOLEAN NOT NULL DEFAULT FALSE;
ALTER TABLE jobs ADD COLUMN progress_time_s DOUBLE PRECISION NOT NULL DEFAULT 0;
)sql"},
    {3, "results compressed: how each row's vals are encoded (result_codec.h)", R"sql(
ALTER TABLE results ADD COLUMN encoding INTEGER NOT NULL DEFAULT 0;  -- 0: raw doubles, 1: zstd
)sql"},
    {4, "fair share: the last start of each tenant's (or client's) jobs found by index", R"sql(
CREATE INDEX IF NOT EXISTS jobs_by_tenant_start ON jobs(tenant, started_ms);
CREATE INDEX IF NOT EXISTS jobs_by_tenant_peer_start ON jobs(tenant, peer, started_ms);
)sql"},
    {5, "row checksums of jobs and sweeps, kept by triggers (JobStore::CheckRows)", R"sql(
ALTER TABLE jobs ADD COLUMN row_sum TEXT;
ALTER TABLE sweeps ADD COLUMN row_sum TEXT;
-- md5 of the served columns, in a text form no session setting changes
-- (doubles and bytes as hex).
CREATE FUNCTION cablesim_job_sum(j jobs) RETURNS TEXT LANGUAGE SQL IMMUTABLE AS $$
  SELECT md5(ROW(j.seq, j.pid, j.state, j.name, encode(float8send(j.end_time_s), 'hex'),
                 j.created_ms, j.started_ms, j.finished_ms, j.attempts, encode(j.summary, 'hex'),
                 j.sweep_seq, j.sweep_index, j.peer, j.tenant)::text) $$;
CREATE FUNCTION cablesim_sweep_sum(s sweeps) RETURNS TEXT LANGUAGE SQL IMMUTABLE AS $$
  SELECT md5(ROW(s.seq, s.pid, s.name, encode(s.axes, 'hex'), s.created_ms, s.tenant)::text) $$;
UPDATE jobs j SET row_sum = cablesim_job_sum(j);
UPDATE sweeps s SET row_sum = cablesim_sweep_sum(s);
-- A row already damaged keeps its checksum on update (the damage stays
-- visible).
CREATE FUNCTION cablesim_job_sum_trigger() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
  IF TG_OP = 'INSERT' THEN
    NEW.row_sum := cablesim_job_sum(NEW);
  ELSIF OLD.row_sum IS NOT DISTINCT FROM cablesim_job_sum(OLD) THEN
    NEW.row_sum := cablesim_job_sum(NEW);
  END IF;
  RETURN NEW;
END $$;
CREATE FUNCTION cablesim_sweep_sum_trigger() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
  IF TG_OP = 'INSERT' THEN
    NEW.row_sum := cablesim_sweep_sum(NEW);
  ELSIF OLD.row_sum IS NOT DISTINCT FROM cablesim_sweep_sum(OLD) THEN
    NEW.row_sum := cablesim_sweep_sum(NEW);
  END IF;
  RETURN NEW;
END $$;
CREATE TRIGGER jobs_row_sum BEFORE INSERT OR UPDATE OF seq, pid, state, name, end_time_s,
  created_ms, started_ms, finished_ms, attempts, summary, sweep_seq, sweep_index, peer, tenant
  ON jobs FOR EACH ROW EXECUTE FUNCTION cablesim_job_sum_trigger();
CREATE TRIGGER sweeps_row_sum BEFORE INSERT OR UPDATE OF seq, pid, name, axes, created_ms, tenant
  ON sweeps FOR EACH ROW EXECUTE FUNCTION cablesim_sweep_sum_trigger();
)sql"},
};

// An arbitrary constant: the advisory lock under which migrations run.
constexpr int64_t kMigrationLock = 0x63626c73696d;  // "cblsim"

std::string ConnectionError(PGconn* conn) {
  std::string text = conn != nullptr ? PQerrorMessage(conn) : "out of memory";
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

// A query result (binary format); cleared on destruction.
class PgResult {
 public:
  // `conn`: the connection that gave `r`, for its error message when `r`
  // is null (the connection lost or never made, or out of memory).
  PgResult(PGresult* r, PGconn* conn)
      : r_(r), no_result_(r == nullptr ? ConnectionError(conn) : std::string()) {}
  ~PgResult() { PQclear(r_); }
  PgResult(const PgResult&) = delete;
  PgResult& operator=(const PgResult&) = delete;

  bool ok() const {
    const ExecStatusType s = PQresultStatus(r_);
    return s == PGRES_COMMAND_OK || s == PGRES_TUPLES_OK;
  }
  absl::Status status() const {
    if (ok()) return absl::OkStatus();
    std::string text;
    if (r_ == nullptr) {
      text = absl::StrCat("the database is unreachable: ", no_result_);
    } else {
      const char* message = PQresultErrorMessage(r_);
      text = message != nullptr ? message : "error";
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    // Lost connection, or the database shutting down: try again later.
    const char* state = r_ != nullptr ? PQresultErrorField(r_, PG_DIAG_SQLSTATE) : nullptr;
    if (state == nullptr || std::strncmp(state, "08", 2) == 0 || std::strncmp(state, "57", 2) == 0) {
      return absl::UnavailableError(absl::StrCat("postgresql: ", text));
    }
    return absl::InternalError(absl::StrCat("postgresql: ", text));
  }
  int rows() const { return PQntuples(r_); }
  // Rows an INSERT, UPDATE or DELETE changed.
  int64_t changed() const { return std::atoll(PQcmdTuples(r_)); }
  bool Null(int row, int col) const { return PQgetisnull(r_, row, col) != 0; }
  int64_t Int(int row, int col) const {
    if (Null(row, col)) return 0;
    const char* v = PQgetvalue(r_, row, col);
    switch (PQgetlength(r_, row, col)) {
      case 1:
        return static_cast<unsigned char>(v[0]);  // bool
      case 2: {
        uint16_t x;
        std::memcpy(&x, v, 2);
        return static_cast<int16_t>(be16toh(x));
      }
      case 4: {
        uint32_t x;
        std::memcpy(&x, v, 4);
        return static_cast<int32_t>(be32toh(x));
      }
      default: {
        uint64_t x;
        std::memcpy(&x, v, 8);
        return static_cast<int64_t>(be64toh(x));
      }
    }
  }
  double Real(int row, int col) const {
    if (Null(row, col)) return 0;
    uint64_t x;
    std::memcpy(&x, PQgetvalue(r_, row, col), 8);
    x = be64toh(x);
    double d;
    std::memcpy(&d, &x, 8);
    return d;
  }
  std::string Bytes(int row, int col) const {
    if (Null(row, col)) return "";
    return std::string(PQgetvalue(r_, row, col), PQgetlength(r_, row, col));
  }

 private:
  PGresult* r_;
  std::string no_result_;
};

// Query parameters: numbers and text as text, blobs as binary.
class Params {
 public:
  Params& Int(int64_t v) { return Add(absl::StrCat(v), 0); }
  Params& Real(double v) { return Add(absl::StrFormat("%.17g", v), 0); }
  Params& Text(std::string v) { return Add(std::move(v), 0); }
  Params& Bytes(std::string v) { return Add(std::move(v), 1); }
  Params& Bytes(const void* data, size_t bytes) {
    return Add(std::string(static_cast<const char*>(data), bytes), 1);
  }

  PgResult Run(PGconn* conn, const std::string& sql) const {
    std::vector<const char*> values;
    std::vector<int> lengths;
    for (const std::string& v : values_) {
      values.push_back(v.data());
      lengths.push_back(static_cast<int>(v.size()));
    }
    return PgResult(PQexecParams(conn, sql.c_str(), static_cast<int>(values_.size()), nullptr,
                                 values.data(), lengths.data(), formats_.data(),
                                 /*resultFormat=*/1),
                    conn);
  }

 private:
  Params& Add(std::string v, int format) {
    values_.push_back(std::move(v));
    formats_.push_back(format);
    return *this;
  }
  std::vector<std::string> values_;
  std::vector<int> formats_;
};

// A transaction on `conn`: BEGIN at construction, ROLLBACK at
// destruction unless committed.
class Transaction {
 public:
  explicit Transaction(PGconn* conn) : conn_(conn) {
    PgResult r(PQexec(conn_, "BEGIN"), conn_);
    begun_ = r.status();
  }
  ~Transaction() {
    if (begun_.ok() && !done_) PQclear(PQexec(conn_, "ROLLBACK"));
  }
  const absl::Status& begun() const { return begun_; }
  absl::Status Commit() {
    done_ = true;
    PgResult r(PQexec(conn_, "COMMIT"), conn_);
    return r.status();
  }

 private:
  PGconn* conn_;
  absl::Status begun_;
  bool done_ = false;
};

// The columns JobFromRow reads, of `jobs j`.
constexpr char kJobColumns[] =
    "j.seq, j.state, j.name, j.created_ms, j.started_ms, j.finished_ms, j.attempts, "
    "j.end_time_s, j.summary, COALESCE(j.sweep_seq, 0), j.sweep_index, "
    "COALESCE((SELECT octet_length(header) + octet_length(vals) FROM results "
    "WHERE job_seq = j.seq), 0)::bigint, j.pid, "
    "COALESCE((SELECT pid FROM sweeps WHERE sweeps.seq = j.sweep_seq), ''), j.progress_time_s, "
    "(j.row_sum IS NOT DISTINCT FROM cablesim_job_sum(j) AND (j.sweep_seq IS NULL OR "
    "(SELECT w.row_sum IS NOT DISTINCT FROM cablesim_sweep_sum(w) FROM sweeps w "
    "WHERE w.seq = j.sweep_seq) IS TRUE))";
// Whether the row passed its checksum (the last of kJobColumns).
constexpr int kJobIntactColumn = 15;

v1::Job JobFromRow(const PgResult& r, int row) {
  v1::Job job;
  job.set_id(r.Bytes(row, 12));
  job.set_state(static_cast<v1::JobState>(r.Int(row, 1)));
  job.set_name(r.Bytes(row, 2));
  job.set_created_unix_ms(r.Int(row, 3));
  job.set_started_unix_ms(r.Int(row, 4));
  job.set_finished_unix_ms(r.Int(row, 5));
  job.set_attempts(static_cast<int>(r.Int(row, 6)));
  job.set_end_time_s(r.Real(row, 7));
  const std::string summary = r.Bytes(row, 8);
  if (!summary.empty()) job.mutable_summary()->ParseFromString(summary);
  if (r.Int(row, 9) > 0) {
    job.set_sweep_id(r.Bytes(row, 13));
    job.set_sweep_index(static_cast<int>(r.Int(row, 10)));
  }
  job.set_stored_bytes(r.Int(row, 11));
  if (job.state() == v1::RUNNING) job.set_progress_time_s(r.Real(row, 14));
  return job;
}

// The URL without its password, for logs.
std::string DescribeConnection(PGconn* conn) {
  return absl::StrCat("postgresql://", PQuser(conn), "@", PQhost(conn), ":", PQport(conn), "/",
                      PQdb(conn));
}

constexpr char kFinishedStates[] = "(3, 4, 5)";  // SUCCEEDED, FAILED, CANCELLED

}  // namespace

int PostgresJobStore::LatestSchemaVersion() {
  return kMigrations[sizeof(kMigrations) / sizeof(kMigrations[0]) - 1].version;
}

PostgresJobStore::PostgresJobStore(PGconn* conn, std::string url, const StoreOptions& options)
    : url_(std::move(url)), options_(options), conn_(conn) {
  char host[256] = "host";
  ::gethostname(host, sizeof(host) - 1);
  const absl::StatusOr<std::string> random = RandomId();
  owner_ = absl::StrCat(host, ":", ::getpid(), ":", random.ok() ? random->substr(0, 8) : "0");
  describe_ = DescribeConnection(conn);
}

absl::StatusOr<std::unique_ptr<PostgresJobStore>> PostgresJobStore::Open(
    const std::string& url, const StoreOptions& options) {
  PGconn* conn = PQconnectdb(url.c_str());
  if (conn == nullptr || PQstatus(conn) != CONNECTION_OK) {
    const std::string message = ConnectionError(conn);
    PQfinish(conn);
    // The URL may hold a password: name the store without it.
    return absl::UnavailableError(
        absl::StrCat("cannot connect to the PostgreSQL job store: ", message));
  }
  std::unique_ptr<PostgresJobStore> store(new PostgresJobStore(conn, url, options));
  absl::MutexLock lock(&store->mu_);
  if (absl::Status s = store->Migrate(); !s.ok()) {
    return absl::Status(s.code(), absl::StrCat(store->describe_, ": ", s.message()));
  }
  // The page-token secret (page_token.h): the first server to start makes
  // it, every server reads the same one.
  absl::StatusOr<std::string> fresh = NewPageTokenSecret();
  if (!fresh.ok()) return fresh.status();
  PgResult put(Params().Text(*fresh).Run(
      store->conn_,
      "INSERT INTO meta (key, value) VALUES ('page_token_secret', $1) ON CONFLICT (key) DO "
      "NOTHING"));
  if (!put.ok()) return put.status();
  PgResult get(
      Params().Run(store->conn_, "SELECT value FROM meta WHERE key = 'page_token_secret'"));
  if (!get.ok()) return get.status();
  if (get.rows() != 1) return absl::InternalError("meta.page_token_secret missing");
  store->page_token_secret_ = get.Bytes(0, 0);
  return store;
}

PostgresJobStore::~PostgresJobStore() {
  stop_ = true;
  if (listen_thread_.joinable()) listen_thread_.join();
  absl::MutexLock lock(&mu_);
  PQfinish(conn_);
}

void PostgresJobStore::EnsureConnected() {
  if (PQstatus(conn_) != CONNECTION_OK) PQreset(conn_);
}

absl::Status PostgresJobStore::Exec(const std::string& sql) {
  PgResult r(PQexec(conn_, sql.c_str()), conn_);
  return r.status();
}

void PostgresJobStore::Notify() {
  PgResult r(Params().Text(owner_).Run(conn_, "SELECT pg_notify('cablesim', $1)"));
  (void)r;
}

absl::Status PostgresJobStore::Migrate() {
  if (absl::Status s = Exec("SET client_min_messages = warning"); !s.ok()) return s;
  Transaction tx(conn_);
  if (!tx.begun().ok()) return tx.begun();
  if (absl::Status s = Exec(absl::StrCat(
          "SELECT pg_advisory_xact_lock(", kMigrationLock,
          "); CREATE TABLE IF NOT EXISTS schema_migrations (version INTEGER PRIMARY KEY, "
          "description TEXT NOT NULL, applied_ms BIGINT NOT NULL)"));
      !s.ok()) {
    return (s);
  }
  PgResult current(Params().Run(conn_, "SELECT COALESCE(MAX(version), 0) FROM schema_migrations"));
  if (!current.ok()) return (current.status());
  const int64_t version = current.Int(0, 0);
  if (version > LatestSchemaVersion()) {
    return (absl::FailedPreconditionError(absl::StrCat(
        "the database's schema is version ", version, ", newer than this server knows (",
        LatestSchemaVersion(), "): run a newer cablesim-server")));
  }
  for (const Migration& m : kMigrations) {
    if (m.version <= version) continue;
    if (absl::Status s = Exec(m.sql); !s.ok()) {
      return (absl::Status(
          s.code(), absl::StrCat("schema migration ", m.version, ": ", s.message())));
    }
    PgResult done(Params().Int(m.version).Text(m.description).Run(
        conn_, absl::StrCat("INSERT INTO schema_migrations (version, description, applied_ms) "
                            "VALUES ($1::int, $2, ",
                            kNowMs, ")")));
    if (!done.ok()) return (done.status());
  }
  return tx.Commit();
}

void PostgresJobStore::SetChangeListener(std::function<void()> listener) {
  const bool start = listener != nullptr;
  {
    absl::MutexLock lock(&listener_mu_);
    listener_ = std::move(listener);
  }
  if (start && options_.notifications && !listen_thread_.joinable()) listen_thread_ = std::thread([this] { Listen(); });
}

void PostgresJobStore::CallListener() {
  absl::MutexLock lock(&listener_mu_);
  if (listener_) listener_();
}

void PostgresJobStore::Listen() {
  PGconn* conn = nullptr;
  while (!stop_) {
    if (conn == nullptr || PQstatus(conn) != CONNECTION_OK) {
      PQfinish(conn);
      conn = PQconnectdb(url_.c_str());
      PgResult r(PQexec(conn, "LISTEN cablesim"), conn);
      if (!r.ok()) {
        // The database is away: the workers' polls carry on meanwhile.
        absl::SleepFor(absl::Milliseconds(500));
        continue;
      }
      CallListener();  // whatever happened while not listening
    }
    pollfd fd = {PQsocket(conn), POLLIN, 0};
    if (::poll(&fd, 1, 200) <= 0) continue;
    if (!PQconsumeInput(conn)) continue;  // broken: reconnect above
    bool changed = false;
    while (PGnotify* n = PQnotifies(conn)) {
      changed |= owner_ != n->extra;  // this server's own changes it knows
      PQfreemem(n);
    }
    if (changed) CallListener();
  }
  PQfinish(conn);
}

absl::StatusOr<int> PostgresJobStore::RequeueRunning() {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Run(conn_, NamedStates(absl::StrCat("UPDATE jobs SET state = {QUEUED}, owner = '' WHERE "
                                                          "state = {RUNNING} AND lease_until_ms < ",
                                                          kNowMs))));
  if (!r.ok()) return r.status();
  return static_cast<int>(r.changed());
}

absl::Status PostgresJobStore::CheckPeerRoom(const std::string& peer, int64_t adding,
                                             int64_t max_unfinished) {
  if (max_unfinished == std::numeric_limits<int64_t>::max()) return absl::OkStatus();
  // One peer's submissions one at a time, across servers, until commit.
  PgResult lock(Params().Text(peer).Run(conn_, "SELECT pg_advisory_xact_lock(hashtext($1))"));
  if (!lock.ok()) return lock.status();
  PgResult c(Params().Text(peer).Run(
      conn_, NamedStates("SELECT COUNT(*) FROM jobs WHERE peer = $1 AND state IN ({QUEUED}, {RUNNING})")));
  if (!c.ok()) return c.status();
  const int64_t unfinished = c.Int(0, 0);
  if (unfinished + adding > max_unfinished) {
    return PeerLimitExceeded(peer, unfinished, adding, max_unfinished);
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::Job> PostgresJobStore::InsertJob(const v1::Scene& scene, double end_time_s,
                                                    const std::string& peer,
                                                    int64_t max_unfinished,
                                                    const std::string& tenant) {
  absl::StatusOr<std::string> pid = NewPublicId('j');
  if (!pid.ok()) return pid.status();
  {
    absl::MutexLock lock(&mu_);
    EnsureConnected();
    Transaction tx(conn_);
    if (!tx.begun().ok()) return tx.begun();
    if (absl::Status st = CheckPeerRoom(peer, 1, max_unfinished); !st.ok()) return (st);
    PgResult r(Params()
                   .Text(scene.name())
                   .Bytes(scene.SerializeAsString())
                   .Real(end_time_s)
                   .Int(NowUnixMs())
                   .Text(peer)
                   .Text(tenant)
                   .Text(*pid)
                   .Run(conn_,
                        "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, peer, "
                        "tenant, pid) VALUES (1, $1, $2, $3, $4, $5, $6, $7)"));
    if (!r.ok()) return (r.status());
    Notify();
    if (absl::Status st = tx.Commit(); !st.ok()) return st;
  }
  return GetJob(*pid);
}

absl::StatusOr<v1::Sweep> PostgresJobStore::InsertSweep(const v1::SubmitSweepRequest& request,
                                                        const std::vector<v1::Scene>& items,
                                                        const std::vector<double>& end_times_s,
                                                        const std::string& peer,
                                                        int64_t max_unfinished,
                                                        const std::string& tenant) {
  absl::StatusOr<std::string> sweep_pid = NewPublicId('s');
  if (!sweep_pid.ok()) return sweep_pid.status();
  {
    absl::MutexLock lock(&mu_);
    EnsureConnected();
    Transaction tx(conn_);
    if (!tx.begun().ok()) return tx.begun();
    if (absl::Status st =
            CheckPeerRoom(peer, static_cast<int64_t>(items.size()), max_unfinished);
        !st.ok()) {
      return (st);
    }
    v1::Sweep axes;
    *axes.mutable_axes() = request.axes();
    *axes.mutable_thresholds() = request.thresholds();  // kept with the axes
    const int64_t now = NowUnixMs();
    PgResult s(Params()
                   .Text(request.name())
                   .Bytes(axes.SerializeAsString())
                   .Int(now)
                   .Text(tenant)
                   .Text(*sweep_pid)
                   .Run(conn_,
                        "INSERT INTO sweeps (name, axes, created_ms, tenant, pid) "
                        "VALUES ($1, $2, $3, $4, $5) RETURNING seq"));
    if (!s.ok()) return (s.status());
    const int64_t sweep_seq = s.Int(0, 0);
    for (size_t i = 0; i < items.size(); ++i) {
      absl::StatusOr<std::string> item_pid = NewPublicId('j');
      if (!item_pid.ok()) return (item_pid.status());
      PgResult r(Params()
                     .Text(items[i].name())
                     .Bytes(items[i].SerializeAsString())
                     .Real(end_times_s[i])
                     .Int(now)
                     .Int(sweep_seq)
                     .Int(static_cast<int64_t>(i))
                     .Text(peer)
                     .Text(tenant)
                     .Text(*item_pid)
                     .Run(conn_,
                          "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, "
                          "sweep_seq, sweep_index, peer, tenant, pid) "
                          "VALUES (1, $1, $2, $3, $4, $5, $6, $7, $8, $9)"));
      if (!r.ok()) return (r.status());
    }
    Notify();
    if (absl::Status st = tx.Commit(); !st.ok()) return st;
  }
  return GetSweep(*sweep_pid);
}

absl::StatusOr<v1::Job> PostgresJobStore::GetJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Run(
      conn_, absl::StrCat("SELECT ", kJobColumns, " FROM jobs j WHERE j.pid = $1")));
  if (!r.ok()) return r.status();
  if (r.rows() == 0) return absl::NotFoundError(absl::StrCat("no job \"", id, "\""));
  if (r.Int(0, kJobIntactColumn) != 1) return DamagedRow("job", id);
  return JobFromRow(r, 0);
}

absl::StatusOr<v1::Scene> PostgresJobStore::GetScene(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Run(conn_, "SELECT scene FROM jobs WHERE pid = $1"));
  if (!r.ok()) return r.status();
  if (r.rows() == 0) return absl::NotFoundError(absl::StrCat("no job \"", id, "\""));
  v1::Scene scene;
  if (!scene.ParseFromString(r.Bytes(0, 0))) return absl::DataLossError("stored scene unreadable");
  return scene;
}

absl::StatusOr<std::vector<v1::Job>> PostgresJobStore::ListJobs(v1::JobState state,
                                                                const std::string& sweep_id,
                                                                int limit, int64_t after_key,
                                                                const std::string* tenant,
                                                                std::vector<int64_t>* keys) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  const int64_t before_seq = after_key > 0 ? after_key : std::numeric_limits<int64_t>::max();
  int64_t sweep_seq = 0;
  if (!sweep_id.empty()) {
    sweep_seq = -1;
    if (IsSweepId(sweep_id)) {
      PgResult r(Params().Text(sweep_id).Run(conn_, "SELECT seq FROM sweeps WHERE pid = $1"));
      if (!r.ok()) return r.status();
      if (r.rows() > 0) sweep_seq = r.Int(0, 0);
    }
  }
  PgResult r(Params()
                 .Int(state)
                 .Int(sweep_seq)
                 .Int(limit)
                 .Int(before_seq)
                 .Int(tenant != nullptr)
                 .Text(tenant != nullptr ? *tenant : std::string())
                 .Run(conn_, absl::StrCat(
                                 "SELECT ", kJobColumns,
                                 " FROM jobs j WHERE ($1::int = 0 OR j.state = $1::int) AND "
                                 "($2::bigint = 0 OR j.sweep_seq = $2::bigint) AND "
                                 "j.seq < $4::bigint AND ($5::int = 0 OR j.tenant = $6) "
                                 "ORDER BY j.seq DESC LIMIT $3::bigint")));
  if (!r.ok()) return r.status();
  std::vector<v1::Job> jobs;
  if (keys != nullptr) keys->clear();
  for (int i = 0; i < r.rows(); ++i) {
    // A damaged row: a placeholder (JobStore::ListJobs).
    jobs.push_back(r.Int(i, kJobIntactColumn) == 1 ? JobFromRow(r, i) : v1::Job());
    if (keys != nullptr) keys->push_back(r.Int(i, 0));
  }
  return jobs;
}

absl::StatusOr<std::string> PostgresJobStore::Tenant(const std::string& id) {
  const bool sweep = IsSweepId(id);
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Run(
      conn_, sweep ? "SELECT tenant, (s.row_sum IS NOT DISTINCT FROM cablesim_sweep_sum(s)) "
                     "FROM sweeps s WHERE pid = $1"
                   : "SELECT tenant, (j.row_sum IS NOT DISTINCT FROM cablesim_job_sum(j)) "
                     "FROM jobs j WHERE pid = $1"));
  if (!r.ok()) return r.status();
  if (r.rows() == 0) {
    return absl::NotFoundError(absl::StrCat("no ", sweep ? "sweep" : "job", " \"", id, "\""));
  }
  // A damaged row's tenant cannot be trusted: DataLoss for everyone.
  if (r.Int(0, 1) != 1) return DamagedRow(sweep ? "sweep" : "job", id);
  return r.Bytes(0, 0);
}

absl::StatusOr<std::vector<std::string>> PostgresJobStore::CheckRows() {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  std::vector<std::string> damaged;
  PgResult rows(Params().Run(
      conn_,
      "SELECT 'job', seq, pid FROM jobs j WHERE j.row_sum IS DISTINCT FROM cablesim_job_sum(j) "
      "UNION ALL SELECT 'sweep', seq, pid FROM sweeps s "
      "WHERE s.row_sum IS DISTINCT FROM cablesim_sweep_sum(s) ORDER BY 1, 2"));
  if (!rows.ok()) return rows.status();
  for (int i = 0; i < rows.rows(); ++i) {
    damaged.push_back(absl::StrCat(rows.Bytes(i, 0), " ", rows.Bytes(i, 2), " (row ",
                                   rows.Int(i, 1), "): the row fails its checksum"));
  }
  PgResult r(Params().Run(conn_,
                          "SELECT r.job_seq, COALESCE(j.pid, ''), r.header, r.vals, r.checksum, "
                          "r.encoding FROM results r LEFT JOIN jobs j ON j.seq = r.job_seq "
                          "ORDER BY r.job_seq"));
  if (!r.ok()) return r.status();
  for (int i = 0; i < r.rows(); ++i) {
    const std::string id = r.Bytes(i, 1);
    absl::StatusOr<StoredResult> result =
        CheckedResult(id, r.Bytes(i, 2), r.Bytes(i, 3), r.Int(i, 4), r.Int(i, 5));
    if (!result.ok()) {
      damaged.push_back(absl::StrCat("result of job ", id, " (row ", r.Int(i, 0),
                                     "): ", result.status().message()));
    }
  }
  return damaged;
}

absl::StatusOr<std::vector<std::string>> PostgresJobStore::QueuedJobIds() {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Run(conn_, NamedStates("SELECT pid FROM jobs WHERE state = {QUEUED} ORDER BY seq")));
  if (!r.ok()) return r.status();
  std::vector<std::string> ids;
  for (int i = 0; i < r.rows(); ++i) ids.push_back(r.Bytes(i, 0));
  return ids;
}

absl::StatusOr<std::optional<Claim>> PostgresJobStore::ClaimNext() {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  // A job no live claim holds, round-robin across tenants (JobStore::
  // ClaimNext); rows another server is claiming right now are skipped,
  // not waited for.
  PgResult r(Params().Text(owner_).Int(options_.lease_ms).Run(
      conn_,
      NamedStates(absl::StrCat("UPDATE jobs SET state = {RUNNING}, owner = $1, lease_until_ms = ", kNowMs,
                   " + $2::bigint, started_ms = ", kNowMs,
                   ", attempts = attempts + 1, cancel_requested = FALSE, progress_time_s = 0 "
                   "WHERE seq = (SELECT seq FROM jobs j WHERE state = {QUEUED} OR (state = {RUNNING} AND "
                   "lease_until_ms < ",
                   kNowMs, ") ORDER BY ", kFairShareOrder,
                   " LIMIT 1 FOR UPDATE SKIP LOCKED) "
                   "RETURNING pid, attempts"))));
  if (!r.ok()) return r.status();
  if (r.rows() == 0) return std::nullopt;
  Notify();
  return Claim{r.Bytes(0, 0), static_cast<int>(r.Int(0, 1))};
}

absl::StatusOr<bool> PostgresJobStore::MarkRunning(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(owner_).Int(options_.lease_ms).Text(id).Run(
      conn_, NamedStates(absl::StrCat("UPDATE jobs SET state = {RUNNING}, owner = $1, lease_until_ms = ", kNowMs,
                          " + $2::bigint, started_ms = ", kNowMs,
                          ", attempts = attempts + 1, cancel_requested = FALSE "
                          "WHERE pid = $3 AND state = {QUEUED} RETURNING seq"))));
  if (!r.ok()) return r.status();
  return r.rows() == 1;
}

absl::Status PostgresJobStore::Requeue(const std::string& id, int attempt) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Text(owner_).Int(attempt).Run(
      conn_,
      NamedStates("UPDATE jobs SET state = {QUEUED}, owner = '', lease_until_ms = 0 WHERE pid = $1 "
                  "AND state = {RUNNING} AND owner = $2 AND ($3::int = 0 OR attempts = $3::int)")));
  if (!r.ok()) return r.status();
  Notify();
  return absl::OkStatus();
}

absl::StatusOr<bool> PostgresJobStore::CancelQueued(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  // A job whose server died (lease expired) is as good as queued.
  PgResult r(Params().Text(id).Run(
      conn_, NamedStates(absl::StrCat("UPDATE jobs SET state = {CANCELLED}, finished_ms = ", kNowMs,
                          ", owner = '' WHERE pid = $1 AND (state = {QUEUED} OR (state = {RUNNING} AND "
                          "lease_until_ms < ",
                          kNowMs, ")) RETURNING seq"))));
  if (!r.ok()) return r.status();
  if (r.rows() == 1) Notify();
  return r.rows() == 1;
}

absl::Status PostgresJobStore::RequestCancel(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Run(
      conn_, NamedStates("UPDATE jobs SET cancel_requested = TRUE WHERE pid = $1 AND state = {RUNNING}")));
  if (!r.ok()) return r.status();
  Notify();
  return absl::OkStatus();
}

absl::StatusOr<HeartbeatReply> PostgresJobStore::Heartbeat(
    const std::vector<RunningJob>& running) {
  HeartbeatReply reply;
  if (running.empty()) return reply;
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  for (const RunningJob& job : running) {
    PgResult r(Params()
                   .Int(options_.lease_ms)
                   .Real(job.progress_time_s)
                   .Text(job.id)
                   .Text(owner_)
                   .Int(job.attempt)
                   .Run(conn_, NamedStates(absl::StrCat("UPDATE jobs SET lease_until_ms = ", kNowMs,
                                            " + $1::bigint, progress_time_s = $2::float8 "
                                            "WHERE pid = $3 AND state = {RUNNING} AND owner = $4 AND "
                                            "attempts = $5::int RETURNING cancel_requested"))));
    if (!r.ok()) return r.status();
    if (r.rows() == 0) {
      reply.lost.push_back(job.id);
    } else if (r.Int(0, 0) != 0) {
      reply.cancel.push_back(job.id);
    }
  }
  Notify();
  return reply;
}

absl::StatusOr<bool> PostgresJobStore::Finish(const std::string& id, v1::JobState state,
                                              const v1::RunSummary& summary,
                                              const StoredResult& result, int attempt) {
  const std::string header = result.header.SerializeAsString();
  const EncodedValues vals = EncodeValues(result.values, result.header.columns_size());
  const int64_t checksum =
      ResultChecksum(header.data(), header.size(), vals.blob.data(), vals.blob.size());
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  Transaction tx(conn_);
  if (!tx.begun().ok()) return tx.begun();
  PgResult u(Params()
                 .Int(state)
                 .Bytes(summary.SerializeAsString())
                 .Text(id)
                 .Text(owner_)
                 .Int(attempt)
                 .Run(conn_, NamedStates(absl::StrCat("UPDATE jobs SET state = $1::int, finished_ms = ",
                                          kNowMs,
                                          ", summary = $2, lease_until_ms = 0 WHERE pid = $3 AND "
                                          "state = {RUNNING} AND owner = $4 AND ($5::int = 0 OR "
                                          "attempts = $5::int) RETURNING seq"))));
  if (!u.ok()) return (u.status());
  if (u.rows() != 1) return false;
  PgResult r(Params()
                 .Int(u.Int(0, 0))
                 .Bytes(header)
                 .Bytes(vals.blob)
                 .Int(checksum)
                 .Int(vals.encoding)
                 .Run(conn_,
                      "INSERT INTO results (job_seq, header, vals, checksum, encoding) VALUES "
                      "($1::bigint, $2, $3, $4::bigint, $5::int) ON CONFLICT (job_seq) DO "
                      "UPDATE SET header = EXCLUDED.header, vals = EXCLUDED.vals, checksum = "
                      "EXCLUDED.checksum, encoding = EXCLUDED.encoding"));
  if (!r.ok()) return (r.status());
  Notify();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return true;
}

absl::StatusOr<StoredResult> PostgresJobStore::GetResult(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult r(Params().Text(id).Run(conn_,
                                   "SELECT r.header, r.vals, r.checksum, r.encoding FROM "
                                   "results r JOIN jobs "
                                   "j ON j.seq = r.job_seq WHERE j.pid = $1"));
  if (!r.ok()) return r.status();
  if (r.rows() == 0) return absl::NotFoundError(absl::StrCat("job \"", id, "\" has no result"));
  return CheckedResult(id, r.Bytes(0, 0), r.Bytes(0, 1), r.Int(0, 2), r.Int(0, 3));
}

absl::StatusOr<v1::Sweep> PostgresJobStore::GetSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  if (!IsSweepId(id)) return absl::NotFoundError(absl::StrCat("no sweep \"", id, "\""));
  PgResult s(Params().Text(id).Run(
      conn_,
      "SELECT name, axes, created_ms, seq, (w.row_sum IS NOT DISTINCT FROM cablesim_sweep_sum(w)) "
      "FROM sweeps w WHERE pid = $1"));
  if (!s.ok()) return s.status();
  if (s.rows() == 0) return absl::NotFoundError(absl::StrCat("no sweep \"", id, "\""));
  if (s.Int(0, 4) != 1) return DamagedRow("sweep", id);
  v1::Sweep sweep;
  sweep.ParseFromString(s.Bytes(0, 1));
  sweep.set_id(id);
  sweep.set_name(s.Bytes(0, 0));
  sweep.set_created_unix_ms(s.Int(0, 2));
  PgResult r(Params().Int(s.Int(0, 3)).Run(
      conn_,
      "SELECT pid, state, (j.row_sum IS NOT DISTINCT FROM cablesim_job_sum(j)) FROM jobs j "
      "WHERE sweep_seq = $1::bigint ORDER BY sweep_index"));
  if (!r.ok()) return r.status();
  int finished = 0, failed = 0;
  for (int i = 0; i < r.rows(); ++i) {
    // A damaged item: the sweep's ids and counts cannot be served whole.
    if (r.Int(i, 2) != 1) {
      return absl::DataLossError(absl::StrCat("sweep ", id, ": the stored row of item ", i,
                                              " fails its checksum (the database is damaged); "
                                              "cablesim-server --check lists it"));
    }
    sweep.add_job_ids(r.Bytes(i, 0));
    const auto state = static_cast<v1::JobState>(r.Int(i, 1));
    if (IsFinished(state)) ++finished;
    if (state == v1::FAILED || state == v1::CANCELLED) ++failed;
  }
  sweep.set_items(r.rows());
  sweep.set_finished(finished);
  sweep.set_failed(failed);
  return sweep;
}

namespace {
constexpr char kResultBytes[] = "octet_length(header) + octet_length(vals)";
}  // namespace

absl::StatusOr<int64_t> PostgresJobStore::DeleteJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  Transaction tx(conn_);
  if (!tx.begun().ok()) return tx.begun();
  PgResult s(Params().Text(IsSweepId(id) ? std::string() : id).Run(
      conn_, absl::StrCat("SELECT j.state, COALESCE(j.sweep_seq, 0), COALESCE((SELECT ",
                          kResultBytes,
                          " FROM results WHERE job_seq = j.seq), 0)::bigint, "
                          "COALESCE((SELECT pid FROM sweeps WHERE sweeps.seq = j.sweep_seq), ''), "
                          "j.seq FROM jobs j WHERE j.pid = $1 FOR UPDATE")));
  if (!s.ok()) return (s.status());
  if (s.rows() == 0) return (absl::NotFoundError(absl::StrCat("no job \"", id, "\"")));
  const auto state = static_cast<v1::JobState>(s.Int(0, 0));
  if (!IsFinished(state)) {
    return (absl::FailedPreconditionError(absl::StrCat(
        "job \"", id, "\" is ", v1::JobState_Name(state), "; cancel it before deleting it")));
  }
  if (s.Int(0, 1) > 0) {
    return (absl::FailedPreconditionError(
        absl::StrCat("job \"", id, "\" is an item of sweep \"", s.Bytes(0, 3),
                     "\"; delete the sweep (DeleteSweep) instead")));
  }
  PgResult d(Params().Int(s.Int(0, 4)).Run(conn_, "DELETE FROM jobs WHERE seq = $1::bigint"));
  if (!d.ok()) return (d.status());
  Notify();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return s.Int(0, 2);
}

absl::StatusOr<int64_t> PostgresJobStore::DeleteSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  Transaction tx(conn_);
  if (!tx.begun().ok()) return tx.begun();
  PgResult s(Params().Text(IsSweepId(id) ? id : std::string()).Run(
      conn_, "SELECT seq FROM sweeps WHERE pid = $1 FOR UPDATE"));
  if (!s.ok()) return (s.status());
  if (s.rows() == 0) return (absl::NotFoundError(absl::StrCat("no sweep \"", id, "\"")));
  const int64_t seq = s.Int(0, 0);
  PgResult c(Params().Int(seq).Run(
      conn_, absl::StrCat("SELECT COUNT(*) FILTER (WHERE state NOT IN ", kFinishedStates,
                          "), COALESCE(SUM((SELECT ", kResultBytes,
                          " FROM results WHERE job_seq = jobs.seq)), 0)::bigint FROM jobs "
                          "WHERE sweep_seq = $1::bigint")));
  if (!c.ok()) return (c.status());
  if (const int64_t unfinished = c.Int(0, 0); unfinished > 0) {
    return (absl::FailedPreconditionError(
        absl::StrCat("sweep \"", id, "\" has ", unfinished,
                     " unfinished items; cancel them before deleting it")));
  }
  PgResult d(Params().Int(seq).Run(conn_,
                                   "DELETE FROM jobs WHERE sweep_seq = $1::bigint"));
  if (!d.ok()) return (d.status());
  PgResult e(Params().Int(seq).Run(conn_, "DELETE FROM sweeps WHERE seq = $1::bigint"));
  if (!e.ok()) return (e.status());
  Notify();
  if (absl::Status st = tx.Commit(); !st.ok()) return st;
  return c.Int(0, 1);
}

absl::StatusOr<RetentionReport> PostgresJobStore::ApplyRetention(int64_t older_than_unix_ms,
                                                                 int64_t max_bytes) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  PgResult t(Params().Run(
      conn_, absl::StrCat("SELECT COALESCE(SUM(", kResultBytes, "), 0)::bigint FROM results")));
  if (!t.ok()) return t.status();
  int64_t total = t.Int(0, 0);
  PgResult c(Params().Run(
      conn_,
      absl::StrCat("SELECT 0, seq, finished_ms, COALESCE((SELECT ", kResultBytes,
                   " FROM results WHERE job_seq = jobs.seq), 0)::bigint FROM jobs "
                   "WHERE sweep_seq IS NULL AND state IN ",
                   kFinishedStates,
                   " UNION ALL "
                   "SELECT 1, sweep_seq, MAX(finished_ms), COALESCE(SUM((SELECT ",
                   kResultBytes,
                   " FROM results WHERE job_seq = jobs.seq)), 0)::bigint FROM jobs "
                   "WHERE sweep_seq IS NOT NULL GROUP BY sweep_seq "
                   "HAVING COUNT(*) FILTER (WHERE state NOT IN ",
                   kFinishedStates, ") = 0 ORDER BY 3")));
  if (!c.ok()) return c.status();
  RetentionReport report;
  for (int i = 0; i < c.rows(); ++i) {
    const bool sweep = c.Int(i, 0) != 0;
    const int64_t seq = c.Int(i, 1), finished_ms = c.Int(i, 2), bytes = c.Int(i, 3);
    if (finished_ms >= older_than_unix_ms && total <= max_bytes) break;
    Transaction tx(conn_);
    if (!tx.begun().ok()) return tx.begun();
    // Another server may have deleted it meanwhile: count what goes here.
    PgResult d(Params().Int(seq).Run(
        conn_, sweep ? "DELETE FROM jobs WHERE sweep_seq = $1::bigint"
                     : absl::StrCat("DELETE FROM jobs WHERE seq = $1::bigint AND sweep_seq IS "
                                    "NULL AND state IN ",
                                    kFinishedStates)));
    absl::Status st = d.status();
    if (st.ok() && sweep) {
      PgResult e(Params().Int(seq).Run(conn_, "DELETE FROM sweeps WHERE seq = $1::bigint"));
      st = e.status();
    }
    if (st.ok()) st = tx.Commit();
    if (!st.ok()) return st;
    total -= bytes;
    report.jobs += d.changed();
    report.sweeps += sweep ? 1 : 0;
    report.bytes += bytes;
  }
  if (report.jobs > 0) Notify();
  return report;
}

}  // namespace cablesim
