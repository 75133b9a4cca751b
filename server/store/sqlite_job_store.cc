#include "server/store/sqlite_job_store.h"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <utility>
#include <variant>
#include <vector>

#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "server/result_codec.h"

namespace cablesim {
namespace {

constexpr char kSchema[] = R"sql(
CREATE TABLE IF NOT EXISTS sweeps (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  pid TEXT,                     -- the public id, `s-` and 128 random bits
  name TEXT NOT NULL,
  axes BLOB NOT NULL,           -- cablesim.v1.Sweep with only the axes
  created_ms INTEGER NOT NULL,
  tenant TEXT NOT NULL DEFAULT '');  -- the token's tenant that made it
CREATE TABLE IF NOT EXISTS jobs (
  seq INTEGER PRIMARY KEY AUTOINCREMENT,
  pid TEXT,                     -- the public id, `j-` and 128 random bits
  state INTEGER NOT NULL,       -- cablesim.v1.JobState
  name TEXT NOT NULL,
  scene BLOB NOT NULL,          -- cablesim.v1.Scene
  end_time_s REAL NOT NULL,
  created_ms INTEGER NOT NULL,
  started_ms INTEGER NOT NULL DEFAULT 0,
  finished_ms INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0,
  summary BLOB,                 -- cablesim.v1.RunSummary once finished
  sweep_seq INTEGER NOT NULL DEFAULT 0,
  sweep_index INTEGER NOT NULL DEFAULT 0,
  peer TEXT NOT NULL DEFAULT '',   -- the client address that submitted it
  tenant TEXT NOT NULL DEFAULT '');  -- the token's tenant that made it
CREATE INDEX IF NOT EXISTS jobs_by_state ON jobs(state, seq);
CREATE INDEX IF NOT EXISTS jobs_by_sweep ON jobs(sweep_seq, sweep_index);
CREATE TABLE IF NOT EXISTS results (
  job_seq INTEGER PRIMARY KEY REFERENCES jobs(seq),
  header BLOB NOT NULL,         -- cablesim.v1.RunHeader
  vals BLOB NOT NULL,           -- the values as `encoding` says (result_codec.h)
  checksum INTEGER,             -- ResultChecksum(header, vals)
  encoding INTEGER NOT NULL DEFAULT 0);  -- 0: raw row-major doubles, 1: zstd
CREATE TABLE IF NOT EXISTS meta (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL);         -- 'store_id': as in DIR/store-id
)sql";

constexpr char kStoreIdFile[] = "store-id";
// PRAGMA auto_vacuum's value for INCREMENTAL.
constexpr int64_t kIncrementalVacuum = 2;
// ReclaimSpace's step: free pages given back per call (16 MiB of 4 KiB
// pages), so that other calls wait at most for one step.
constexpr int kReclaimPages = 4096;



std::string ReadSmallFile(const std::string& path) {
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  return text;
}

// Writes `text` to `path` (0600) through a temporary file, synced.
absl::Status WriteFileDurably(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return absl::UnavailableError(absl::StrCat(tmp, ": ", std::strerror(errno)));
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) &&
                       ::fsync(fd) == 0;
  ::close(fd);
  if (!written || std::rename(tmp.c_str(), path.c_str()) != 0) {
    return absl::UnavailableError(absl::StrCat(path, ": ", std::strerror(errno)));
  }
  return absl::OkStatus();
}

