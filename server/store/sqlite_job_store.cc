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

// The last columns: bytes of the job's stored result (0 without one),
// the id, the sweep's id, whether the row is intact.
const std::string& JobColumns() {
  static const std::string* sql = new std::string(absl::StrCat(
      "seq, state, name, created_ms, started_ms, finished_ms, attempts, end_time_s, summary, "
      "sweep_seq, sweep_index, "
      "(SELECT length(header) + length(vals) FROM results WHERE job_seq = jobs.seq), pid, "
      "(SELECT pid FROM sweeps WHERE sweeps.seq = jobs.sweep_seq), ",
      JobIntact()));
  return *sql;
}
constexpr int kJobIntactColumn = 14;

v1::Job JobFromRow(Stmt& s) {
  v1::Job job;
  job.set_id(s.Text(12));
  job.set_state(static_cast<v1::JobState>(s.Int(1)));
  job.set_name(s.Text(2));
  job.set_created_unix_ms(s.Int(3));
  job.set_started_unix_ms(s.Int(4));
  job.set_finished_unix_ms(s.Int(5));
  job.set_attempts(static_cast<int>(s.Int(6)));
  job.set_end_time_s(s.Real(7));
  const std::string summary = s.Blob(8);
  if (!summary.empty()) job.mutable_summary()->ParseFromString(summary);
  if (s.Int(9) > 0) {
    job.set_sweep_id(s.Text(13));
    job.set_sweep_index(static_cast<int>(s.Int(10)));
  }
  job.set_stored_bytes(s.Int(11));
  return job;
}



}  // namespace





int64_t SqliteJobStore::LookUpSeq(const std::string& id) {
  Stmt s(db_, IsSweepId(id) ? "SELECT seq FROM sweeps WHERE pid = ?1"
                            : "SELECT seq FROM jobs WHERE pid = ?1");
  s.Bind(1, id);
  return s.Step() == SQLITE_ROW ? s.Int(0) : -1;
}

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

absl::StatusOr<int> SqliteJobStore::RequeueRunning() {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, "UPDATE jobs SET state = ?1 WHERE state = ?2");
  s.Bind(1, int64_t{v1::QUEUED}).Bind(2, int64_t{v1::RUNNING});
  if (absl::Status st = s.Done(); !st.ok()) return st;
  return sqlite3_changes(db_);
}

