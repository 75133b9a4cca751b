// cablesim-server: the cablesim gRPC service (proto/cablesim/v1/service.proto).
//
//   cablesim-server --listen 127.0.0.1:50051 --data-dir DIR [--workers N]
//   cablesim-server --listen ... --store postgresql://USER@HOST:PORT/DB
//
// Jobs and results live in SQLite under DIR (created when missing), or in
// a PostgreSQL database that several servers share. SIGTERM or SIGINT shuts down
// gracefully: running jobs stop at their next step and stay queued for the
// next start. Logs go to stderr. With --port-file, the port actually bound
// (useful with port 0) is written to that file once the server serves.

#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <fstream>
#include <iostream>
#include <iterator>
#include <utility>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/reflection.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "absl/strings/ascii.h"
#include "cablesim/version.h"
#include "server/cablesim_server.h"
#include "server/listen_address.h"
#include "server/metrics_endpoint.h"

ABSL_FLAG(std::string, listen, "127.0.0.1:50051", "host:port to listen on (port 0: any free)");
ABSL_FLAG(std::string, data_dir, "",
          "directory of the job database (SQLite, created when missing); the same as "
          "--store sqlite:DIR");
ABSL_FLAG(std::string, store, "",
          "the job store: sqlite:DIR (one server) or postgresql://USER@HOST:PORT/DB (shared by "
          "any number of servers; libpq URL, PGPASSWORD or ~/.pgpass for a password)");
ABSL_FLAG(double, lease_s, 10,
          "shared store: a job whose server sent no heartbeat for this long is taken again");
ABSL_FLAG(int, workers, 0, "job worker threads (0: the number of cores)");
ABSL_FLAG(std::string, port_file, "", "write the bound port to this file once serving");
ABSL_FLAG(std::string, tls_cert, "", "TLS: the server's certificate chain (PEM file)");
ABSL_FLAG(std::string, tls_key, "", "TLS: the server's private key (PEM file)");
ABSL_FLAG(std::string, tls_client_ca, "",
          "TLS: clients must present a certificate signed by this CA (PEM file; mutual TLS)");
ABSL_FLAG(std::string, token_file, "",
          "bearer tokens a client must send, one \"TOKEN TENANT\" per line (# comments)");
ABSL_FLAG(bool, insecure, false,
          "allow listening beyond loopback without TLS and tokens (never on a shared network)");
ABSL_FLAG(std::string, metrics_listen, "",
          "serve Prometheus metrics (GET /metrics, plain HTTP) on this IPv4 host:port (empty: off)");