// One prepared statement; finalized on destruction.
class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) : db_(db) {
    rc_ = sqlite3_prepare_v2(db, sql, -1, &stmt_, nullptr);
  }
  ~Stmt() { sqlite3_finalize(stmt_); }
  absl::Status status() const {
    return rc_ == SQLITE_OK ? absl::OkStatus()
                            : absl::InternalError(absl::StrCat("sqlite: ", sqlite3_errmsg(db_)));
  }
  Stmt& Bind(int i, int64_t v) {
    sqlite3_bind_int64(stmt_, i, v);
    return *this;
  }
  Stmt& Bind(int i, double v) {
    sqlite3_bind_double(stmt_, i, v);
    return *this;
  }
  Stmt& Bind(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  // An empty blob (never NULL, even when `data` is null).
  Stmt& BindBlob(int i, const void* data, size_t bytes) {
    static const char kEmpty = 0;
    sqlite3_bind_blob64(stmt_, i, data != nullptr ? data : &kEmpty, bytes, SQLITE_TRANSIENT);
    return *this;
  }
  // SQLITE_ROW, SQLITE_DONE or an error code.
  int Step() { return stmt_ ? sqlite3_step(stmt_) : rc_; }
  absl::Status Done() {
    const int rc = Step();
    if (rc == SQLITE_DONE || rc == SQLITE_ROW) return absl::OkStatus();
    return absl::InternalError(absl::StrCat("sqlite: ", sqlite3_errmsg(db_)));
  }
  int64_t Int(int c) { return sqlite3_column_int64(stmt_, c); }
  double Real(int c) { return sqlite3_column_double(stmt_, c); }
  std::string Text(int c) {
    const auto* p = sqlite3_column_text(stmt_, c);
    return p ? std::string(reinterpret_cast<const char*>(p), sqlite3_column_bytes(stmt_, c)) : "";
  }
  std::string Blob(int c) {
    const void* p = sqlite3_column_blob(stmt_, c);
    return p ? std::string(static_cast<const char*>(p), sqlite3_column_bytes(stmt_, c)) : "";
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  int rc_;
};

absl::Status SqlError(sqlite3* db) {
  return absl::InternalError(absl::StrCat("sqlite: ", sqlite3_errmsg(db)));
}

// Row checksums (JobStore::CheckRows): the SQL function cablesim_row_sum,
// CRC-32 over its arguments (each as its type, its length and its bytes),
// over these columns of every job and sweep row; triggers keep the column
// row_sum up to date on every insert and update of them, and every read
// that serves a row recomputes it (kJobIntact, kSweepIntact).
constexpr char kJobSumColumns[] =
    "seq, pid, state, name, end_time_s, created_ms, started_ms, finished_ms, attempts, "
    "summary, sweep_seq, sweep_index, peer, tenant";
constexpr char kSweepSumColumns[] = "seq, pid, name, axes, created_ms, tenant";

// `columns` ("a, b") with each prefixed ("NEW.a, NEW.b").
std::string Prefixed(absl::string_view prefix, absl::string_view columns) {
  std::string out;
  for (absl::string_view c : absl::StrSplit(columns, ", ")) {
    absl::StrAppend(&out, out.empty() ? "" : ", ", prefix, c);
  }
  return out;
}

void RowSumFunction(sqlite3_context* context, int argc, sqlite3_value** argv) {
  uLong crc = crc32(0L, Z_NULL, 0);
  auto add = [&](const void* data, size_t n) {
    crc = crc32(crc, static_cast<const Bytef*>(data), static_cast<uInt>(n));
  };
  for (int i = 0; i < argc; ++i) {
    const unsigned char type = static_cast<unsigned char>(sqlite3_value_type(argv[i]));
    add(&type, 1);
    if (type == SQLITE_INTEGER) {
      const int64_t v = sqlite3_value_int64(argv[i]);
      add(&v, sizeof v);
    } else if (type == SQLITE_FLOAT) {
      const double v = sqlite3_value_double(argv[i]);
      add(&v, sizeof v);
    } else if (type == SQLITE_TEXT || type == SQLITE_BLOB) {
      const void* data = type == SQLITE_TEXT
                             ? static_cast<const void*>(sqlite3_value_text(argv[i]))
                             : sqlite3_value_blob(argv[i]);
      const int64_t n = sqlite3_value_bytes(argv[i]);
      add(&n, sizeof n);
      if (n > 0) add(data, static_cast<size_t>(n));
    }
  }
  sqlite3_result_int64(context, static_cast<int64_t>(crc));
}

// 1 when the row's stored checksum matches its columns (FROM sweeps, or
// FROM jobs; a job of a sweep also needs its sweep's row intact, whose
// id it is served with).
const std::string& SweepIntact() {
  static const std::string* sql =
      new std::string(absl::StrCat("(sweeps.row_sum IS cablesim_row_sum(",
                                   Prefixed("sweeps.", kSweepSumColumns), "))"));
  return *sql;
}
const std::string& JobIntact() {
  static const std::string* sql = new std::string(absl::StrCat(
      "(jobs.row_sum IS cablesim_row_sum(", Prefixed("jobs.", kJobSumColumns),
      ") AND (jobs.sweep_seq = 0 OR (SELECT ", SweepIntact(),
      " FROM sweeps WHERE sweeps.seq = jobs.sweep_seq) IS 1))"));
  return *sql;
}

// The triggers that keep row_sum; an update of a row that was already
// damaged leaves its checksum as it was (the damage stays visible).
std::string RowSumTriggers(absl::string_view table, absl::string_view columns) {
  const std::string fresh = absl::StrCat("UPDATE ", table, " SET row_sum = cablesim_row_sum(",
                                         Prefixed("NEW.", columns), ") WHERE seq = NEW.seq; END;");
  return absl::StrCat(
      "CREATE TRIGGER IF NOT EXISTS ", table, "_row_sum_insert AFTER INSERT ON ", table,
      " BEGIN ", fresh, " CREATE TRIGGER IF NOT EXISTS ", table, "_row_sum_update AFTER UPDATE OF ",
      columns, " ON ", table, " WHEN OLD.row_sum IS cablesim_row_sum(", Prefixed("OLD.", columns),
      ") BEGIN ", fresh);
}

// The columns SqlStatements lists for a job row: progress is not stored
// (one server runs its jobs and knows their progress), read as 0.
const std::string& JobColumns() {
  static const std::string* sql = new std::string(absl::StrCat(
      "seq, state, name, created_ms, started_ms, finished_ms, attempts, end_time_s, summary, "
      "sweep_seq, sweep_index, "
      "(SELECT length(header) + length(vals) FROM results WHERE job_seq = jobs.seq), pid, "
      "(SELECT pid FROM sweeps WHERE sweeps.seq = jobs.sweep_seq), 0.0, ",
      JobIntact()));
  return *sql;
}

constexpr char kResultBytes[] = "length(header) + length(vals)";
constexpr char kFinishedStates[] = "(@succeeded, @failed, @cancelled)";

// SQLite's statements (SqlStatements): states are bound as the numbers
// the jobs table stores; the time is this server's clock (@now_ms). One
// connection and one server (the flock): a single UPDATE claims.
const SqlStatements& Statements() {
  static const SqlStatements* sql = new SqlStatements{
      .begin = "BEGIN IMMEDIATE",
      .requeue_running = "UPDATE jobs SET state = @queued WHERE state = @running",
      .peer_lock = "",
      .peer_unfinished =
          "SELECT COUNT(*) FROM jobs WHERE peer = @peer AND state IN (@queued, @running)",
      .insert_job = "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, peer, tenant, "
                    "pid) VALUES (@queued, @name, @scene, @end_time_s, @now_ms, @peer, @tenant, "
                    "@id)",
      .insert_sweep = "INSERT INTO sweeps (name, axes, created_ms, tenant, pid) VALUES (@name, "
                      "@axes, @created_ms, @tenant, @id) RETURNING seq",
      .insert_item = "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, sweep_seq, "
                     "sweep_index, peer, tenant, pid) VALUES (@queued, @name, @scene, "
                     "@end_time_s, @created_ms, @sweep_seq, @sweep_index, @peer, @tenant, @id)",
      .job_by_id = absl::StrCat("SELECT ", JobColumns(), " FROM jobs WHERE pid = @id"),
      .scene_by_id = "SELECT scene FROM jobs WHERE pid = @id",
      .sweep_seq_by_id = "SELECT seq FROM sweeps WHERE pid = @id",
      .list_jobs = absl::StrCat(
          "SELECT ", JobColumns(),
          " FROM jobs WHERE (@any_state = 1 OR state = @state) AND (@sweep_seq = 0 OR "
          "sweep_seq = @sweep_seq) AND seq < @before_seq AND (@any_tenant = 1 OR tenant = "
          "@tenant) ORDER BY seq DESC LIMIT @limit"),
      .tenant_of_job = absl::StrCat("SELECT tenant, ", JobIntact(), " FROM jobs WHERE pid = @id"),
      .tenant_of_sweep =
          absl::StrCat("SELECT tenant, ", SweepIntact(), " FROM sweeps WHERE pid = @id"),
      .damaged_rows = absl::StrCat("SELECT 'job', seq, pid FROM jobs WHERE NOT ", JobIntact(),
                                   " UNION ALL SELECT 'sweep', seq, pid FROM sweeps WHERE NOT ",
                                   SweepIntact(), " ORDER BY 1, 2"),
      .all_results = "SELECT job_seq, (SELECT pid FROM jobs WHERE seq = job_seq), header, vals, "
                     "checksum, encoding FROM results ORDER BY job_seq",
      .queued_ids = "SELECT pid FROM jobs WHERE state = @queued ORDER BY seq",
      .claim_next = absl::StrCat(
          "UPDATE jobs SET state = @running, started_ms = @now_ms, attempts = attempts + 1 "
          "WHERE seq = (SELECT seq FROM jobs j WHERE state = @queued ORDER BY ",
          kFairShareOrder, " LIMIT 1) AND state = @queued RETURNING pid, attempts"),
      .mark_running = "UPDATE jobs SET state = @running, started_ms = @now_ms, attempts = "
                      "attempts + 1 WHERE pid = @id AND state = @queued RETURNING seq",
      .requeue = "UPDATE jobs SET state = @queued WHERE pid = @id AND state = @running AND "
                 "(@attempt = 0 OR attempts = @attempt)",
      .cancel_queued = "UPDATE jobs SET state = @cancelled, finished_ms = @now_ms WHERE pid = @id "
                       "AND state = @queued RETURNING seq",
      .finish = "UPDATE jobs SET state = @state, finished_ms = @now_ms, summary = @summary WHERE "
                "pid = @id AND state = @running AND (@attempt = 0 OR attempts = @attempt) "
                "RETURNING seq",
      .store_result = "INSERT OR REPLACE INTO results (job_seq, header, vals, checksum, encoding) "
                      "VALUES (@seq, @header, @vals, @checksum, @encoding)",
      .result_by_id = "SELECT header, vals, checksum, encoding FROM results WHERE job_seq = "
                      "(SELECT seq FROM jobs WHERE pid = @id)",
      .sweep_by_id = absl::StrCat("SELECT name, axes, created_ms, seq, ", SweepIntact(),
                                  " FROM sweeps WHERE pid = @id"),
      .sweep_items = absl::StrCat("SELECT pid, state, ", JobIntact(),
                                  " FROM jobs WHERE sweep_seq = @seq ORDER BY sweep_index"),
      .job_for_delete = absl::StrCat(
          "SELECT state, sweep_seq, (SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq), (SELECT pid FROM sweeps WHERE sweeps.seq = "
          "jobs.sweep_seq), seq FROM jobs WHERE pid = @id"),
      .sweep_for_delete = "SELECT seq FROM sweeps WHERE pid = @id",
      .sweep_unfinished = absl::StrCat(
          "SELECT COALESCE(SUM(state NOT IN ", kFinishedStates, "), 0), COALESCE(SUM((SELECT ",
          kResultBytes, " FROM results WHERE job_seq = jobs.seq)), 0) FROM jobs WHERE "
          "sweep_seq = @seq"),
      .delete_job_results = absl::StrCat(
          "DELETE FROM results WHERE job_seq IN (SELECT seq FROM jobs WHERE seq = @seq AND "
          "sweep_seq = 0 AND state IN ", kFinishedStates, ")"),
      .delete_job = absl::StrCat("DELETE FROM jobs WHERE seq = @seq AND sweep_seq = 0 AND state IN ",
                                 kFinishedStates),
      .delete_sweep_results =
          "DELETE FROM results WHERE job_seq IN (SELECT seq FROM jobs WHERE sweep_seq = @seq)",
      .delete_sweep_jobs = "DELETE FROM jobs WHERE sweep_seq = @seq",
      .delete_sweep = "DELETE FROM sweeps WHERE seq = @seq",
      .results_bytes = absl::StrCat("SELECT COALESCE(SUM(", kResultBytes, "), 0) FROM results"),
      .retention_candidates = absl::StrCat(
          "SELECT 0, seq, finished_ms, COALESCE((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq), 0) FROM jobs WHERE sweep_seq = 0 AND state "
          "IN ", kFinishedStates,
          " UNION ALL SELECT 1, sweep_seq, MAX(finished_ms), COALESCE(SUM((SELECT ", kResultBytes,
          " FROM results WHERE job_seq = jobs.seq)), 0) FROM jobs WHERE sweep_seq > 0 GROUP BY "
          "sweep_seq HAVING SUM(state NOT IN ", kFinishedStates, ") = 0 ORDER BY 3"),
  };
  return *sql;
}

// The rows of one statement, each column a copy of its value (the
// conversions of sqlite3_value_*, as sqlite3_column_* would make).
class SqliteRows final : public SqlRows {
 public:
  SqliteRows(std::vector<sqlite3_value*> cells, int columns, int64_t changed)
      : cells_(std::move(cells)), columns_(columns), changed_(changed) {}
  ~SqliteRows() override {
    for (sqlite3_value* v : cells_) sqlite3_value_free(v);
  }
  SqliteRows(const SqliteRows&) = delete;
  SqliteRows& operator=(const SqliteRows&) = delete;

  int size() const override {
    return columns_ > 0 ? static_cast<int>(cells_.size()) / columns_ : 0;
  }
  int64_t Int(int row, int col) const override { return sqlite3_value_int64(cell(row, col)); }
  double Real(int row, int col) const override { return sqlite3_value_double(cell(row, col)); }
  std::string Bytes(int row, int col) const override {
    sqlite3_value* v = cell(row, col);
    const void* p = sqlite3_value_blob(v);
    return p ? std::string(static_cast<const char*>(p), sqlite3_value_bytes(v)) : "";
  }
  int64_t changed() const override { return changed_; }

 private:
  sqlite3_value* cell(int row, int col) const { return cells_[row * columns_ + col]; }
  std::vector<sqlite3_value*> cells_;
  int columns_;
  int64_t changed_;
};
}  // namespace