absl::Status SqliteJobStore::CheckPeerRoom(const std::string& peer, int64_t adding,
                                     int64_t max_unfinished) {
  if (max_unfinished == std::numeric_limits<int64_t>::max()) return absl::OkStatus();
  Stmt c(db_, "SELECT COUNT(*) FROM jobs WHERE peer = ?1 AND state IN (?2, ?3)");
  c.Bind(1, peer).Bind(2, int64_t{v1::QUEUED}).Bind(3, int64_t{v1::RUNNING});
  if (c.Step() != SQLITE_ROW) return SqlError(db_);
  const int64_t unfinished = c.Int(0);
  if (unfinished + adding > max_unfinished) {
    return PeerLimitExceeded(peer, unfinished, adding, max_unfinished);
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::Job> SqliteJobStore::InsertJob(const v1::Scene& scene, double end_time_s,
                                            const std::string& peer, int64_t max_unfinished,
                                            const std::string& tenant) {
  absl::StatusOr<std::string> pid = NewPublicId('j');
  if (!pid.ok()) return pid.status();
  {
    absl::MutexLock lock(&mu_);
    if (absl::Status st = CheckPeerRoom(peer, 1, max_unfinished); !st.ok()) return st;
    Stmt s(db_,
           "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, peer, tenant, pid) "
           "VALUES (?1,?2,?3,?4,?5,?6,?7,?8)");
    const std::string blob = scene.SerializeAsString();
    s.Bind(1, int64_t{v1::QUEUED})
        .Bind(2, scene.name())
        .BindBlob(3, blob.data(), blob.size())
        .Bind(4, end_time_s)
        .Bind(5, NowUnixMs())
        .Bind(6, peer)
        .Bind(7, tenant)
        .Bind(8, *pid);
    if (absl::Status st = s.Done(); !st.ok()) return st;
  }
  return GetJob(*pid);
}

absl::StatusOr<v1::Sweep> SqliteJobStore::InsertSweep(const v1::SubmitSweepRequest& request,
                                                const std::vector<v1::Scene>& items,
                                                const std::vector<double>& end_times_s,
                                                const std::string& peer,
                                                int64_t max_unfinished,
                                                const std::string& tenant) {
  int64_t sweep_seq;
  absl::StatusOr<std::string> sweep_pid;
  {
    absl::MutexLock lock(&mu_);
    if (absl::Status st = CheckPeerRoom(peer, static_cast<int64_t>(items.size()), max_unfinished);
        !st.ok()) {
      return st;
    }
    if (absl::Status st = Exec("BEGIN IMMEDIATE"); !st.ok()) return st;
    auto rollback = [&](absl::Status st) {
      Exec("ROLLBACK").IgnoreError();
      return st;
    };
    sweep_pid = NewPublicId('s');
    if (!sweep_pid.ok()) return rollback(sweep_pid.status());
    v1::Sweep axes;
    *axes.mutable_axes() = request.axes();
    *axes.mutable_thresholds() = request.thresholds();  // kept with the axes
    const std::string axes_blob = axes.SerializeAsString();
    const int64_t now = NowUnixMs();
    {
      Stmt s(db_,
             "INSERT INTO sweeps (name, axes, created_ms, tenant, pid) VALUES (?1,?2,?3,?4,?5)");
      s.Bind(1, request.name())
          .BindBlob(2, axes_blob.data(), axes_blob.size())
          .Bind(3, now)
          .Bind(4, tenant)
          .Bind(5, *sweep_pid);
      if (absl::Status st = s.Done(); !st.ok()) return rollback(st);
      sweep_seq = sqlite3_last_insert_rowid(db_);
    }
    for (size_t i = 0; i < items.size(); ++i) {
      Stmt s(db_,
             "INSERT INTO jobs (state, name, scene, end_time_s, created_ms, sweep_seq, "
             "sweep_index, peer, tenant, pid) VALUES (?1,?2,?3,?4,?5,?6,?7,?8,?9,?10)");
      const std::string blob = items[i].SerializeAsString();
      s.Bind(1, int64_t{v1::QUEUED})
          .Bind(2, items[i].name())
          .BindBlob(3, blob.data(), blob.size())
          .Bind(4, end_times_s[i])
          .Bind(5, now)
          .Bind(6, sweep_seq)
          .Bind(7, static_cast<int64_t>(i))
          .Bind(8, peer)
          .Bind(9, tenant);
      absl::StatusOr<std::string> item_pid = NewPublicId('j');
      if (!item_pid.ok()) return rollback(item_pid.status());
      s.Bind(10, *item_pid);
      if (absl::Status st = s.Done(); !st.ok()) return rollback(st);
    }
    if (absl::Status st = Exec("COMMIT"); !st.ok()) return rollback(st);
  }
  (void)sweep_seq;
  return GetSweep(*sweep_pid);
}

absl::StatusOr<v1::Job> SqliteJobStore::GetJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, absl::StrCat("SELECT ", JobColumns(), " FROM jobs WHERE pid = ?1").c_str());
  s.Bind(1, id);
  const int rc = s.Step();
  if (rc == SQLITE_ROW) {
    if (s.Int(kJobIntactColumn) != 1) return DamagedRow("job", id);
    return JobFromRow(s);
  }
  if (rc == SQLITE_DONE) return absl::NotFoundError(absl::StrCat("no job \"", id, "\""));
  return SqlError(db_);
}

absl::StatusOr<v1::Scene> SqliteJobStore::GetScene(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, "SELECT scene FROM jobs WHERE pid = ?1");
  s.Bind(1, id);
  const int rc = s.Step();
  if (rc == SQLITE_DONE) return absl::NotFoundError(absl::StrCat("no job \"", id, "\""));
  if (rc != SQLITE_ROW) return SqlError(db_);
  v1::Scene scene;
  if (!scene.ParseFromString(s.Blob(0))) return absl::DataLossError("stored scene unreadable");
  return scene;
}

