#ifndef CABLESIM_TESTS_POSTGRES_TEST_UTIL_H_
#define CABLESIM_TESTS_POSTGRES_TEST_UTIL_H_

// A real PostgreSQL server for the tests, started by the test itself:
// `initdb` into a temporary directory and `pg_ctl start` on 127.0.0.1 at a
// free port (trust authentication, reachable from loopback only), stopped
// with `pg_ctl stop -m immediate` and removed at the end. One server per
// test process, each test a fresh database; initdb (seconds) runs once per
// machine into a template cluster that each server copies.
//
// The binaries: $CABLESIM_PG_BINDIR, else `pg_config --bindir`, else the
// newest /usr/lib/postgresql/*/bin (Debian). When none is installed the
// tests are skipped, saying so; deploy/install-deps.sh installs them, so
// CI runs them. PostgreSQL refuses to run as root: as root the commands
// run as the `postgres` user (Debian's package creates it).

#include <arpa/inet.h>
#include <fcntl.h>
#include <sys/file.h>
#include <libpq-fe.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <pwd.h>

#include <atomic>
#include <iostream>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"

namespace cablesim::testing {

class TestPostgres {
 public:
  // The binary's server, started at the first call; null (and `why` says
  // why) when PostgreSQL is not installed or cannot start.
  static TestPostgres* Get(std::string* why) {
    static std::string* reason = new std::string();
    static TestPostgres* server = [] {
      auto* s = new TestPostgres();
      if (!s->Start(reason)) {
        delete s;
        return static_cast<TestPostgres*>(nullptr);
      }
      std::atexit([] { delete server; });
      return s;
    }();
    *why = *reason;
    return server;
  }