absl::StatusOr<std::unique_ptr<SqliteJobStore>> SqliteJobStore::Open(const std::string& dir) {
  // A missing directory is created (0700; missing parents too, with the
  // default mode), so that the first start needs no preparation.
  if (absl::Status made = CreateDataDir(dir); !made.ok()) return made;
  // Private: the directory 0700, the database (and so its WAL and shared
  // memory files, which SQLite creates with the database's mode) 0600.
  if (::chmod(dir.c_str(), 0700) != 0) {
    return absl::UnavailableError(absl::StrCat(dir, ": ", std::strerror(errno)));
  }
  const std::string path = absl::StrCat(dir, "/cablesim.db");
  // The single-server lock is held on the database file itself: removing
  // a file cannot release it, and the kernel drops it when the process
  // dies, even by kill -9. (flock locks are independent of the POSIX
  // locks SQLite takes; this descriptor stays open as long as the store,
  // so closing it never drops SQLite's own locks.)
  const int lock_fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (lock_fd < 0) {
    return absl::UnavailableError(absl::StrCat(path, ": ", std::strerror(errno)));
  }
  if (::flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd);
    return absl::FailedPreconditionError(
        absl::StrCat(dir, ": in use by another cablesim-server (", path, " is locked)"));
  }
  ::fchmod(lock_fd, 0600);
  for (const char* suffix : {"-wal", "-shm"}) {
    ::chmod(absl::StrCat(path, suffix).c_str(), 0600);  // absent: nothing to do
  }
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
    const std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close(db);
    ::close(lock_fd);
    return absl::UnavailableError(absl::StrCat(path, ": ", message));
  }
  std::unique_ptr<SqliteJobStore> store(new SqliteJobStore(db, lock_fd, dir));
  sqlite3_busy_timeout(db, 5000);
  sqlite3_create_function(db, "cablesim_row_sum", -1, SQLITE_UTF8 | SQLITE_DETERMINISTIC,
                          nullptr, RowSumFunction, nullptr, nullptr);
  if (absl::Status s = store->CheckAndMigrate(dir); !s.ok()) {
    return absl::Status(s.code(), absl::StrCat(path, ": ", s.message()));
  }
  return store;
}