absl::StatusOr<std::vector<v1::Job>> SqliteJobStore::ListJobs(v1::JobState state,
                                                              const std::string& sweep_id,
                                                              int limit, int64_t after_key,
                                                              const std::string* tenant,
                                                              std::vector<int64_t>* keys) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, absl::StrCat("SELECT ", JobColumns(),
                           " FROM jobs WHERE (?1 = 0 OR state = ?1) AND (?2 = 0 OR sweep_seq = ?2)"
                           " AND seq < ?4 AND (?5 = 0 OR tenant = ?6) ORDER BY seq DESC LIMIT ?3")
                  .c_str());
  s.Bind(5, int64_t{tenant != nullptr}).Bind(6, tenant != nullptr ? *tenant : std::string());
  s.Bind(1, int64_t{state})
      .Bind(2, sweep_id.empty() ? 0 : (IsSweepId(sweep_id) ? LookUpSeq(sweep_id) : -1))
      .Bind(3, int64_t{limit})
      .Bind(4, after_key > 0 ? after_key : std::numeric_limits<int64_t>::max());
  std::vector<v1::Job> jobs;
  if (keys != nullptr) keys->clear();
  int rc;
  while ((rc = s.Step()) == SQLITE_ROW) {
    // A damaged row: a placeholder (JobStore::ListJobs).
    jobs.push_back(s.Int(kJobIntactColumn) == 1 ? JobFromRow(s) : v1::Job());
    if (keys != nullptr) keys->push_back(s.Int(0));
  }
  if (rc != SQLITE_DONE) return SqlError(db_);
  return jobs;
}

absl::StatusOr<std::vector<std::string>> SqliteJobStore::QueuedJobIds() {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, "SELECT pid FROM jobs WHERE state = ?1 ORDER BY seq");
  s.Bind(1, int64_t{v1::QUEUED});
  std::vector<std::string> ids;
  int rc;
  while ((rc = s.Step()) == SQLITE_ROW) ids.push_back(s.Text(0));
  if (rc != SQLITE_DONE) return SqlError(db_);
  return ids;
}

absl::StatusOr<bool> SqliteJobStore::MarkRunning(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_,
         "UPDATE jobs SET state = ?1, started_ms = ?2, attempts = attempts + 1 "
         "WHERE seq = ?3 AND state = ?4");
  s.Bind(1, int64_t{v1::RUNNING})
      .Bind(2, NowUnixMs())
      .Bind(3, LookUpSeq(id))
      .Bind(4, int64_t{v1::QUEUED});
  if (absl::Status st = s.Done(); !st.ok()) return st;
  return sqlite3_changes(db_) == 1;
}

absl::Status SqliteJobStore::Requeue(const std::string& id, int attempt) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_,
         "UPDATE jobs SET state = ?1 WHERE seq = ?2 AND state = ?3 AND (?4 = 0 OR attempts = ?4)");
  s.Bind(1, int64_t{v1::QUEUED})
      .Bind(2, LookUpSeq(id))
      .Bind(3, int64_t{v1::RUNNING})
      .Bind(4, int64_t{attempt});
  return s.Done();
}

absl::StatusOr<std::optional<Claim>> SqliteJobStore::ClaimNext() {
  absl::MutexLock lock(&mu_);
  // One connection, one server (the flock): nothing else can claim
  // between the look and the update.
  Stmt s(db_, absl::StrCat("SELECT seq, pid, attempts FROM jobs j WHERE state = ?1 ORDER BY ",
                          kFairShareOrder, " LIMIT 1")
                 .c_str());
  s.Bind(1, int64_t{v1::QUEUED});
  const int rc = s.Step();
  if (rc == SQLITE_DONE) return std::nullopt;
  if (rc != SQLITE_ROW) return SqlError(db_);
  Claim claim{s.Text(1), static_cast<int>(s.Int(2)) + 1};
  Stmt u(db_,
         "UPDATE jobs SET state = ?1, started_ms = ?2, attempts = attempts + 1 "
         "WHERE seq = ?3 AND state = ?4");
  u.Bind(1, int64_t{v1::RUNNING})
      .Bind(2, NowUnixMs())
      .Bind(3, s.Int(0))
      .Bind(4, int64_t{v1::QUEUED});
  if (absl::Status st = u.Done(); !st.ok()) return st;
  if (sqlite3_changes(db_) != 1) return std::nullopt;
  return claim;
}

