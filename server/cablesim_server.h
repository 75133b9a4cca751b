#ifndef CABLESIM_SERVER_CABLESIM_SERVER_H_
#define CABLESIM_SERVER_CABLESIM_SERVER_H_

// A running cablesim service: the gRPC server with CablesimService, the
// gRPC health service (grpc.health.v1, SERVING while up) and server
// reflection; with a data directory, the job store and its workers.
// Used by cablesim-server, by `cablesim` (in-process, no port) and by the
// tests and benchmarks.

#include <grpcpp/grpcpp.h>

#include <map>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "server/cablesim_service.h"
#include "server/job_manager.h"
#include "server/store/job_store.h"
#include "server/request_checks.h"

namespace cablesim {

struct ServerOptions {
  // host:port to listen on (port 0: any free port, see port()); empty: no
  // network port, in-process channels only.
  std::string listen;
  // The job store: `sqlite:DIR`, a bare DIR, or `postgresql://...`
  // (JobStore::Open); empty: no jobs (Run and Validate only).
  std::string data_dir;
  // Shared stores: how long a claim holds without a heartbeat.
  int64_t lease_ms = 10'000;
  // Shared stores: StoreOptions::notifications.
  bool store_notifications = true;
  int workers = 1;
  ServerLimits limits;
  // Report jobs, sweeps and shutdown on stderr.
  bool log = true;
  // TLS: the server's certificate chain and private key (PEM text); empty:
  // no TLS. With a client CA (PEM), clients must present a certificate it
  // signed (mutual TLS).
  std::string tls_cert_pem, tls_key_pem, tls_client_ca_pem;
  // Bearer tokens -> tenant (CablesimServiceImpl::Authorize); empty: none
  // needed.
  std::map<std::string, std::string> tokens;
  // Without `listen`: build the gRPC server only at the first
  // InProcessChannel(). A caller that only calls service() directly (the
  // command line's `run`) then never starts gRPC's threads.
  bool defer_grpc = false;
  // TEST ONLY: see JobManager::set_test_only_gate_dir (empty: off).
  std::string test_only_job_gate_dir;
};

class CablesimServer {
 public:
  static absl::StatusOr<std::unique_ptr<CablesimServer>> Start(const ServerOptions& options);
  ~CablesimServer();  // Shutdown(0)

  // The port bound (0 when not listening).
  int port() const { return port_; }
  std::shared_ptr<grpc::Channel> InProcessChannel();
  // The service itself, for calls made directly in this process.
  CablesimServiceImpl* service() { return service_.get(); }
  // The job store, for logs (JobStore::Describe; never a password).
  std::string store_description() const { return store_ ? store_->Describe() : "none"; }

  // Stops the workers (running jobs go back to QUEUED), then the server:
  // calls still running after `grace` are cancelled. Idempotent.
  void Shutdown(absl::Duration grace);

 private:
  CablesimServer() = default;
  // Builds and starts server_ (listening on options.listen, if any).
  absl::Status StartGrpc(const ServerOptions& options);
  ServerOptions deferred_;  // the options for a deferred StartGrpc
  ServerLimits limits_;
  std::unique_ptr<JobStore> store_;
  std::unique_ptr<JobManager> jobs_;
  std::unique_ptr<CablesimServiceImpl> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;
  bool down_ = false;
  bool log_ = true;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_CABLESIM_SERVER_H_