ABSL_FLAG(int, max_elements, 5000, "limit: cable elements per scene");
ABSL_FLAG(int64_t, max_steps, 5'000'000, "limit: time steps (or load steps) per run");
ABSL_FLAG(int64_t, max_frames, 200'000, "limit: output frames per run");
ABSL_FLAG(int64_t, max_trajectory_values, 32 << 20, "limit: frames x columns kept per run");
ABSL_FLAG(int, max_sweep_items, 1000, "limit: items per sweep");
ABSL_FLAG(int, max_streams, 64, "limit: concurrent Run streams");
ABSL_FLAG(int, max_streams_per_peer, 16,
          "limit: concurrent Run streams of one client address");
ABSL_FLAG(int64_t, max_queued_jobs_per_peer, 1000,
          "limit: jobs (sweep items included) one client address has queued or running");
ABSL_FLAG(int, max_modes, 200, "limit: MODAL modes per run");
ABSL_FLAG(int64_t, max_modal_bytes, int64_t{1} << 30,
          "limit: estimated memory of a MODAL run's modes (8 x dofs x (3 modes + 1) bytes)");
ABSL_FLAG(int64_t, max_name_bytes, 256,
          "limit: bytes of any string in a request (names, sweep paths); names are also "
          "bounded by the scene format (256)");
ABSL_FLAG(int64_t, max_coordinates, 1'000'000, "limit: coordinates of a scene's model");
ABSL_FLAG(int, max_message_bytes, 16 << 20, "limit: gRPC message size");
ABSL_FLAG(int, max_unary_calls, cablesim::DefaultServerLimits().max_unary_calls,
          "limit: scene-carrying unary calls (Validate, SubmitJob, SubmitSweep) at once");
ABSL_FLAG(int, max_unary_calls_per_peer,
          cablesim::DefaultServerLimits().max_unary_calls_per_peer,
          "limit: scene-carrying unary calls at once of one client (tenant or address)");
ABSL_FLAG(int64_t, max_inflight_bytes, cablesim::DefaultServerLimits().max_inflight_bytes,
          "limit: memory budget of the requests in flight, each counted as 20 x its size "
          "(the parsed scene and the model built from it)");
ABSL_FLAG(int64_t, max_work_units, cablesim::DefaultServerLimits().max_work_units,
          "limit: a run's work, steps x (elements x Gauss points x (1 + wave components) + "
          "contact points + sheave wraps)");
ABSL_FLAG(double, retention_max_age_s, 0,
          "delete finished jobs and sweeps this many seconds after they finished (0: keep)");
ABSL_FLAG(int64_t, retention_max_bytes, 0,
          "delete the oldest finished jobs and sweeps while stored results take more bytes "
          "than this (0: no limit)");
ABSL_FLAG(double, stall_timeout_s, 30, "cancel a stream whose client reads nothing this long");
ABSL_FLAG(std::string, check, "",
          "check every stored row of this store (DIR, sqlite:DIR or postgresql://...) against its "
          "checksum, list the damaged ones and exit: 0 when none is, 1 otherwise (a SQLite "
          "store only while no server has it open)");
ABSL_FLAG(double, shutdown_grace_s, 2,
          "on SIGTERM, wait this long for calls (and idle client connections) to end");

namespace {

constexpr char kUsage[] =
    "Usage: cablesim-server --listen HOST:PORT --data-dir DIR [--workers N] [--LIMIT N ...]\n"
    "       cablesim-server --listen HOST:PORT --store sqlite:DIR|postgresql://... [...]\n"
    "\n"
    "The cablesim gRPC service (proto/cablesim/v1/service.proto): runs, durable jobs\n"
    "and sweeps, with the jobs in SQLite under DIR (created when missing), or in a\n"
    "PostgreSQL database shared by any number of servers. Flags may be written\n"
    "--data-dir or --data_dir, --flag=value or --flag value.\n"
    "\n"
    "Exit status: 0 after SIGTERM or SIGINT (running jobs stay queued) and for\n"
    "--help and --version, 1 when the server cannot start (address in use, data\n"
    "directory or database unusable), 2 for a usage error.\n";

// The flags of this file, sorted, as --help lists them.
void PrintHelp(std::ostream& out) {
  out << kUsage << "\nFlags:\n";
  std::vector<const absl::CommandLineFlag*> flags;
  for (const auto& [name, flag] : absl::GetAllFlags()) {
    if (absl::StrContains(flag->Filename(), "cablesim_server_main")) flags.push_back(flag);
  }
  std::sort(flags.begin(), flags.end(),
            [](const auto* a, const auto* b) { return a->Name() < b->Name(); });
  for (const absl::CommandLineFlag* flag : flags) {
    std::string name(flag->Name());
    std::replace(name.begin(), name.end(), '_', '-');
    out << "  --" << name << "  " << flag->Help() << " (default: " << flag->DefaultValue()
        << ")\n";
  }
}

int UsageError(const std::string& message) {
  std::cerr << "cablesim-server: " << message << "\n" << kUsage;
  return 2;
}

// Sets the flags from the command line. Done here rather than with
// absl::ParseCommandLine, which exits with status 1 for --help and for a
// usage error alike. Returns the exit code when the program should stop.
std::optional<int> ParseFlags(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h" || arg == "-help" || arg == "--helpfull") {
      PrintHelp(std::cout);
      return 0;
    }
    if (arg == "--version" || arg == "-version") {
      std::cout << cablesim::VersionLine("cablesim-server") << "\n";
      return 0;
    }
    if (arg.size() < 3 || arg.rfind("--", 0) != 0) {
      return UsageError(absl::StrCat("unexpected argument \"", arg, "\""));
    }
    std::string name = arg.substr(2);
    std::optional<std::string> value;
    if (const size_t eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name.resize(eq);
    }
    std::replace(name.begin(), name.end(), '-', '_');  // --data-dir is --data_dir
    absl::CommandLineFlag* flag = absl::FindCommandLineFlag(name);
    if (flag == nullptr || !absl::StrContains(flag->Filename(), "cablesim_server_main")) {
      return UsageError(absl::StrCat("unknown flag ", arg));
    }
    if (!value.has_value()) {
      if (i + 1 >= argc) return UsageError(absl::StrCat(arg, " needs a value"));
      value = argv[++i];
    }
    std::string error;
    if (!flag->ParseFrom(*value, &error)) {
      return UsageError(absl::StrCat("--", name, ": ", error));
    }
  }
  return std::nullopt;
}

