#include "server/cablesim_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>

#include <chrono>
#include <iostream>

#include "absl/strings/str_cat.h"
#include "server/request_parse_interceptor.h"

namespace cablesim {

absl::StatusOr<std::unique_ptr<CablesimServer>> CablesimServer::Start(
    const ServerOptions& options) {
  std::unique_ptr<CablesimServer> s(new CablesimServer());
  s->limits_ = options.limits;
  if (!options.data_dir.empty()) {
    StoreOptions store_options;
    store_options.lease_ms = options.lease_ms;
    store_options.notifications = options.store_notifications;
    absl::StatusOr<std::unique_ptr<JobStore>> store =
        JobStore::Open(options.data_dir, store_options);
    if (!store.ok()) return store.status();
    s->store_ = std::move(*store);
    s->jobs_ =
        std::make_unique<JobManager>(s->store_.get(), options.workers, options.limits, options.log);
    s->jobs_->set_test_only_gate_dir(options.test_only_job_gate_dir);
    s->jobs_->set_lease(absl::Milliseconds(options.lease_ms));
  }
  s->service_ = std::make_unique<CablesimServiceImpl>(s->jobs_.get(), options.limits, options.log,
                                                      options.tokens);
  s->log_ = options.log;

  if (options.defer_grpc && options.listen.empty()) {
    s->deferred_ = options;
  } else if (absl::Status st = s->StartGrpc(options); !st.ok()) {
    return st;
  }
  if (s->jobs_ != nullptr) {
    if (absl::Status st = s->jobs_->Start(); !st.ok()) {
      s->Shutdown(absl::ZeroDuration());
      return st;
    }
  }
  return s;
}

absl::Status CablesimServer::StartGrpc(const ServerOptions& options) {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  if (!options.listen.empty()) {
    std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials();
    if (!options.tls_cert_pem.empty()) {
      // gRPC's own TLS: the certificate and key, and with a client CA,
      // clients must present a certificate it signed.
      grpc::SslServerCredentialsOptions ssl(
          options.tls_client_ca_pem.empty()
              ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
              : GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY);
      ssl.pem_root_certs = options.tls_client_ca_pem;
      ssl.pem_key_cert_pairs.push_back({options.tls_key_pem, options.tls_cert_pem});
      credentials = grpc::SslServerCredentials(ssl);
    }
    builder.AddListeningPort(options.listen, credentials, &port_);
  }
  builder.SetMaxReceiveMessageSize(options.limits.max_message_bytes);
  builder.SetMaxSendMessageSize(options.limits.max_message_bytes);
  builder.RegisterService(service_.get());
  std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(std::make_unique<RequestParseInterceptorFactory>());
  builder.experimental().SetInterceptorCreators(std::move(interceptors));
  server_ = builder.BuildAndStart();
  if (server_ == nullptr || (!options.listen.empty() && port_ == 0)) {
    down_ = true;
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen));
  }
  server_->GetHealthCheckService()->SetServingStatus(true);
  return absl::OkStatus();
}

CablesimServer::~CablesimServer() { Shutdown(absl::ZeroDuration()); }

std::shared_ptr<grpc::Channel> CablesimServer::InProcessChannel() {
  if (server_ == nullptr && !down_) {
    // Deferred (ServerOptions::defer_grpc); no port, so it cannot fail to
    // listen.
    (void)StartGrpc(deferred_);
  }
  if (server_ == nullptr) return nullptr;
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(limits_.max_message_bytes);
  args.SetMaxSendMessageSize(limits_.max_message_bytes);
  return server_->InProcessChannel(args);
}

void CablesimServer::Shutdown(absl::Duration grace) {
  if (down_) return;
  down_ = true;
  if (server_ != nullptr) server_->GetHealthCheckService()->SetServingStatus(false);
  if (jobs_ != nullptr) {
    jobs_->Shutdown();
    if (log_) std::cerr << "cablesim-server: workers stopped, unfinished jobs left queued\n";
  }
  if (server_ != nullptr) {
    server_->Shutdown(std::chrono::system_clock::now() +
                      std::chrono::milliseconds(absl::ToInt64Milliseconds(grace)));
    server_->Wait();
  }
}

}  // namespace cablesim