absl::StatusOr<bool> SqliteJobStore::CancelQueued(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, "UPDATE jobs SET state = ?1, finished_ms = ?2 WHERE seq = ?3 AND state = ?4");
  s.Bind(1, int64_t{v1::CANCELLED})
      .Bind(2, NowUnixMs())
      .Bind(3, LookUpSeq(id))
      .Bind(4, int64_t{v1::QUEUED});
  if (absl::Status st = s.Done(); !st.ok()) return st;
  return sqlite3_changes(db_) == 1;
}

absl::StatusOr<bool> SqliteJobStore::Finish(const std::string& id, v1::JobState state,
                                            const v1::RunSummary& summary,
                                            const StoredResult& result, int attempt) {
  const std::string summary_blob = summary.SerializeAsString();
  const std::string header_blob = result.header.SerializeAsString();
  const EncodedValues vals = EncodeValues(result.values, result.header.columns_size());
  absl::MutexLock lock(&mu_);
  const int64_t seq = LookUpSeq(id);
  if (absl::Status st = Exec("BEGIN IMMEDIATE"); !st.ok()) return st;
  auto rollback = [&](absl::Status st) {
    Exec("ROLLBACK").IgnoreError();
    return st;
  };
  Stmt u(db_,
         "UPDATE jobs SET state = ?1, finished_ms = ?2, summary = ?3 WHERE seq = ?4 AND "
         "state = ?5 AND (?6 = 0 OR attempts = ?6)");
  u.Bind(1, int64_t{state})
      .Bind(2, NowUnixMs())
      .BindBlob(3, summary_blob.data(), summary_blob.size())
      .Bind(4, seq)
      .Bind(5, int64_t{v1::RUNNING})
      .Bind(6, int64_t{attempt});
  if (absl::Status st = u.Done(); !st.ok()) return rollback(st);
  if (sqlite3_changes(db_) != 1) {
    Exec("ROLLBACK").IgnoreError();
    return false;
  }
  Stmt r(db_,
         "INSERT OR REPLACE INTO results (job_seq, header, vals, checksum, encoding) VALUES "
         "(?1,?2,?3,?4,?5)");
  r.Bind(1, seq)
      .BindBlob(2, header_blob.data(), header_blob.size())
      .BindBlob(3, vals.blob.data(), vals.blob.size())
      .Bind(4, ResultChecksum(header_blob.data(), header_blob.size(), vals.blob.data(),
                              vals.blob.size()))
      .Bind(5, vals.encoding);
  if (absl::Status st = r.Done(); !st.ok()) return rollback(st);
  if (absl::Status st = Exec("COMMIT"); !st.ok()) return rollback(st);
  return true;
}

absl::StatusOr<StoredResult> SqliteJobStore::GetResult(const std::string& id) {
  absl::MutexLock lock(&mu_);
  Stmt s(db_, "SELECT header, vals, checksum, encoding FROM results WHERE job_seq = ?1");
  s.Bind(1, LookUpSeq(id));
  const int rc = s.Step();
  if (rc == SQLITE_DONE) return absl::NotFoundError(absl::StrCat("job \"", id, "\" has no result"));
  if (rc != SQLITE_ROW) return SqlError(db_);
  const std::string header = s.Blob(0), vals = s.Blob(1);
  // Never serve altered data: the checksum written with the result must
  // still match.
  return CheckedResult(id, header, vals, s.Int(2), s.Int(3));
}