  ~TestPostgres() {
    if (started_) Run(absl::StrCat(bin_, "/pg_ctl -D '", dir_, "/data' -m immediate stop"));
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  // Call before the first Get: the server flushes every commit to disk
  // (fsync on, PostgreSQL's default), for benchmarks comparing with
  // SQLite's synchronous=FULL. The tests leave it off.
  static bool& durable() {
    static bool on = false;
    return on;
  }

  // Whether Get's reason is that PostgreSQL is not installed (the only
  // reason to skip; any other is a failure).
  static bool NotInstalled(const std::string& why) {
    return why.rfind(kNotInstalled, 0) == 0;
  }

  int port() const { return port_; }
  // A fresh empty database; its URL ("" when it cannot be made).
  std::string NewDatabase(const std::string& prefix) {
    static std::atomic<int> counter{0};
    const std::string name = absl::StrCat(prefix, "_", ::getpid(), "_", counter++);
    PGconn* conn = PQconnectdb(Url("postgres").c_str());
    PGresult* r = PQexec(conn, absl::StrCat("CREATE DATABASE \"", name, "\"").c_str());
    const bool ok = PQresultStatus(r) == PGRES_COMMAND_OK;
    if (!ok) std::cerr << "CREATE DATABASE " << name << ": " << PQerrorMessage(conn) << "\n";
    PQclear(r);
    PQfinish(conn);
    return ok ? Url(name) : "";
  }
  std::string Url(const std::string& database) const {
    return absl::StrCat("postgresql://cablesim@127.0.0.1:", port_, "/", database);
  }

 private:
  TestPostgres() = default;
  static constexpr char kNotInstalled[] = "PostgreSQL is not installed";

  // The tests' temporary directory (gtest's TEST_TMPDIR, else the
  // system's), without a test framework, so that benchmarks can use this.
  static std::string TempDir() {
    if (const char* t = std::getenv("TEST_TMPDIR"); t && *t) return t;
    return std::filesystem::temp_directory_path().string();
  }

  static std::string Output(const std::string& command) {
    std::string out;
    if (FILE* p = ::popen(command.c_str(), "r")) {
      char buffer[512];
      while (std::fgets(buffer, sizeof(buffer), p) != nullptr) out += buffer;
      ::pclose(p);
    }
    return std::string(absl::StripAsciiWhitespace(out));
  }

  // `command` as the user PostgreSQL runs as; true on exit status 0.
  bool Run(const std::string& command) const {
    const std::string as = ::geteuid() == 0 ? "runuser -u postgres -- " : "";
    return std::system(absl::StrCat(as, command, " >> '", dir_, "/setup.log' 2>&1").c_str()) == 0;
  }

  static std::string FindBinaries() {
    if (const char* env = std::getenv("CABLESIM_PG_BINDIR"); env && *env) return env;
    const std::string configured = Output("pg_config --bindir 2>/dev/null");
    if (!configured.empty() && std::filesystem::exists(configured + "/initdb")) return configured;
    std::string best;
    std::error_code ignored;
    for (const auto& entry : std::filesystem::directory_iterator("/usr/lib/postgresql", ignored)) {
      const std::string bin = entry.path().string() + "/bin";
      if (std::filesystem::exists(bin + "/initdb") && bin > best) best = bin;
    }
    return best;
  }

  static int FreePort() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof(addr);
    ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr));
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
    ::close(fd);
    return ntohs(addr.sin_port);
  }

  bool Start(std::string* why) {
    bin_ = FindBinaries();
    if (bin_.empty()) {
      *why = absl::StrCat(kNotInstalled,
                          " (no initdb under pg_config --bindir or /usr/lib/postgresql/*/bin): "
                          "install it with deploy/install-deps.sh");
      return false;
    }
    if (::geteuid() == 0 && ::getpwnam("postgres") == nullptr) {
      *why = "running as root, and there is no user `postgres` to run PostgreSQL as";
      return false;
    }
    dir_ = absl::StrCat(TempDir(), "/cablesim_pg_", ::getpid());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    if (::geteuid() == 0) {
      std::system(absl::StrCat("chown postgres '", dir_, "'").c_str());
    }
    port_ = FreePort();
    // initdb takes seconds, and CTest runs every test in a process of its
    // own: one cluster made by initdb is kept as a template (made once,
    // under a lock) and copied for each server.
    const std::string templ = absl::StrCat(TempDir(), "/cablesim_pg_template_",
                                           std::hash<std::string>()(bin_), "_", ::geteuid());
    {
      const int lock = ::open((templ + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
      ::flock(lock, LOCK_EX);
      if (!std::filesystem::exists(templ + "/PG_VERSION")) {
        std::filesystem::remove_all(templ + ".tmp");
        std::filesystem::create_directories(templ + ".tmp");
        if (::geteuid() == 0) std::system(absl::StrCat("chown postgres '", templ, ".tmp'").c_str());
        if (!Run(absl::StrCat(bin_, "/initdb -D '", templ,
                              ".tmp' -U cablesim --auth=trust -E UTF8 --no-sync"))) {
          ::close(lock);
          *why = absl::StrCat("initdb failed (see ", dir_, "/setup.log)");
          return false;
        }
        std::filesystem::rename(templ + ".tmp", templ);
      }
      ::close(lock);
    }
    if (!Run(absl::StrCat("cp -a '", templ, "' '", dir_, "/data'"))) {
      *why = absl::StrCat("copying the initdb template ", templ, " failed");
      return false;
    }
    // fsync off unless durable(): what the tests test is cablesim's use
    // of the database, not PostgreSQL's own crash safety (no test kills
    // PostgreSQL).
    if (!Run(absl::StrCat(bin_, "/pg_ctl -D '", dir_, "/data' -l '", dir_,
                          "/postgres.log' -w -t 60 -o \"-p ", port_, " -k '", dir_,
                          "' -c listen_addresses=127.0.0.1 -c fsync=", durable() ? "on" : "off",
                          " "
                          "-c max_connections=300\" start"))) {
      *why = absl::StrCat("pg_ctl start failed (see ", dir_, "/setup.log and postgres.log)");
      return false;
    }
    started_ = true;
    std::cerr << "[ postgres ] " << bin_ << " on 127.0.0.1:" << port_ << " (" << dir_ << ")\n";
    return true;
  }

  std::string bin_, dir_;
  int port_ = 0;
  bool started_ = false;
};

// In a GoogleTest test: the URL of a fresh database, or GTEST_SKIP with
// the reason when PostgreSQL is not installed (any other reason fails).
#define CABLESIM_POSTGRES_URL_OR_SKIP(url, prefix)                                       \
  std::string url;                                                                       \
  {                                                                                      \
    std::string why;                                                                     \
    ::cablesim::testing::TestPostgres* pg = ::cablesim::testing::TestPostgres::Get(&why); \
    if (pg == nullptr && ::cablesim::testing::TestPostgres::NotInstalled(why)) {         \
      GTEST_SKIP() << "PostgreSQL tests skipped: " << why;                               \
    }                                                                                    \
    if (pg == nullptr) FAIL() << "PostgreSQL is installed but cannot start: " << why;    \
    url = pg->NewDatabase(prefix);                                                       \
  }

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_POSTGRES_TEST_UTIL_H_
