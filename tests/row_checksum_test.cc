// Checksummed job and sweep rows (issue 30, item 3): a database with jobs,
// a sweep and results has single bits flipped at offsets spread over the
// whole file; whatever the store still serves (GetJob, ListJobs, GetSweep,
// GetResult) is exactly what it served before the flip, or an error
// (DATA_LOSS for the damaged row; ListJobs leaves the row out, marked as a
// placeholder, and serves the rest). Before row checksums one flip could
// change a summary value or a job's id and be served as if it were true.
// The same for PostgreSQL with rows altered behind the triggers' back.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "server/store/job_store.h"
#include "server/store/sqlite_job_store.h"
#include "tests/postgres_test_util.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

std::string FreshDir(const std::string& name) {
  return testing::ScratchDir("row_checksum_test_" + name);
}

// Everything the store serves, as bytes per call (an error: absent).
struct Served {
  std::map<std::string, std::string> jobs;     // id -> GetJob
  std::map<std::string, std::string> results;  // id -> GetResult values
  std::map<std::string, std::string> sweeps;   // id -> GetSweep
  std::vector<std::string> listed;             // ListJobs (placeholders left out)
  int placeholders = 0;
  int data_loss = 0;
};

Served ServeAll(JobStore* store, const std::vector<std::string>& job_ids,
                const std::vector<std::string>& sweep_ids) {
  Served served;
  for (const std::string& id : job_ids) {
    absl::StatusOr<v1::Job> job = store->GetJob(id);
    if (job.ok()) served.jobs[id] = job->SerializeAsString();
    served.data_loss += absl::IsDataLoss(job.status());
    absl::StatusOr<StoredResult> result = store->GetResult(id);
    if (result.ok()) {
      served.results[id] =
          absl::StrCat(result->header.SerializeAsString(), "|",
                       std::string(reinterpret_cast<const char*>(result->values.data()),
                                   result->values.size() * sizeof(double)));
    }
  }
  for (const std::string& id : sweep_ids) {
    absl::StatusOr<v1::Sweep> sweep = store->GetSweep(id);
    if (sweep.ok()) served.sweeps[id] = sweep->SerializeAsString();
    served.data_loss += absl::IsDataLoss(sweep.status());
  }
  absl::StatusOr<std::vector<v1::Job>> listed =
      store->ListJobs(v1::JOB_STATE_UNSPECIFIED, "", 1000);
  if (listed.ok()) {
    for (const v1::Job& job : *listed) {
      if (job.state() == v1::JOB_STATE_UNSPECIFIED) {
        ++served.placeholders;
      } else {
        served.listed.push_back(job.SerializeAsString());
      }
    }
  }
  return served;
}

// Jobs (finished with summaries and results, one cancelled, one queued)
// and a sweep of three items; their ids.
void Fill(JobStore* store, std::vector<std::string>* job_ids, std::vector<std::string>* sweep_ids) {
  for (int i = 0; i < 8; ++i) {
    v1::Scene scene;
    scene.set_name(absl::StrCat("job-", i));
    absl::StatusOr<v1::Job> job = store->InsertJob(scene, 1.5, "ipv4:127.0.0.1", 1000, "alice");
    ASSERT_TRUE(job.ok()) << job.status();
    job_ids->push_back(job->id());
  }
  v1::SubmitSweepRequest request;
  request.set_name("sweep");
  std::vector<v1::Scene> items(3);
  for (int i = 0; i < 3; ++i) items[i].set_name(absl::StrCat("item-", i));
  absl::StatusOr<v1::Sweep> sweep = store->InsertSweep(request, items, {1, 1, 1});
  ASSERT_TRUE(sweep.ok()) << sweep.status();
  sweep_ids->push_back(sweep->id());
  for (const std::string& id : sweep->job_ids()) job_ids->push_back(id);
  for (size_t k = 0; k + 1 < job_ids->size(); ++k) {
    absl::StatusOr<std::optional<Claim>> claim = store->ClaimNext();
    ASSERT_TRUE(claim.ok() && claim->has_value());
    v1::RunSummary summary;
    summary.set_status("ok");
    summary.set_frames(100 + k);
    summary.set_steps(1000 + k);
    summary.set_failure_time_s(0.25 * k);
    StoredResult result;
    result.header.add_columns("t");
    result.header.add_columns("x");
    for (int r = 0; r < 50; ++r) {
      result.values.push_back(0.01 * r);
      result.values.push_back(std::sin(0.1 * r + k));
    }
    ASSERT_TRUE(*store->Finish((*claim)->id, k == 3 ? v1::FAILED : v1::SUCCEEDED, summary,
                               result));
  }
}