absl::StatusOr<v1::Sweep> SqliteJobStore::GetSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  const int64_t seq = IsSweepId(id) ? LookUpSeq(id) : -1;
  v1::Sweep sweep;
  {
    Stmt s(db_, absl::StrCat("SELECT name, axes, created_ms, ", SweepIntact(),
                             " FROM sweeps WHERE seq = ?1")
                    .c_str());
    s.Bind(1, seq);
    const int rc = s.Step();
    if (rc == SQLITE_DONE) return absl::NotFoundError(absl::StrCat("no sweep \"", id, "\""));
    if (rc != SQLITE_ROW) return SqlError(db_);
    if (s.Int(3) != 1) return DamagedRow("sweep", id);
    sweep.ParseFromString(s.Blob(1));
    sweep.set_id(id);
    sweep.set_name(s.Text(0));
    sweep.set_created_unix_ms(s.Int(2));
  }
  Stmt s(db_, absl::StrCat("SELECT pid, state, ", JobIntact(),
                           " FROM jobs WHERE sweep_seq = ?1 ORDER BY sweep_index")
                  .c_str());
  s.Bind(1, seq);
  int rc;
  int items = 0, finished = 0, failed = 0;
  while ((rc = s.Step()) == SQLITE_ROW) {
    ++items;
    // A damaged item: the sweep's ids and counts cannot be served whole.
    if (s.Int(2) != 1) {
      return absl::DataLossError(absl::StrCat("sweep ", id, ": the stored row of item ",
                                              items - 1, " fails its checksum (the database "
                                              "is damaged); cablesim-server --check lists it"));
    }
    sweep.add_job_ids(s.Text(0));
    const auto state = static_cast<v1::JobState>(s.Int(1));
    if (state == v1::SUCCEEDED || state == v1::FAILED || state == v1::CANCELLED) ++finished;
    if (state == v1::FAILED || state == v1::CANCELLED) ++failed;
  }
  if (rc != SQLITE_DONE) return SqlError(db_);
  sweep.set_items(items);
  sweep.set_finished(finished);
  sweep.set_failed(failed);
  return sweep;
}

namespace {


constexpr char kResultBytes[] = "length(header) + length(vals)";

}  // namespace

absl::Status SqliteJobStore::DeleteJobRows(const std::string& where, int64_t key) {
  Stmt r(db_, absl::StrCat("DELETE FROM results WHERE job_seq IN (SELECT seq FROM jobs WHERE ",
                           where, ")")
                  .c_str());
  if (absl::Status st = r.Bind(1, key).Done(); !st.ok()) return st;
  Stmt j(db_, absl::StrCat("DELETE FROM jobs WHERE ", where).c_str());
  return j.Bind(1, key).Done();
}

absl::StatusOr<int64_t> SqliteJobStore::DeleteJob(const std::string& id) {
  absl::MutexLock lock(&mu_);
  const int64_t seq = IsSweepId(id) ? -1 : LookUpSeq(id);
  if (absl::Status st = Exec("BEGIN IMMEDIATE"); !st.ok()) return st;
  auto rollback = [&](absl::Status st) {
    Exec("ROLLBACK").IgnoreError();
    return st;
  };
  Stmt s(db_, absl::StrCat("SELECT state, sweep_seq, (SELECT ", kResultBytes,
                           " FROM results WHERE job_seq = jobs.seq), "
                           "(SELECT pid FROM sweeps WHERE sweeps.seq = jobs.sweep_seq) "
                           "FROM jobs WHERE seq = ?1")
                  .c_str());
  s.Bind(1, seq);
  const int rc = s.Step();
  if (rc == SQLITE_DONE) return rollback(absl::NotFoundError(absl::StrCat("no job \"", id, "\"")));
  if (rc != SQLITE_ROW) return rollback(SqlError(db_));
  const auto state = static_cast<v1::JobState>(s.Int(0));
  const int64_t sweep_seq = s.Int(1), bytes = s.Int(2);
  const std::string sweep_id = s.Text(3);
  if (!IsFinished(state)) {
    return rollback(absl::FailedPreconditionError(absl::StrCat(
        "job \"", id, "\" is ", v1::JobState_Name(state), "; cancel it before deleting it")));
  }
  if (sweep_seq > 0) {
    return rollback(absl::FailedPreconditionError(
        absl::StrCat("job \"", id, "\" is an item of sweep \"", sweep_id,
                     "\"; delete the sweep (DeleteSweep) instead")));
  }
  if (absl::Status st = DeleteJobRows("seq = ?1", seq); !st.ok()) return rollback(st);
  if (absl::Status st = Exec("COMMIT"); !st.ok()) return rollback(st);
  return bytes;
}

