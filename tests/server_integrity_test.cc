// The job store's integrity against a real cablesim-server: a stored result
// altered on disk is DATA_LOSS, never served; a damaged, emptied or
// replaced database is refused at start-up; the single-server lock cannot
// be removed; the data is private (0700 / 0600).

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "absl/strings/escaping.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::Pendulum;
using testing::ServerProcess;

// A server on a fresh directory that has run one job to the end and was
// stopped; returns the job id.
std::string OneFinishedJob(const std::string& dir) {
  // (No grace period for calls at shutdown: none is left.)
  ServerProcess server(dir, {"--workers=1", "--shutdown-grace-s=0"});
  auto stub = server.Stub();
  grpc::ClientContext context;
  v1::SubmitJobRequest submit;
  *submit.mutable_scene() = Pendulum(0.05, 1e-3, 1e-2);
  v1::Job job;
  EXPECT_TRUE(stub->SubmitJob(&context, submit, &job).ok());
  EXPECT_EQ(testing::WaitForJob(stub.get(), job.id()), v1::SUCCEEDED);
  stub.reset();
  EXPECT_EQ(server.Kill(SIGTERM), 0);  // exit 0: the database closed cleanly
  return job.id();
}

// Flips one byte of every stored trajectory in DIR/cablesim.db (the
// server stopped): a valid database still, that only a checksum can tell.
void FlipAByteOfEachResult(const std::string& dir) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(absl::StrCat(dir, "/cablesim.db").c_str(), &db), SQLITE_OK);
  std::vector<std::pair<int64_t, std::string>> rows;
  sqlite3_stmt* read = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT job_seq, vals FROM results", -1, &read, nullptr),
            SQLITE_OK);
  while (sqlite3_step(read) == SQLITE_ROW) {
    rows.emplace_back(sqlite3_column_int64(read, 0),
                      std::string(static_cast<const char*>(sqlite3_column_blob(read, 1)),
                                  sqlite3_column_bytes(read, 1)));
  }
  sqlite3_finalize(read);
  ASSERT_FALSE(rows.empty());
  for (auto& [seq, vals] : rows) {
    vals[vals.size() / 2] ^= 0x10;
    sqlite3_stmt* write = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE results SET vals = ?1 WHERE job_seq = ?2", -1, &write,
                                 nullptr),
              SQLITE_OK);
    sqlite3_bind_blob(write, 1, vals.data(), static_cast<int>(vals.size()), SQLITE_TRANSIENT);
    sqlite3_bind_int64(write, 2, seq);
    EXPECT_EQ(sqlite3_step(write), SQLITE_DONE);
    sqlite3_finalize(write);
  }
  sqlite3_close(db);
}

TEST(ServerIntegrityTest, AnAlteredResultIsDataLossNeverServed) {
  const std::string dir = testing::FreshDir("integrity_altered");
  const std::string id = OneFinishedJob(dir);
  FlipAByteOfEachResult(dir);
  ServerProcess server(dir);
  auto stub = server.Stub();
  const testing::JobResultRead read = testing::ReadJobResult(stub.get(), id);
  EXPECT_EQ(read.status.error_code(), grpc::StatusCode::DATA_LOSS);
  EXPECT_THAT(read.status.error_message(), HasSubstr("checksum"));
  EXPECT_EQ(read.rows, 0);
  {
    grpc::ClientContext context;
    v1::EnergyRequest energy;
    energy.set_job_id(id);
    v1::EnergyResponse response;
    EXPECT_EQ(stub->GetEnergy(&context, energy, &response).error_code(),
              grpc::StatusCode::DATA_LOSS);
  }
  // The job itself is still listed.
  grpc::ClientContext context;
  v1::GetJobRequest get;
  get.set_id(id);
  v1::Job job;
  ASSERT_TRUE(stub->GetJob(&context, get, &job).ok());
  EXPECT_EQ(job.state(), v1::SUCCEEDED);
}

TEST(ServerIntegrityTest, ADamagedDatabaseIsRefused) {
  const std::string dir = testing::FreshDir("integrity_damaged");
  OneFinishedJob(dir);
  // Every page after the first (the schema) overwritten.
  const std::string path = dir + "/cablesim.db";
  const auto size = std::filesystem::file_size(path);
  ASSERT_GT(size, 4096u);
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(4096);
    const std::string junk(size - 4096, '\xa5');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  }
  std::string log;
  EXPECT_EQ(testing::StartRefused(dir, &log), 1);
  EXPECT_THAT(log, HasSubstr("damaged"));
}

TEST(ServerIntegrityTest, AnEmptiedDatabaseIsRefusedNotStartedAfresh) {
  const std::string dir = testing::FreshDir("integrity_emptied");
  OneFinishedJob(dir);
  std::filesystem::resize_file(dir + "/cablesim.db", 0);
  std::string log;
  EXPECT_EQ(testing::StartRefused(dir, &log), 1);
  EXPECT_THAT(log, HasSubstr("lost its schema and jobs"));
  // Nor is another store's database taken for this one.
  const std::string other = testing::FreshDir("integrity_other");
  OneFinishedJob(other);
  std::filesystem::copy_file(other + "/cablesim.db", dir + "/cablesim.db",
                             std::filesystem::copy_options::overwrite_existing);
  EXPECT_EQ(testing::StartRefused(dir, &log), 1);
  EXPECT_THAT(log, HasSubstr("belongs to another store"));
}