TEST(RowChecksumTest, SingleBitFlipsAcrossTheSqliteFileServeNothingAltered) {
  const std::string dir = FreshDir("flips");
  std::vector<std::string> job_ids, sweep_ids;
  {
    absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open("sqlite:" + dir);
    ASSERT_TRUE(store.ok()) << store.status();
    Fill(store->get(), &job_ids, &sweep_ids);
  }
  Served baseline;
  {
    absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open("sqlite:" + dir);
    ASSERT_TRUE(store.ok()) << store.status();
    baseline = ServeAll(store->get(), job_ids, sweep_ids);
    ASSERT_EQ(baseline.jobs.size(), job_ids.size());
    ASSERT_EQ(baseline.listed.size(), job_ids.size());
    ASSERT_EQ(baseline.placeholders, 0);
    EXPECT_TRUE(store->get()->CheckRows()->empty());
  }
  const std::string db = dir + "/cablesim.db";
  std::ifstream in(db, std::ios::binary);
  const std::string original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(original.size(), 4096u);
  // Offsets spread evenly over the file (every page hit), then inside
  // every stored copy of the rows' served values (ids, names, tenant,
  // summaries: in the table and in its indexes), bits varied.
  std::vector<size_t> offsets;
  for (int f = 0; f < 240; ++f) offsets.push_back((original.size() - 1) * f / 239);
  std::vector<std::string> needles = {"alice", "sweep", "ipv4:127.0.0.1"};
  for (const std::string& id : job_ids) needles.push_back(id);
  for (const std::string& id : sweep_ids) needles.push_back(id);
  for (const auto& [id, bytes] : baseline.jobs) {
    v1::Job job;
    job.ParseFromString(bytes);
    needles.push_back(job.name());
    if (job.has_summary()) needles.push_back(job.summary().SerializeAsString());
  }
  for (const std::string& needle : needles) {
    for (size_t at = original.find(needle); at != std::string::npos;
         at = original.find(needle, at + 1)) {
      offsets.push_back(at + needle.size() / 2);
      offsets.push_back(at + needle.size() - 1);
    }
  }
  const int kFlips = static_cast<int>(offsets.size());
  int detected = 0, refused = 0;
  const std::string copy = FreshDir("flip_copy");
  for (int f = 0; f < kFlips; ++f) {
    const size_t offset = offsets[f];
    std::filesystem::remove_all(copy);
    std::filesystem::copy(dir, copy);
    std::string damaged = original;
    damaged[offset] = static_cast<char>(damaged[offset] ^ (1 << (f % 8)));
    std::ofstream(copy + "/cablesim.db", std::ios::binary | std::ios::trunc) << damaged;
    absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open("sqlite:" + copy);
    if (!store.ok()) {  // SQLite's own check saw the damage: nothing served
      ++refused;
      continue;
    }
    const Served served = ServeAll(store->get(), job_ids, sweep_ids);
    for (const auto& [id, bytes] : served.jobs) {
      EXPECT_EQ(bytes, baseline.jobs.at(id)) << "GetJob " << id << " altered, flip at " << offset;
    }
    for (const auto& [id, bytes] : served.results) {
      EXPECT_EQ(bytes, baseline.results.at(id)) << "GetResult " << id << ", flip at " << offset;
    }
    for (const auto& [id, bytes] : served.sweeps) {
      EXPECT_EQ(bytes, baseline.sweeps.at(id)) << "GetSweep " << id << ", flip at " << offset;
    }
    for (const std::string& bytes : served.listed) {
      EXPECT_NE(std::find(baseline.listed.begin(), baseline.listed.end(), bytes),
                baseline.listed.end())
          << "ListJobs served an altered job, flip at " << offset;
    }
    const bool seen = served.data_loss > 0 || served.placeholders > 0;
    detected += seen;
    if (seen) {
      absl::StatusOr<std::vector<std::string>> report = store->get()->CheckRows();
      ASSERT_TRUE(report.ok()) << report.status();
      EXPECT_FALSE(report->empty()) << "--check missed the damage at " << offset;
    }
  }
  std::cerr << "[ flips ] " << kFlips << " flips over " << original.size() << " bytes: "
            << detected << " caught by row or result checksums, " << refused
            << " refused at open (SQLite's check)\n";
  EXPECT_GT(detected, 0);
}