absl::StatusOr<int64_t> SqliteJobStore::DeleteSweep(const std::string& id) {
  absl::MutexLock lock(&mu_);
  const int64_t seq = IsSweepId(id) ? LookUpSeq(id) : -1;
  if (absl::Status st = Exec("BEGIN IMMEDIATE"); !st.ok()) return st;
  auto rollback = [&](absl::Status st) {
    Exec("ROLLBACK").IgnoreError();
    return st;
  };
  {
    Stmt s(db_, "SELECT 1 FROM sweeps WHERE seq = ?1");
    s.Bind(1, seq);
    const int rc = s.Step();
    if (rc == SQLITE_DONE) {
      return rollback(absl::NotFoundError(absl::StrCat("no sweep \"", id, "\"")));
    }
    if (rc != SQLITE_ROW) return rollback(SqlError(db_));
  }
  int64_t bytes = 0, unfinished = 0;
  {
    Stmt s(db_, absl::StrCat("SELECT state, (SELECT ", kResultBytes,
                             " FROM results WHERE job_seq = jobs.seq) FROM jobs WHERE "
                             "sweep_seq = ?1")
                    .c_str());
    s.Bind(1, seq);
    int rc;
    while ((rc = s.Step()) == SQLITE_ROW) {
      unfinished += IsFinished(static_cast<v1::JobState>(s.Int(0))) ? 0 : 1;
      bytes += s.Int(1);
    }
    if (rc != SQLITE_DONE) return rollback(SqlError(db_));
  }
  if (unfinished > 0) {
    return rollback(absl::FailedPreconditionError(
        absl::StrCat("sweep \"", id, "\" has ", unfinished,
                     " unfinished items; cancel them before deleting it")));
  }
  if (absl::Status st = DeleteJobRows("sweep_seq = ?1", seq); !st.ok()) return rollback(st);
  Stmt d(db_, "DELETE FROM sweeps WHERE seq = ?1");
  if (absl::Status st = d.Bind(1, seq).Done(); !st.ok()) return rollback(st);
  if (absl::Status st = Exec("COMMIT"); !st.ok()) return rollback(st);
  return bytes;
}

