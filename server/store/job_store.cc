#include "server/store/job_store.h"

#include <sys/random.h>
#include <sys/stat.h>
#include <zlib.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>

#include "absl/strings/escaping.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/store/postgres_job_store.h"
#include "server/result_codec.h"
#include "server/store/sqlite_job_store.h"

namespace cablesim {

absl::StatusOr<std::unique_ptr<JobStore>> JobStore::Open(const std::string& spec,
                                                         const StoreOptions& options) {
  if (absl::StartsWith(spec, "postgresql://") || absl::StartsWith(spec, "postgres://")) {
    absl::StatusOr<std::unique_ptr<PostgresJobStore>> store =
        PostgresJobStore::Open(spec, options);
    if (!store.ok()) return store.status();
    return std::unique_ptr<JobStore>(std::move(*store));
  }
  std::string dir = spec;
  if (absl::StartsWith(dir, "sqlite:")) dir = dir.substr(7);
  if (dir.empty()) {
    return absl::InvalidArgumentError(
        "--store: expected sqlite:DIR or postgresql://[user@]host[:port]/database");
  }
  absl::StatusOr<std::unique_ptr<SqliteJobStore>> store = SqliteJobStore::Open(dir);
  if (!store.ok()) return store.status();
  return std::unique_ptr<JobStore>(std::move(*store));
}

int64_t ResultChecksum(const void* header, size_t header_bytes, const void* vals,
                       size_t vals_bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  crc = crc32_z(crc, static_cast<const Bytef*>(header), header_bytes);
  crc = crc32_z(crc, static_cast<const Bytef*>(vals), vals_bytes);
  return static_cast<int64_t>(crc);
}

absl::StatusOr<std::string> RandomId() {
  unsigned char bytes[16];
  std::ifstream in("/dev/urandom", std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(bytes), sizeof(bytes))) {
    return absl::UnavailableError("cannot read /dev/urandom");
  }
  std::string id;
  for (unsigned char b : bytes) absl::StrAppendFormat(&id, "%02x", b);
  return id;
}

absl::StatusOr<std::string> NewPageTokenSecret() {
  absl::StatusOr<std::string> a = RandomId();
  if (!a.ok()) return a.status();
  absl::StatusOr<std::string> b = RandomId();
  if (!b.ok()) return b.status();
  return absl::StrCat(*a, *b);
}

absl::Status DamagedRow(absl::string_view kind, absl::string_view id) {
  return absl::DataLossError(absl::StrCat(kind, " ", id,
                                          ": the stored row fails its checksum (the database is "
                                          "damaged); cablesim-server --check lists every such row"));
}

absl::StatusOr<StoredResult> CheckedResult(const std::string& id, const std::string& header,
                                           const std::string& vals, int64_t checksum,
                                           int64_t encoding) {
  const absl::Status damaged = absl::DataLossError(absl::StrCat(
      "job ", id, ": the stored result fails its checksum (the database is damaged)"));
  StoredResult result;
  if (ResultChecksum(header.data(), header.size(), vals.data(), vals.size()) != checksum ||
      !result.header.ParseFromString(header)) {
    return damaged;
  }
  absl::StatusOr<std::vector<double>> values =
      DecodeValues(vals, encoding, result.header.columns_size());
  if (!values.ok()) {
    return absl::DataLossError(absl::StrCat("job ", id, ": ", values.status().message(),
                                            " (the database is damaged)"));
  }
  result.values = std::move(*values);
  return result;
}

absl::Status CreateDataDir(const std::string& dir) {
  struct stat st;
  if (::stat(dir.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) return absl::OkStatus();
    return absl::FailedPreconditionError(
        absl::StrCat("the data directory ", dir, " is not a directory"));
  }
  // Parents first (default mode), then the directory itself, private.
  std::string path;
  for (size_t slash = dir.find('/', 1); slash != std::string::npos;
       slash = dir.find('/', slash + 1)) {
    path = dir.substr(0, slash);
    if (::mkdir(path.c_str(), 0755) != 0 && errno != EEXIST) break;
  }
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    return absl::FailedPreconditionError(absl::StrCat("cannot create the data directory ", dir,
                                                      ": ", std::strerror(errno)));
  }
  return absl::OkStatus();
}

std::string JobId(int64_t seq) { return absl::StrFormat("j-%06d", seq); }
std::string SweepId(int64_t seq) { return absl::StrFormat("s-%06d", seq); }

bool IsSweepId(const std::string& id) { return absl::StartsWith(id, "s-"); }

absl::StatusOr<std::string> NewPublicId(char prefix) {
  unsigned char bytes[16];
  if (::getrandom(bytes, sizeof(bytes), 0) != static_cast<ssize_t>(sizeof(bytes))) {
    return absl::UnavailableError(absl::StrCat("getrandom: ", std::strerror(errno)));
  }
  return absl::StrCat(std::string(1, prefix), "-",
                      absl::WebSafeBase64Escape(absl::string_view(
                          reinterpret_cast<const char*>(bytes), sizeof(bytes))));
}

int64_t NowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

absl::Status PeerLimitExceeded(const std::string& peer, int64_t unfinished, int64_t adding,
                               int64_t max_unfinished) {
  return absl::ResourceExhaustedError(absl::StrFormat(
      "this client (%s) has %d jobs queued or running and asks for %d more, the server's "
      "limit is %d (max_queued_jobs_per_peer); try again when some have finished",
      peer, unfinished, adding, max_unfinished));
}

bool IsFinished(v1::JobState state) {
  return state == v1::SUCCEEDED || state == v1::FAILED || state == v1::CANCELLED;
}

}  // namespace cablesim