// --check STORE: every damaged row listed; 0 when none, 1 otherwise.
int CheckStore(const std::string& spec) {
  cablesim::StoreOptions options;
  options.notifications = false;
  absl::StatusOr<std::unique_ptr<cablesim::JobStore>> store =
      cablesim::JobStore::Open(spec, options);
  if (!store.ok()) {
    std::cerr << "cablesim-server: --check " << spec << ": " << store.status().message() << "\n";
    return 1;
  }
  absl::StatusOr<std::vector<std::string>> damaged = (*store)->CheckRows();
  if (!damaged.ok()) {
    std::cerr << "cablesim-server: --check " << spec << ": " << damaged.status().message()
              << "\n";
    return 1;
  }
  for (const std::string& line : *damaged) std::cout << "damaged: " << line << "\n";
  std::cout << (*store)->Describe() << ": " << damaged->size() << " damaged rows\n";
  return damaged->empty() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (const std::optional<int> exit_code = ParseFlags(argc, argv)) return *exit_code;
  if (const std::string check = absl::GetFlag(FLAGS_check); !check.empty()) {
    return CheckStore(check);
  }
  cablesim::ServerOptions options;
  options.listen = absl::GetFlag(FLAGS_listen);
  options.data_dir = absl::GetFlag(FLAGS_data_dir);
  const std::string store = absl::GetFlag(FLAGS_store);
  if (options.data_dir.empty() == store.empty()) {
    return UsageError("give one of --data-dir DIR and --store sqlite:DIR|postgresql://...");
  }
  if (!store.empty()) {
    if (!absl::StartsWith(store, "sqlite:") && !absl::StartsWith(store, "postgresql://") &&
        !absl::StartsWith(store, "postgres://")) {
      return UsageError(absl::StrCat("--store ", store,
                                     ": expected sqlite:DIR or postgresql://USER@HOST:PORT/DB"));
    }
    options.data_dir = store;
  }
  if (const double lease = absl::GetFlag(FLAGS_lease_s); lease >= 0.2) {
    options.lease_ms = static_cast<int64_t>(lease * 1000);
  } else {
    return UsageError("--lease-s: must be >= 0.2");
  }
  options.workers = absl::GetFlag(FLAGS_workers);
  if (options.workers <= 0) options.workers = std::max(1u, std::thread::hardware_concurrency());
  cablesim::ServerLimits& limits = options.limits;
  limits.max_elements = absl::GetFlag(FLAGS_max_elements);
  limits.max_steps = absl::GetFlag(FLAGS_max_steps);
  limits.max_frames = absl::GetFlag(FLAGS_max_frames);
  limits.max_trajectory_values = absl::GetFlag(FLAGS_max_trajectory_values);
  limits.max_sweep_items = absl::GetFlag(FLAGS_max_sweep_items);
  limits.max_streams = absl::GetFlag(FLAGS_max_streams);
  limits.max_message_bytes = absl::GetFlag(FLAGS_max_message_bytes);
  limits.max_modes = absl::GetFlag(FLAGS_max_modes);
  limits.max_modal_bytes = absl::GetFlag(FLAGS_max_modal_bytes);
  limits.max_name_bytes = absl::GetFlag(FLAGS_max_name_bytes);
  limits.max_coordinates = absl::GetFlag(FLAGS_max_coordinates);
  limits.max_streams_per_peer = absl::GetFlag(FLAGS_max_streams_per_peer);
  limits.max_queued_jobs_per_peer = absl::GetFlag(FLAGS_max_queued_jobs_per_peer);
  limits.max_unary_calls = absl::GetFlag(FLAGS_max_unary_calls);
  limits.max_unary_calls_per_peer = absl::GetFlag(FLAGS_max_unary_calls_per_peer);
  limits.max_inflight_bytes = absl::GetFlag(FLAGS_max_inflight_bytes);
  limits.max_work_units = absl::GetFlag(FLAGS_max_work_units);
  if (const double age = absl::GetFlag(FLAGS_retention_max_age_s); age > 0) {
    limits.retention_max_age = absl::Seconds(age);
  } else if (age < 0) {
    return UsageError("--retention-max-age-s: must be >= 0");
  }
  if (const int64_t bytes = absl::GetFlag(FLAGS_retention_max_bytes); bytes > 0) {
    limits.retention_max_bytes = bytes;
  } else if (bytes < 0) {
    return UsageError("--retention-max-bytes: must be >= 0");
  }
  limits.stall_timeout = absl::Seconds(absl::GetFlag(FLAGS_stall_timeout_s));
  auto read_file = [](const std::string& path, std::string* text) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    text->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
  };
  const std::string cert = absl::GetFlag(FLAGS_tls_cert), key = absl::GetFlag(FLAGS_tls_key),
                    client_ca = absl::GetFlag(FLAGS_tls_client_ca),
                    token_file = absl::GetFlag(FLAGS_token_file);
  if (cert.empty() != key.empty()) return UsageError("--tls-cert and --tls-key go together");
  if (!client_ca.empty() && cert.empty()) return UsageError("--tls-client-ca needs --tls-cert");
  for (const auto& [path, text] :
       {std::pair{cert, &options.tls_cert_pem}, std::pair{key, &options.tls_key_pem},
        std::pair{client_ca, &options.tls_client_ca_pem}}) {
    if (!path.empty() && !read_file(path, text)) {
      std::cerr << "cablesim-server: cannot read " << path << "\n";
      return 1;
    }
  }
  if (!token_file.empty()) {
    // The tokens are passwords: a file that others can read or change is
    // refused (as ssh does with a private key), naming the file and its
    // mode. Group access is only warned about: Kubernetes mounts secrets
    // 0440 for the pod's own group (fsGroup).
    struct stat info;
    if (::stat(token_file.c_str(), &info) == 0) {
      const std::string mode = absl::StrFormat("%04o", info.st_mode & 07777);
      if ((info.st_mode & S_IRWXO) != 0) {
        std::cerr << "cablesim-server: " << token_file << ": mode " << mode
                  << " lets others read or change the tokens; make it readable by its owner "
                     "only (chmod 600 "
                  << token_file << ")\n";
        return 1;
      }
      if ((info.st_mode & S_IRWXG) != 0) {
        std::cerr << "cablesim-server: WARNING: " << token_file << ": mode " << mode
                  << " lets its group read the tokens; fine when the group is the server's own "
                     "(a Kubernetes secret with fsGroup), else chmod 600 "
                  << token_file << "\n";
      }
    }
    std::string text;
    if (!read_file(token_file, &text)) {
      std::cerr << "cablesim-server: cannot read " << token_file << "\n";
      return 1;
    }
    int line_number = 0;
    for (absl::string_view line : absl::StrSplit(text, '\n')) {
      ++line_number;
      line = absl::StripAsciiWhitespace(line);
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> fields = absl::StrSplit(line, ' ', absl::SkipWhitespace());
      if (fields.size() != 2 || fields[0].size() < 16) {
        std::cerr << "cablesim-server: " << token_file << ":" << line_number
                  << ": expected \"TOKEN TENANT\" with a token of at least 16 characters\n";
        return 1;
      }
      options.tokens[fields[0]] = fields[1];
    }
    if (options.tokens.empty()) {
      std::cerr << "cablesim-server: " << token_file << ": no tokens\n";
      return 1;
    }
  }
  // Beyond loopback, only with TLS and tokens (or when told it is fine).
  // The address is resolved once, here: the check looks at the address
  // bound, not at how its name is spelled (127.evil.example is not local).
  {
    absl::StatusOr<cablesim::ListenAddress> listen =
        cablesim::ResolveListenAddress(options.listen);
    if (!listen.ok()) return UsageError(std::string(listen.status().message()));
    if (!listen->loopback && (options.tls_cert_pem.empty() || options.tokens.empty()) &&
        !absl::GetFlag(FLAGS_insecure)) {
      return UsageError(absl::StrCat(
          "--listen ", options.listen, " (", listen->bind,
          "): beyond loopback the server needs --tls-cert/--tls-key and --token-file "
          "(or --insecure, to accept anyone who can reach the port)"));
    }
    options.listen = listen->bind;
  }
  // Only the tests set this (tests/server_test_util.h); no flag, so it is
  // not offered in --help, and it is announced loudly when present.
  if (const char* gate = std::getenv("CABLESIM_TEST_ONLY_JOB_GATE"); gate && *gate) {
    options.test_only_job_gate_dir = gate;
    std::cerr << "cablesim-server: WARNING: CABLESIM_TEST_ONLY_JOB_GATE is set: jobs named "
                 "\"gated...\" wait for a file in "
              << gate << " (for tests only; unset it in any deployment)\n";
  }

  // Block the shutdown signals in every thread; the main thread waits for
  // them below.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  absl::StatusOr<std::unique_ptr<cablesim::CablesimServer>> server =
      cablesim::CablesimServer::Start(options);
  if (!server.ok()) {
    std::cerr << "cablesim-server: " << server.status().message() << "\n";
    return 1;
  }
  std::cerr << "cablesim-server: listening on port " << (*server)->port() << " (" << options.listen
            << "), jobs in " << (*server)->store_description() << ", " << options.workers << " workers\n";
  std::unique_ptr<cablesim::MetricsEndpoint> metrics;
  if (const std::string listen = absl::GetFlag(FLAGS_metrics_listen); !listen.empty()) {
    absl::StatusOr<std::unique_ptr<cablesim::MetricsEndpoint>> started =
        cablesim::MetricsEndpoint::Start(listen, (*server)->InProcessChannel(), options.tokens,
                                         options.workers);
    if (!started.ok()) {
      std::cerr << "cablesim-server: " << started.status().message() << "\n";
      (*server)->Shutdown(absl::ZeroDuration());
      return 1;
    }
    metrics = std::move(*started);
    std::cerr << "cablesim-server: metrics on port " << metrics->port() << " (" << listen
              << ", GET /metrics)\n";
  }
  const std::string port_file = absl::GetFlag(FLAGS_port_file);
  if (!port_file.empty()) {
    const std::string tmp = port_file + ".tmp";
    { std::ofstream(tmp) << (*server)->port() << "\n"; }
    std::rename(tmp.c_str(), port_file.c_str());
  }
  int signal = 0;
  sigwait(&signals, &signal);
  std::cerr << "cablesim-server: signal " << signal << ", shutting down\n";
  metrics.reset();
  (*server)->Shutdown(absl::Seconds(absl::GetFlag(FLAGS_shutdown_grace_s)));
  std::cerr << "cablesim-server: stopped\n";
  return 0;
}