absl::StatusOr<RetentionReport> SqliteJobStore::ApplyRetention(int64_t older_than_unix_ms,
                                                         int64_t max_bytes) {
  // What can go: finished jobs outside sweeps, and sweeps whose items have
  // all finished (a sweep goes as a whole), oldest finished first.
  struct Candidate {
    bool sweep;
    int64_t seq, finished_ms, bytes;
  };
  std::vector<Candidate> candidates;
  int64_t total = 0;
  absl::MutexLock lock(&mu_);
  {
    Stmt t(db_, absl::StrCat("SELECT COALESCE(SUM(", kResultBytes, "), 0) FROM results").c_str());
    if (t.Step() != SQLITE_ROW) return SqlError(db_);
    total = t.Int(0);
  }
  {
    Stmt s(db_, absl::StrCat(
                    "SELECT 0, seq, finished_ms, COALESCE((SELECT ", kResultBytes,
                    " FROM results WHERE job_seq = jobs.seq), 0) FROM jobs "
                    "WHERE sweep_seq = 0 AND state IN (?1, ?2, ?3) "
                    "UNION ALL "
                    "SELECT 1, sweep_seq, MAX(finished_ms), COALESCE(SUM((SELECT ",
                    kResultBytes,
                    " FROM results WHERE job_seq = jobs.seq)), 0) FROM jobs "
                    "WHERE sweep_seq > 0 GROUP BY sweep_seq "
                    "HAVING SUM(state NOT IN (?1, ?2, ?3)) = 0 "
                    "ORDER BY 3")
                    .c_str());
    s.Bind(1, int64_t{v1::SUCCEEDED}).Bind(2, int64_t{v1::FAILED}).Bind(3, int64_t{v1::CANCELLED});
    int rc;
    while ((rc = s.Step()) == SQLITE_ROW) {
      candidates.push_back({s.Int(0) != 0, s.Int(1), s.Int(2), s.Int(3)});
    }
    if (rc != SQLITE_DONE) return SqlError(db_);
  }
  RetentionReport report;
  for (const Candidate& c : candidates) {
    if (c.finished_ms >= older_than_unix_ms && total <= max_bytes) break;
    if (absl::Status st = Exec("BEGIN IMMEDIATE"); !st.ok()) return st;
    absl::Status st = DeleteJobRows(c.sweep ? "sweep_seq = ?1" : "seq = ?1", c.seq);
    int64_t jobs = sqlite3_changes(db_);
    if (st.ok() && c.sweep) {
      Stmt d(db_, "DELETE FROM sweeps WHERE seq = ?1");
      st = d.Bind(1, c.seq).Done();
    }
    if (st.ok()) st = Exec("COMMIT");
    if (!st.ok()) {
      Exec("ROLLBACK").IgnoreError();
      return st;
    }
    total -= c.bytes;
    report.jobs += jobs;
    report.sweeps += c.sweep ? 1 : 0;
    report.bytes += c.bytes;
  }
  return report;
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

absl::StatusOr<std::string> SqliteJobStore::Tenant(const std::string& id) {
  const bool sweep = IsSweepId(id);
  absl::MutexLock lock(&mu_);
  Stmt s(db_, absl::StrCat("SELECT tenant, ", sweep ? SweepIntact() : JobIntact(), " FROM ",
                           sweep ? "sweeps" : "jobs", " WHERE pid = ?1")
                  .c_str());
  s.Bind(1, id);
  const int rc = s.Step();
  if (rc == SQLITE_ROW) {
    // A damaged row's tenant cannot be trusted: DataLoss for everyone.
    if (s.Int(1) != 1) return DamagedRow(sweep ? "sweep" : "job", id);
    return s.Text(0);
  }
  if (rc == SQLITE_DONE) {
    return absl::NotFoundError(absl::StrCat("no ", sweep ? "sweep" : "job", " \"", id, "\""));
  }
  return SqlError(db_);
}

absl::StatusOr<std::vector<std::string>> SqliteJobStore::CheckRows() {
  absl::MutexLock lock(&mu_);
  std::vector<std::string> damaged;
  for (const auto& [table, kind, intact] : {std::tuple{"jobs", "job", &JobIntact()},
                                            std::tuple{"sweeps", "sweep", &SweepIntact()}}) {
    Stmt s(db_, absl::StrCat("SELECT seq, pid FROM ", table, " WHERE NOT ", *intact, " ORDER BY seq")
                    .c_str());
    int rc;
    while ((rc = s.Step()) == SQLITE_ROW) {
      damaged.push_back(absl::StrCat(kind, " ", s.Text(1), " (row ", s.Int(0),
                                     "): the row fails its checksum"));
    }
    if (rc != SQLITE_DONE) return SqlError(db_);
  }
  Stmt r(db_,
         "SELECT job_seq, (SELECT pid FROM jobs WHERE seq = job_seq), header, vals, checksum, "
         "encoding FROM results ORDER BY job_seq");
  int rc;
  while ((rc = r.Step()) == SQLITE_ROW) {
    const std::string id = r.Text(1);
    absl::StatusOr<StoredResult> result =
        CheckedResult(id, r.Blob(2), r.Blob(3), r.Int(4), r.Int(5));
    if (!result.ok()) {
      damaged.push_back(absl::StrCat("result of job ", id, " (row ", r.Int(0),
                                     "): ", result.status().message()));
    }
  }
  if (rc != SQLITE_DONE) return SqlError(db_);
  return damaged;
}

}  // namespace cablesim