absl::Status SqliteJobStore::CheckAndMigrate(const std::string& dir) {
  // Damage SQLite can see: refuse to serve from a damaged database.
  {
    Stmt check(db_, "PRAGMA quick_check");
    std::string problems;
    int rc;
    for (int n = 0; (rc = check.Step()) == SQLITE_ROW && n < 5; ++n) {
      const std::string line = check.Text(0);
      if (line == "ok") break;
      absl::StrAppend(&problems, problems.empty() ? "" : "; ", line);
    }
    if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
      return absl::DataLossError(absl::StrCat("the database is damaged (", sqlite3_errmsg(db_),
                                              "); restore it from a backup"));
    }
    if (!problems.empty()) {
      return absl::DataLossError(absl::StrCat("the database is damaged (PRAGMA quick_check: ",
                                              problems, "); restore it from a backup"));
    }
  }
  // Which store this is: DIR/store-id names the database the directory
  // had. A database that is empty, truncated or replaced while the file
  // remains is refused rather than silently started afresh (which would
  // lose every job and reuse their ids).
  const std::string id_path = absl::StrCat(dir, "/", kStoreIdFile);
  const std::string expected_id = ReadSmallFile(id_path);
  bool has_jobs = false, has_meta = false;
  {
    Stmt tables(db_, "SELECT name FROM sqlite_schema WHERE type = 'table'");
    while (tables.Step() == SQLITE_ROW) {
      const std::string name = tables.Text(0);
      has_jobs |= name == "jobs";
      has_meta |= name == "meta";
    }
  }
  std::string stored_id;
  if (has_meta) {
    Stmt get(db_, "SELECT value FROM meta WHERE key = 'store_id'");
    if (get.Step() == SQLITE_ROW) stored_id = get.Text(0);
  }
  if (!stored_id.empty() && !has_jobs) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the database has lost its schema and jobs (it names store ", stored_id,
        " but has no jobs table); restore it from a backup, or move the directory aside to "
        "start afresh"));
  }
  if (!expected_id.empty() && stored_id != expected_id) {
    return absl::FailedPreconditionError(absl::StrCat(
        "this is not the database of ", dir, " (", id_path, " names store ", expected_id,
        has_jobs ? ", the database belongs to another store"
                 : ", the database has lost its schema and jobs",
        "); restore the database from a backup, or move the directory aside to start afresh"));
  }
  // Deleted results give their disk space back (ReclaimSpace):
  // auto_vacuum=INCREMENTAL keeps the page map that incremental_vacuum
  // needs. A new database takes it before its first table; a database made
  // before is rebuilt once by VACUUM (time in proportion to its size, at
  // this start only).
  int64_t vacuum_mode = -1;
  {
    Stmt mode(db_, "PRAGMA auto_vacuum");
    if (mode.Step() != SQLITE_ROW) return SqlError(db_);
    vacuum_mode = mode.Int(0);
  }
  if (vacuum_mode != kIncrementalVacuum) {
    const char* sql = has_jobs || has_meta ? "PRAGMA auto_vacuum=INCREMENTAL; VACUUM"
                                           : "PRAGMA auto_vacuum=INCREMENTAL";
    if (absl::Status s = Exec(sql); !s.ok()) return absl::UnavailableError(s.message());
  }
  // WAL: readers do not block the writer; synchronous=FULL: a committed
  // transaction is on disk before the call returns; journal_size_limit:
  // after a checkpoint the log file keeps at most 16 MiB (not the size of
  // the largest result ever written).
  for (const char* sql : {"PRAGMA journal_mode=WAL", "PRAGMA synchronous=FULL",
                          "PRAGMA journal_size_limit=16777216", "PRAGMA foreign_keys=ON",
                          kSchema}) {
    if (absl::Status s = Exec(sql); !s.ok()) return absl::UnavailableError(s.message());
  }
  // Databases from before checksums: add the column and fill it from the
  // data as it is now.
  bool has_checksum = false;
  {
    Stmt columns(db_, "PRAGMA table_info(results)");
    while (columns.Step() == SQLITE_ROW) has_checksum |= columns.Text(1) == "checksum";
  }
  if (!has_checksum) {
    if (absl::Status s = Exec("ALTER TABLE results ADD COLUMN checksum INTEGER"); !s.ok()) return s;
  }
  // Databases from before compression: their results stay raw doubles
  // (encoding 0), read as they are.
  bool has_encoding = false;
  {
    Stmt columns(db_, "PRAGMA table_info(results)");
    while (columns.Step() == SQLITE_ROW) has_encoding |= columns.Text(1) == "encoding";
  }
  if (!has_encoding) {
    if (absl::Status s =
            Exec("ALTER TABLE results ADD COLUMN encoding INTEGER NOT NULL DEFAULT 0");
        !s.ok()) {
      return s;
    }
  }
  // Databases from before random ids: their rows keep the ids they had.
  for (const auto& [table, prefix] : {std::pair{"jobs", "j"}, std::pair{"sweeps", "s"}}) {
    bool has = false;
    {
      Stmt columns(db_, absl::StrCat("PRAGMA table_info(", table, ")").c_str());
      while (columns.Step() == SQLITE_ROW) has |= columns.Text(1) == "pid";
    }
    if (!has) {
      if (absl::Status s = Exec(absl::StrCat("ALTER TABLE ", table, " ADD COLUMN pid TEXT").c_str());
          !s.ok()) {
        return s;
      }
    }
    if (absl::Status s = Exec(absl::StrCat("UPDATE ", table, " SET pid = printf('", prefix,
                                           "-%06d', seq) WHERE pid IS NULL; ",
                                           "CREATE UNIQUE INDEX IF NOT EXISTS ", table,
                                           "_by_pid ON ", table, "(pid)")
                                  .c_str());
        !s.ok()) {
      return s;
    }
  }
  // Databases from before per-client limits and tenants: jobs and sweeps
  // of no known client and no tenant.
  for (const auto& [table, column] : {std::pair{"jobs", "peer"}, std::pair{"jobs", "tenant"},
                                      std::pair{"sweeps", "tenant"}}) {
    bool has = false;
    Stmt columns(db_, absl::StrCat("PRAGMA table_info(", table, ")").c_str());
    while (columns.Step() == SQLITE_ROW) has |= columns.Text(1) == column;
    if (has) continue;
    if (absl::Status s = Exec(absl::StrCat("ALTER TABLE ", table, " ADD COLUMN ", column,
                                           " TEXT NOT NULL DEFAULT ''")
                                  .c_str());
        !s.ok()) {
      return s;
    }
  }
  // Databases from before row checksums: the column, filled from the rows
  // as they are now, and the triggers that keep it.
  for (const auto& [table, columns] :
       {std::pair{"jobs", kJobSumColumns}, std::pair{"sweeps", kSweepSumColumns}}) {
    bool has = false;
    {
      Stmt info(db_, absl::StrCat("PRAGMA table_info(", table, ")").c_str());
      while (info.Step() == SQLITE_ROW) has |= info.Text(1) == "row_sum";
    }
    if (!has) {
      if (absl::Status s = Exec(absl::StrCat("ALTER TABLE ", table,
                                             " ADD COLUMN row_sum INTEGER; UPDATE ", table,
                                             " SET row_sum = cablesim_row_sum(", columns, ")")
                                    .c_str());
          !s.ok()) {
        return s;
      }
    }
    if (absl::Status s = Exec(RowSumTriggers(table, columns).c_str()); !s.ok()) return s;
  }
  // Fair share (kFairShareOrder): each tenant's, or client's, latest start
  // by index.
  if (absl::Status s = Exec(
          "CREATE INDEX IF NOT EXISTS jobs_by_tenant_start ON jobs(tenant, started_ms); "
          "CREATE INDEX IF NOT EXISTS jobs_by_tenant_peer_start ON jobs(tenant, peer, started_ms)");
      !s.ok()) {
    return s;
  }
  {
    std::vector<std::pair<int64_t, int64_t>> sums;
    Stmt missing(db_, "SELECT job_seq, header, vals FROM results WHERE checksum IS NULL");
    while (missing.Step() == SQLITE_ROW) {
      const std::string header = missing.Blob(1), vals = missing.Blob(2);
      sums.emplace_back(missing.Int(0),
                        ResultChecksum(header.data(), header.size(), vals.data(), vals.size()));
    }
    for (const auto& [seq, sum] : sums) {
      Stmt set(db_, "UPDATE results SET checksum = ?1 WHERE job_seq = ?2");
      if (absl::Status s = set.Bind(1, sum).Bind(2, seq).Done(); !s.ok()) return s;
    }
  }
  // The page-token secret (page_token.h): made once, kept with the jobs.
  {
    absl::StatusOr<std::string> fresh = NewPageTokenSecret();
    if (!fresh.ok()) return fresh.status();
    Stmt put(db_, "INSERT OR IGNORE INTO meta (key, value) VALUES ('page_token_secret', ?1)");
    if (absl::Status s = put.Bind(1, *fresh).Done(); !s.ok()) return s;
    Stmt get(db_, "SELECT value FROM meta WHERE key = 'page_token_secret'");
    if (get.Step() != SQLITE_ROW) return SqlError(db_);
    page_token_secret_ = get.Text(0);
  }
  if (stored_id.empty()) {
    absl::StatusOr<std::string> id = RandomId();
    if (!id.ok()) return id.status();
    stored_id = *id;
    Stmt put(db_, "INSERT OR REPLACE INTO meta (key, value) VALUES ('store_id', ?1)");
    if (absl::Status s = put.Bind(1, stored_id).Done(); !s.ok()) return s;
  }
  // The database first, then the file: a crash in between leaves a
  // database whose id the next start writes again.
  if (expected_id != stored_id) return WriteFileDurably(id_path, stored_id);
  return absl::OkStatus();
}