// A database written before row checksums (no row_sum column, no
// triggers) opens, gains them, and serves its jobs as before.
TEST(RowChecksumTest, ADatabaseFromBeforeRowChecksumsMigrates) {
  const std::string dir = FreshDir("migrate");
  std::vector<std::string> job_ids, sweep_ids;
  Served before;
  {
    absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open("sqlite:" + dir);
    ASSERT_TRUE(store.ok()) << store.status();
    Fill(store->get(), &job_ids, &sweep_ids);
    before = ServeAll(store->get(), job_ids, sweep_ids);
  }
  // Back to main's schema: the triggers and the column gone.
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir + "/cablesim.db").c_str(), &db), SQLITE_OK);
    for (const char* sql :
         {"DROP TRIGGER jobs_row_sum_insert", "DROP TRIGGER jobs_row_sum_update",
          "DROP TRIGGER sweeps_row_sum_insert", "DROP TRIGGER sweeps_row_sum_update",
          "ALTER TABLE jobs DROP COLUMN row_sum", "ALTER TABLE sweeps DROP COLUMN row_sum"}) {
      char* error = nullptr;
      EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, &error), SQLITE_OK) << sql << ": " << error;
      sqlite3_free(error);
    }
    sqlite3_close(db);
  }
  absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open("sqlite:" + dir);
  ASSERT_TRUE(store.ok()) << store.status();
  const Served after = ServeAll(store->get(), job_ids, sweep_ids);
  EXPECT_EQ(after.jobs, before.jobs);
  EXPECT_EQ(after.listed, before.listed);
  EXPECT_EQ(after.sweeps, before.sweeps);
  EXPECT_TRUE(store->get()->CheckRows()->empty());
}

// PostgreSQL: rows altered behind the triggers' back (as a flipped bit
// in a data file would be) are DATA_LOSS, left out of ListJobs, and
// listed by CheckRows; the others are served as before.
TEST(RowChecksumTest, AlteredPostgresRowsAreNotServed) {
  CABLESIM_POSTGRES_URL_OR_SKIP(url, "row_sums");
  ASSERT_FALSE(url.empty());
  std::vector<std::string> job_ids, sweep_ids;
  absl::StatusOr<std::unique_ptr<JobStore>> store = JobStore::Open(url);
  ASSERT_TRUE(store.ok()) << store.status();
  Fill(store->get(), &job_ids, &sweep_ids);
  const Served before = ServeAll(store->get(), job_ids, sweep_ids);
  ASSERT_EQ(before.listed.size(), job_ids.size());
  EXPECT_TRUE(store->get()->CheckRows()->empty());
  PGconn* conn = PQconnectdb(url.c_str());
  ASSERT_EQ(PQstatus(conn), CONNECTION_OK);
  const std::string alter = absl::StrCat(
      "ALTER TABLE jobs DISABLE TRIGGER jobs_row_sum; ALTER TABLE sweeps DISABLE TRIGGER "
      "sweeps_row_sum; "
      "UPDATE jobs SET summary = set_byte(summary, 3, get_byte(summary, 3) # 4) WHERE pid = '",
      job_ids[0], "'; UPDATE jobs SET pid = pid || 'x' WHERE pid = '", job_ids[1],
      "'; UPDATE sweeps SET name = 'swoop' WHERE pid = '", sweep_ids[0],
      "'; ALTER TABLE jobs ENABLE TRIGGER jobs_row_sum; "
      "ALTER TABLE sweeps ENABLE TRIGGER sweeps_row_sum");
  PGresult* r = PQexec(conn, alter.c_str());
  ASSERT_EQ(PQresultStatus(r), PGRES_COMMAND_OK) << PQerrorMessage(conn);
  PQclear(r);
  PQfinish(conn);
  EXPECT_TRUE(absl::IsDataLoss(store->get()->GetJob(job_ids[0]).status()));
  EXPECT_TRUE(absl::IsNotFound(store->get()->GetJob(job_ids[1]).status()));  // its id changed
  EXPECT_TRUE(absl::IsDataLoss(store->get()->GetSweep(sweep_ids[0]).status()));
  EXPECT_TRUE(absl::IsDataLoss(store->get()->Tenant(job_ids[0]).status()));
  const Served after = ServeAll(store->get(), job_ids, sweep_ids);
  // The two jobs, and the sweep's three items (served with its id).
  EXPECT_EQ(after.placeholders, 5);
  EXPECT_EQ(after.listed.size(), job_ids.size() - 5);
  for (const std::string& bytes : after.listed) {
    EXPECT_NE(std::find(before.listed.begin(), before.listed.end(), bytes), before.listed.end());
  }
  absl::StatusOr<std::vector<std::string>> report = store->get()->CheckRows();
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_EQ(report->size(), 3u) << ::testing::PrintToString(*report);
  // A later update of a damaged row (a cancel, a finish) does not bless it.
  EXPECT_TRUE(absl::IsDataLoss(store->get()->GetJob(job_ids[0]).status()));
}

}  // namespace
}  // namespace cablesim
