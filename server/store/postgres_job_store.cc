#include "server/store/postgres_job_store.h"

#include <endian.h>
#include <libpq-fe.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <utility>
#include <variant>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_format.h"
#include "absl/time/clock.h"
#include "server/result_codec.h"

namespace cablesim {
namespace {

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
    {6, "job states by name: queries bind a state's name, stored rows keep its number", R"sql(
-- The contract's JobState (service.proto): a state's name to the number
-- jobs.state stores. Immutable, so that a query's bound name folds to a
-- constant when it is planned (indexes on state still serve).
CREATE FUNCTION cablesim_state(name TEXT) RETURNS INTEGER LANGUAGE SQL IMMUTABLE AS $$
  SELECT CASE name WHEN 'JOB_STATE_UNSPECIFIED' THEN 0 WHEN 'QUEUED' THEN 1 WHEN 'RUNNING' THEN 2
    WHEN 'SUCCEEDED' THEN 3 WHEN 'FAILED' THEN 4 WHEN 'CANCELLED' THEN 5 END $$;
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
    return PgResult(Exec(conn, sql), conn);
  }
  PGresult* Exec(PGconn* conn, const std::string& sql) const {
    std::vector<const char*> values;
    std::vector<int> lengths;
    for (const std::string& v : values_) {
      values.push_back(v.data());
      lengths.push_back(static_cast<int>(v.size()));
    }
    return PQexecParams(conn, sql.c_str(), static_cast<int>(values_.size()), nullptr,
                        values.data(), lengths.data(), formats_.data(), /*resultFormat=*/1);
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
// The URL without its password, for logs.
std::string DescribeConnection(PGconn* conn) {
  return absl::StrCat("postgresql://", PQuser(conn), "@", PQhost(conn), ":", PQport(conn), "/",
                      PQdb(conn));
}

// A state bound by name (SqlState), as the number the jobs table stores.
#define CABLESIM_STATE(param) "cablesim_state(@" param ")"
constexpr char kFinishedStates[] =
    "(" CABLESIM_STATE("succeeded") ", " CABLESIM_STATE("failed") ", " CABLESIM_STATE(
        "cancelled") ")";
constexpr char kResultBytes[] = "octet_length(header) + octet_length(vals)";

// PostgreSQL's statements (SqlStatements): states are bound by name and
// mapped by cablesim_state (migration 6); leases and claim times are the
// database's clock; a claim skips the rows another server is claiming.
const SqlStatements& Statements() {
  static const SqlStatements* sql = new SqlStatements{
      .begin = "BEGIN",
      .requeue_running = absl::StrCat(
          "UPDATE jobs SET state = ", CABLESIM_STATE("queued"), ", owner = '' WHERE state = ",
          CABLESIM_STATE("running"), " AND lease_until_ms < ", kNowMs),
      // One peer's submissions one at a time, across servers, until commit.
      .peer_lock = "SELECT pg_advisory_xact_lock(hashtext(@peer))",
      .peer_unfinished = "SELECT COUNT(*) FROM jobs WHERE peer = @peer AND state IN (" CABLESIM_STATE(
          "queued") ", " CABLESIM_STATE("running") ")",
      .insert_job = "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, peer, tenant, "
                    "pid) VALUES (" CABLESIM_STATE("queued") ", @name, @scene, @end_time_s, "
                    "@now_ms, @peer, @tenant, @id)",
      .insert_sweep = "INSERT INTO sweeps (name, axes, created_ms, tenant, pid) VALUES (@name, "
                      "@axes, @created_ms, @tenant, @id) RETURNING seq",
      .insert_item = "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, sweep_seq, "
                     "sweep_index, peer, tenant, pid) VALUES (" CABLESIM_STATE("queued") ", "
                     "@name, @scene, @end_time_s, @created_ms, @sweep_seq, @sweep_index, @peer, "
                     "@tenant, @id)",
      .job_by_id = absl::StrCat("SELECT ", kJobColumns, " FROM jobs j WHERE j.pid = @id"),
      .scene_by_id = "SELECT scene FROM jobs WHERE pid = @id",
      .sweep_seq_by_id = "SELECT seq FROM sweeps WHERE pid = @id",
      .list_jobs = absl::StrCat(
          "SELECT ", kJobColumns,
          " FROM jobs j WHERE (@any_state::int = 1 OR j.state = ", CABLESIM_STATE("state"),
          ") AND (@sweep_seq::bigint = 0 OR j.sweep_seq = @sweep_seq::bigint) AND j.seq < "
          "@before_seq::bigint AND (@any_tenant::int = 1 OR j.tenant = @tenant) ORDER BY j.seq "
          "DESC LIMIT @limit::bigint"),
      .tenant_of_job = "SELECT tenant, (j.row_sum IS NOT DISTINCT FROM cablesim_job_sum(j)) "
                       "FROM jobs j WHERE pid = @id",
      .tenant_of_sweep = "SELECT tenant, (s.row_sum IS NOT DISTINCT FROM cablesim_sweep_sum(s)) "
                         "FROM sweeps s WHERE pid = @id",
      .damaged_rows =
          "SELECT 'job', seq, pid FROM jobs j WHERE j.row_sum IS DISTINCT FROM "
          "cablesim_job_sum(j) UNION ALL SELECT 'sweep', seq, pid FROM sweeps s WHERE s.row_sum "
          "IS DISTINCT FROM cablesim_sweep_sum(s) ORDER BY 1, 2",
      .all_results = "SELECT r.job_seq, COALESCE(j.pid, ''), r.header, r.vals, r.checksum, "
                     "r.encoding FROM results r LEFT JOIN jobs j ON j.seq = r.job_seq ORDER BY "
                     "r.job_seq",
      .queued_ids =
          "SELECT pid FROM jobs WHERE state = " CABLESIM_STATE("queued") " ORDER BY seq",
      // A job no live claim holds, round-robin across tenants
      // (JobStore::ClaimNext); rows another server is claiming right now
      // are skipped, not waited for.
      .claim_next = absl::StrCat(
          "UPDATE jobs SET state = ", CABLESIM_STATE("running"),
          ", owner = @owner, lease_until_ms = ", kNowMs, " + @lease_ms::bigint, started_ms = ",
          kNowMs,
          ", attempts = attempts + 1, cancel_requested = FALSE, progress_time_s = 0 WHERE seq = "
          "(SELECT seq FROM jobs j WHERE state = ",
          CABLESIM_STATE("queued"), " OR (state = ", CABLESIM_STATE("running"),
          " AND lease_until_ms < ", kNowMs, ") ORDER BY ", kFairShareOrder,
          " LIMIT 1 FOR UPDATE SKIP LOCKED) RETURNING pid, attempts"),
      .mark_running = absl::StrCat(
          "UPDATE jobs SET state = ", CABLESIM_STATE("running"),
          ", owner = @owner, lease_until_ms = ", kNowMs, " + @lease_ms::bigint, started_ms = ",
          kNowMs, ", attempts = attempts + 1, cancel_requested = FALSE WHERE pid = @id AND state = ",
          CABLESIM_STATE("queued"), " RETURNING seq"),
      .requeue = "UPDATE jobs SET state = " CABLESIM_STATE("queued") ", owner = '', "
                 "lease_until_ms = 0 WHERE pid = @id AND state = " CABLESIM_STATE("running") " "
                 "AND owner = @owner AND (@attempt::int = 0 OR attempts = @attempt::int)",
      // A job whose server died (lease expired) is as good as queued.
      .cancel_queued = absl::StrCat(
          "UPDATE jobs SET state = ", CABLESIM_STATE("cancelled"), ", finished_ms = ", kNowMs,
          ", owner = '' WHERE pid = @id AND (state = ", CABLESIM_STATE("queued"),
          " OR (state = ", CABLESIM_STATE("running"), " AND lease_until_ms < ", kNowMs,
          ")) RETURNING seq"),
      .finish = absl::StrCat(
          "UPDATE jobs SET state = ", CABLESIM_STATE("state"), ", finished_ms = ", kNowMs,
          ", summary = @summary, lease_until_ms = 0 WHERE pid = @id AND state = ",
          CABLESIM_STATE("running"),
          " AND owner = @owner AND (@attempt::int = 0 OR attempts = @attempt::int) RETURNING seq"),
      .store_result =
          "INSERT INTO results (job_seq, header, vals, checksum, encoding) VALUES "
          "(@seq::bigint, @header, @vals, @checksum::bigint, @encoding::int) ON CONFLICT "
          "(job_seq) DO UPDATE SET header = EXCLUDED.header, vals = EXCLUDED.vals, checksum = "
          "EXCLUDED.checksum, encoding = EXCLUDED.encoding",
      .result_by_id = "SELECT r.header, r.vals, r.checksum, r.encoding FROM results r JOIN jobs j "
                      "ON j.seq = r.job_seq WHERE j.pid = @id",
      .sweep_by_id = "SELECT name, axes, created_ms, seq, (w.row_sum IS NOT DISTINCT FROM "
                     "cablesim_sweep_sum(w)) FROM sweeps w WHERE pid = @id",
      .sweep_items = "SELECT pid, state, (j.row_sum IS NOT DISTINCT FROM cablesim_job_sum(j)) "
                     "FROM jobs j WHERE sweep_seq = @seq::bigint ORDER BY sweep_index",
      .job_for_delete = absl::StrCat(
          "SELECT j.state, COALESCE(j.sweep_seq, 0), COALESCE((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = j.seq), 0)::bigint, COALESCE((SELECT pid FROM sweeps "
          "WHERE sweeps.seq = j.sweep_seq), ''), j.seq FROM jobs j WHERE j.pid = @id FOR UPDATE"),
      .sweep_for_delete = "SELECT seq FROM sweeps WHERE pid = @id FOR UPDATE",
      .sweep_unfinished = absl::StrCat(
          "SELECT COUNT(*) FILTER (WHERE state NOT IN ", kFinishedStates,
          "), COALESCE(SUM((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq)), 0)::bigint FROM jobs WHERE sweep_seq = "
          "@seq::bigint"),
      // Retention: another server may have deleted the job meanwhile, or
      // (not finished) may not let it go.
      .delete_job_results = absl::StrCat(
          "DELETE FROM results WHERE job_seq IN (SELECT seq FROM jobs WHERE seq = @seq::bigint "
          "AND sweep_seq IS NULL AND state IN ", kFinishedStates, ")"),
      .delete_job = absl::StrCat(
          "DELETE FROM jobs WHERE seq = @seq::bigint AND sweep_seq IS NULL AND state IN ",
          kFinishedStates),
      .delete_sweep_results = "DELETE FROM results WHERE job_seq IN (SELECT seq FROM jobs WHERE "
                              "sweep_seq = @seq::bigint)",
      .delete_sweep_jobs = "DELETE FROM jobs WHERE sweep_seq = @seq::bigint",
      .delete_sweep = "DELETE FROM sweeps WHERE seq = @seq::bigint",
      .results_bytes =
          absl::StrCat("SELECT COALESCE(SUM(", kResultBytes, "), 0)::bigint FROM results"),
      .retention_candidates = absl::StrCat(
          "SELECT 0, seq, finished_ms, COALESCE((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq), 0)::bigint FROM jobs WHERE sweep_seq IS "
          "NULL AND state IN ",
          kFinishedStates,
          " UNION ALL SELECT 1, sweep_seq, MAX(finished_ms), COALESCE(SUM((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq)), 0)::bigint FROM jobs WHERE sweep_seq IS NOT "
          "NULL GROUP BY sweep_seq HAVING COUNT(*) FILTER (WHERE state NOT IN ",
          kFinishedStates, ") = 0 ORDER BY 3"),
  };
  return *sql;
}

// A PgResult read through SqlRows.
class PgRows final : public SqlRows {
 public:
  PgRows(PGresult* r, PGconn* conn) : r_(r, conn) {}
  const PgResult& result() const { return r_; }
  int size() const override { return r_.rows(); }
  int64_t Int(int row, int col) const override { return r_.Int(row, col); }
  double Real(int row, int col) const override { return r_.Real(row, col); }
  std::string Bytes(int row, int col) const override { return r_.Bytes(row, col); }
  int64_t changed() const override { return r_.changed(); }

 private:
  PgResult r_;
};

}  // namespace

int PostgresJobStore::LatestSchemaVersion() {
  return kMigrations[sizeof(kMigrations) / sizeof(kMigrations[0]) - 1].version;
}

PostgresJobStore::PostgresJobStore(PGconn* conn, std::string url, const StoreOptions& options)
    : SqlJobStore(Statements()), url_(std::move(url)), options_(options), conn_(conn) {
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

absl::StatusOr<std::unique_ptr<SqlRows>> PostgresJobStore::Run(const std::string& sql,
                                                               const SqlParams& params) {
  // `@name` becomes `$n`, the n-th parameter this statement names.
  std::string text;
  std::vector<const SqlValue*> bound;
  std::vector<std::string> names;
  for (size_t i = 0; i < sql.size();) {
    if (sql[i] != '@') {
      text.push_back(sql[i++]);
      continue;
    }
    size_t end = i + 1;
    while (end < sql.size() && (std::isalnum(static_cast<unsigned char>(sql[end])) || sql[end] == '_')) {
      ++end;
    }
    const std::string name = sql.substr(i + 1, end - i - 1);
    size_t n = std::find(names.begin(), names.end(), name) - names.begin();
    if (n == names.size()) {
      const auto it = std::find_if(params.begin(), params.end(),
                                   [&](const auto& p) { return name == p.first; });
      if (it == params.end()) {
        return absl::InternalError(absl::StrCat("postgresql: no value for @", name));
      }
      names.push_back(name);
      bound.push_back(&it->second);
    }
    absl::StrAppend(&text, "$", n + 1);
    i = end;
  }
  // Numbers and text as text, bytes as binary, states by name.
  Params values;
  for (const SqlValue* v : bound) {
    if (const auto* x = std::get_if<int64_t>(v)) {
      values.Int(*x);
    } else if (const auto* x = std::get_if<double>(v)) {
      values.Real(*x);
    } else if (const auto* x = std::get_if<std::string>(v)) {
      values.Text(*x);
    } else if (const auto* x = std::get_if<SqlBytes>(v)) {
      values.Bytes(x->data);
    } else {
      values.Text(v1::JobState_Name(std::get<SqlState>(*v).state));
    }
  }
  auto rows = std::make_unique<PgRows>(values.Exec(conn_, text), conn_);
  if (!rows->result().ok()) return rows->result().status();
  return rows;
}

absl::Status PostgresJobStore::RequestCancel(const std::string& id) {
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  absl::StatusOr<std::unique_ptr<SqlRows>> r =
      Query("UPDATE jobs SET cancel_requested = TRUE WHERE pid = @id AND state = " CABLESIM_STATE(
                "running"),
            {{"id", id}});
  if (!r.ok()) return r.status();
  Notify();
  return absl::OkStatus();
}

absl::StatusOr<HeartbeatReply> PostgresJobStore::Heartbeat(
    const std::vector<RunningJob>& running) {
  HeartbeatReply reply;
  if (running.empty()) return reply;
  static const std::string* const kRenew = new std::string(absl::StrCat(
      "UPDATE jobs SET lease_until_ms = ", kNowMs,
      " + @lease_ms::bigint, progress_time_s = @progress::float8 WHERE pid = @id AND state = ",
      CABLESIM_STATE("running"),
      " AND owner = @owner AND attempts = @attempt::int RETURNING cancel_requested"));
  absl::MutexLock lock(&mu_);
  EnsureConnected();
  for (const RunningJob& job : running) {
    absl::StatusOr<std::unique_ptr<SqlRows>> r =
        Query(*kRenew, {{"progress", job.progress_time_s},
                        {"id", job.id},
                        {"attempt", int64_t{job.attempt}}});
    if (!r.ok()) return r.status();
    if ((*r)->size() == 0) {
      reply.lost.push_back(job.id);
    } else if ((*r)->Int(0, 0) != 0) {
      reply.cancel.push_back(job.id);
    }
  }
  Notify();
  return reply;
}

}  // namespace cablesim