TEST(ServerIntegrityTest, TheSingleServerLockCannotBeRemoved) {
  const std::string dir = testing::FreshDir("integrity_lock");
  ServerProcess first(dir);
  // Whatever files a careless operator deletes (the lock used to be a
  // separate file, DIR/lock), the second server is refused.
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name != "cablesim.db" && name != "cablesim.db-wal" && name != "cablesim.db-shm") {
      std::filesystem::remove_all(entry.path());
    }
  }
  std::string log;
  EXPECT_EQ(testing::StartRefused(dir, &log), 1);
  EXPECT_THAT(log, HasSubstr("in use by another cablesim-server"));
}

TEST(ServerIntegrityTest, ADatabaseFromBeforeIsUpgradedAndKeepsItsIds) {
  // The schema of the last release (no checksums, peers, tenants or
  // random ids) with one finished job and its two-row result.
  const std::string dir = testing::FreshDir("integrity_upgrade");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir + "/cablesim.db").c_str(), &db), SQLITE_OK);
  v1::RunHeader header;
  header.add_columns("t");
  header.add_columns("x");
  const std::string header_blob = header.SerializeAsString();
  v1::RunSummary summary;
  summary.set_status("ok");
  const std::string summary_blob = summary.SerializeAsString();
  const double vals[] = {0.0, 1.0, 0.5, 2.0};
  const std::string sql = absl::StrCat(R"sql(
CREATE TABLE sweeps (seq INTEGER PRIMARY KEY AUTOINCREMENT, name TEXT NOT NULL,
  axes BLOB NOT NULL, created_ms INTEGER NOT NULL);
CREATE TABLE jobs (seq INTEGER PRIMARY KEY AUTOINCREMENT, state INTEGER NOT NULL,
  name TEXT NOT NULL, scene BLOB NOT NULL, end_time_s REAL NOT NULL, created_ms INTEGER NOT NULL,
  started_ms INTEGER NOT NULL DEFAULT 0, finished_ms INTEGER NOT NULL DEFAULT 0,
  attempts INTEGER NOT NULL DEFAULT 0, summary BLOB, sweep_seq INTEGER NOT NULL DEFAULT 0,
  sweep_index INTEGER NOT NULL DEFAULT 0);
CREATE TABLE results (job_seq INTEGER PRIMARY KEY REFERENCES jobs(seq), header BLOB NOT NULL,
  vals BLOB NOT NULL);
INSERT INTO jobs (state, name, scene, end_time_s, created_ms, finished_ms, attempts, summary)
  VALUES (3, 'old', x'', 1.0, 1, 2, 1, x')sql",
                                       absl::BytesToHexString(summary_blob), R"sql(');
INSERT INTO results (job_seq, header, vals) VALUES (1, x')sql",
                                       absl::BytesToHexString(header_blob), "', x'",
                                       absl::BytesToHexString(absl::string_view(
                                           reinterpret_cast<const char*>(vals), sizeof(vals))),
                                       "');");
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << error;
  sqlite3_close(db);

  ServerProcess server(dir);
  auto stub = server.Stub();
  grpc::ClientContext context;
  v1::GetJobRequest get;
  get.set_id("j-000001");
  v1::Job job;
  const grpc::Status s = stub->GetJob(&context, get, &job);
  ASSERT_TRUE(s.ok()) << s.error_message();
  EXPECT_EQ(job.state(), v1::SUCCEEDED);
  EXPECT_EQ(job.name(), "old");
  const testing::JobResultRead read = testing::ReadJobResult(stub.get(), "j-000001");
  EXPECT_TRUE(read.status.ok()) << read.status.error_message();
  EXPECT_EQ(read.rows, 2);
  // New jobs get random ids beside it.
  grpc::ClientContext submit_context;
  v1::SubmitJobRequest submit;
  *submit.mutable_scene() = Pendulum(0.01, 1e-3, 1e-3);
  v1::Job fresh;
  ASSERT_TRUE(stub->SubmitJob(&submit_context, submit, &fresh).ok());
  EXPECT_THAT(fresh.id(), ::testing::MatchesRegex("j-[A-Za-z0-9_-]{22}"));
}

TEST(ServerIntegrityTest, TheDataIsPrivate) {
  const std::string dir = testing::FreshDir("integrity_private");
  std::filesystem::permissions(dir, std::filesystem::perms::all);  // 0777 to start with
  ServerProcess server(dir);
  auto mode = [](const std::string& path) {
    struct stat st {};
    EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
    return st.st_mode & 0777;
  };
  EXPECT_EQ(mode(dir), 0700u);
  for (const char* file : {"cablesim.db", "cablesim.db-wal", "cablesim.db-shm", "store-id"}) {
    EXPECT_EQ(mode(absl::StrCat(dir, "/", file)), 0600u) << file;
  }
}

}  // namespace
}  // namespace cablesim
