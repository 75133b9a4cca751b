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

#include "server/store/sql_job_store.h"

struct sqlite3;

namespace cablesim {

class SqliteJobStore final : public SqlJobStore {
 public:
  // Opens (creating if needed) DIR/cablesim.db; creates DIR (0700) when
  // missing, FailedPrecondition naming it when it cannot.
  static absl::StatusOr<std::unique_ptr<SqliteJobStore>> Open(const std::string& dir);
  ~SqliteJobStore() override;

  std::string Describe() const override { return "sqlite:" + dir_; }
  // `PRAGMA incremental_vacuum` of at most 4096 pages (16 MiB), and once
  // no free page is left, a checkpoint that truncates the database file
  // and empties the write-ahead log.
  absl::StatusOr<bool> ReclaimSpace() override;

 protected:
  absl::StatusOr<std::unique_ptr<SqlRows>> Run(const std::string& sql,
                                               const SqlParams& params) override;

 private:
  SqliteJobStore(sqlite3* db, int lock_fd, std::string dir);
  absl::Status Exec(const char* sql);
  // Open's checks (quick_check, the store id), the schema and migrations.
  absl::Status CheckAndMigrate(const std::string& dir);

  sqlite3* db_;
  int lock_fd_;
  const std::string dir_;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_STORE_SQLITE_JOB_STORE_H_