SqliteJobStore::~SqliteJobStore() {
  sqlite3_close(db_);
  ::close(lock_fd_);  // releases the lock (after SQLite has let go of the file)
}

absl::Status SqliteJobStore::Exec(const char* sql) {
  char* error = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    absl::Status s = absl::InternalError(absl::StrCat("sqlite: ", error ? error : "error"));
    sqlite3_free(error);
    return s;
  }
  return absl::OkStatus();
}

SqliteJobStore::SqliteJobStore(sqlite3* db, int lock_fd, std::string dir)
    : SqlJobStore(Statements()), db_(db), lock_fd_(lock_fd), dir_(std::move(dir)) {}

absl::StatusOr<std::unique_ptr<SqlRows>> SqliteJobStore::Run(const std::string& sql,
                                                             const SqlParams& params) {
  sqlite3_stmt* stmt = nullptr;
  if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt, nullptr) != SQLITE_OK) {
    sqlite3_finalize(stmt);
    return SqlError(db_);
  }
  for (const auto& [name, value] : params) {
    const int i = sqlite3_bind_parameter_index(stmt, absl::StrCat("@", name).c_str());
    if (i == 0) continue;  // a parameter this statement does not use
    if (const auto* v = std::get_if<int64_t>(&value)) {
      sqlite3_bind_int64(stmt, i, *v);
    } else if (const auto* v = std::get_if<double>(&value)) {
      sqlite3_bind_double(stmt, i, *v);
    } else if (const auto* v = std::get_if<std::string>(&value)) {
      sqlite3_bind_text(stmt, i, v->data(), static_cast<int>(v->size()), SQLITE_TRANSIENT);
    } else if (const auto* v = std::get_if<SqlBytes>(&value)) {
      // An empty blob, never NULL.
      static const char kEmpty = 0;
      sqlite3_bind_blob64(stmt, i, v->data.empty() ? &kEmpty : v->data.data(), v->data.size(),
                          SQLITE_TRANSIENT);
    } else {
      // The state's number, as the jobs table stores it.
      sqlite3_bind_int64(stmt, i, std::get<SqlState>(value).state);
    }
  }
  const int columns = sqlite3_column_count(stmt);
  std::vector<sqlite3_value*> cells;
  int rc;
  while ((rc = sqlite3_step(stmt)) == SQLITE_ROW) {
    for (int c = 0; c < columns; ++c) cells.push_back(sqlite3_value_dup(sqlite3_column_value(stmt, c)));
  }
  std::unique_ptr<SqlRows> rows(new SqliteRows(std::move(cells), columns, sqlite3_changes(db_)));
  if (rc != SQLITE_DONE) {
    absl::Status error = SqlError(db_);
    sqlite3_finalize(stmt);
    return error;
  }
  sqlite3_finalize(stmt);
  return rows;
}

absl::StatusOr<bool> SqliteJobStore::ReclaimSpace() {
  absl::MutexLock lock(&mu_);
  auto free_pages = [this]() -> int64_t {
    Stmt count(db_, "PRAGMA freelist_count");
    return count.Step() == SQLITE_ROW ? count.Int(0) : -1;
  };
  const int64_t before = free_pages();
  if (before < 0) return SqlError(db_);
  if (before == 0) return false;
  // Moves the pages at the end of the file into the free ones and cuts the
  // file (in the write-ahead log until the checkpoint below).
  if (absl::Status s = Exec(absl::StrCat("PRAGMA incremental_vacuum(", kReclaimPages, ")").c_str());
      !s.ok()) {
    return s;
  }
  const int64_t after = free_pages();
  if (after < 0) return SqlError(db_);
  if (after > 0) return true;
  // Everything moved: the database file shrinks at this checkpoint, and
  // the log is emptied.
  if (absl::Status s = Exec("PRAGMA wal_checkpoint(TRUNCATE)"); !s.ok()) return s;
  return false;
}

}  // namespace cablesim
