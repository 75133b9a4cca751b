#include "client/service_client.h"

#include <stdlib.h>

#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <grpcpp/support/client_interceptor.h>

#include "absl/strings/str_cat.h"
#include "convert/run_proto.h"

namespace cablesim {
namespace {

RemoteSecurity& Security() {
  static RemoteSecurity* security = new RemoteSecurity();
  return *security;
}

// Adds `authorization: Bearer TOKEN` to every call of the channel.
class TokenInterceptor : public grpc::experimental::Interceptor {
 public:
  explicit TokenInterceptor(const std::string& token) : value_("Bearer " + token) {}
  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(
            grpc::experimental::InterceptionHookPoints::PRE_SEND_INITIAL_METADATA)) {
      methods->GetSendInitialMetadata()->insert({"authorization", value_});
    }
    methods->Proceed();
  }

 private:
  const std::string value_;
};

class TokenInterceptorFactory : public grpc::experimental::ClientInterceptorFactoryInterface {
 public:
  explicit TokenInterceptorFactory(std::string token) : token_(std::move(token)) {}
  grpc::experimental::Interceptor* CreateClientInterceptor(
      grpc::experimental::ClientRpcInfo*) override {
    return new TokenInterceptor(token_);
  }

 private:
  const std::string token_;
};

}  // namespace

void SetRemoteSecurity(RemoteSecurity security) { Security() = std::move(security); }

namespace {
bool& InProcessLimitsOn() {
  static bool on = true;
  return on;
}
}  // namespace

void SetInProcessLimits(bool on) { InProcessLimitsOn() = on; }

ServerLimits InProcessLimits() {
  if (InProcessLimitsOn()) return DefaultServerLimits();
  ServerLimits none;  // no limits beyond the engine's
  none.max_elements = std::numeric_limits<int>::max();
  none.max_steps = std::numeric_limits<int64_t>::max() / 4;
  none.max_frames = std::numeric_limits<int64_t>::max();
  none.max_trajectory_values = std::numeric_limits<int64_t>::max();
  none.max_sweep_items = std::numeric_limits<int>::max();
  return none;
}

Connection::~Connection() {
  stub.reset();
  channel.reset();
  if (local != nullptr) local->Shutdown(absl::ZeroDuration());
  local.reset();
  if (!local_data_dir.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(local_data_dir, ignored);
  }
}

absl::Status FromGrpc(const grpc::Status& status) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()), status.error_message());
}

absl::StatusOr<std::unique_ptr<Connection>> Connect(const std::optional<std::string>& server,
                                                    bool jobs, int workers) {
  auto c = std::make_unique<Connection>();
  if (server.has_value()) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    // A target may name several servers (ipv4:A:P,B:Q, or a DNS name with
    // several addresses): spread the calls over all that answer.
    args.SetLoadBalancingPolicyName("round_robin");
    const RemoteSecurity& security = Security();
    std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials();
    if (!security.tls_ca_pem.empty()) {
      grpc::SslCredentialsOptions ssl;
      ssl.pem_root_certs = security.tls_ca_pem;
      credentials = grpc::SslCredentials(ssl);
    }
    std::vector<std::unique_ptr<grpc::experimental::ClientInterceptorFactoryInterface>> tokens;
    if (!security.token.empty()) {
      tokens.push_back(std::make_unique<TokenInterceptorFactory>(security.token));
    }
    c->channel = grpc::experimental::CreateCustomChannelWithInterceptors(
        *server, credentials, args, std::move(tokens));
  } else {
    ServerOptions options;
    // The user's own process: the server's default costing limits (a
    // 1e9-step scene is refused at once, naming the limit, rather than
    // grinding silently), unless --no-limits. Streams and their stall
    // timeout protect a server from other clients: none here.
    options.limits = InProcessLimits();
    options.limits.max_streams = std::numeric_limits<int>::max() / 2;
    options.limits.max_streams_per_peer = std::numeric_limits<int>::max() / 2;
    options.limits.max_queued_jobs_per_peer = std::numeric_limits<int64_t>::max();
    options.limits.max_unary_calls = std::numeric_limits<int>::max();
    options.limits.max_unary_calls_per_peer = std::numeric_limits<int>::max();
    options.limits.max_inflight_bytes = std::numeric_limits<int64_t>::max();
    options.limits.stall_timeout = absl::Hours(24 * 365);
    options.log = false;
    options.workers = workers > 0 ? workers : std::max(1u, std::thread::hardware_concurrency());
    if (jobs) {
      std::string templ = (std::filesystem::temp_directory_path() / "cablesim-XXXXXX").string();
      if (mkdtemp(templ.data()) == nullptr) {
        return absl::UnavailableError("cannot create a temporary directory for the jobs");
      }
      c->local_data_dir = templ;
      options.data_dir = templ;
    }
    absl::StatusOr<std::unique_ptr<CablesimServer>> local = CablesimServer::Start(options);
    if (!local.ok()) return local.status();
    c->local = std::move(*local);
    c->channel = c->local->InProcessChannel();
  }
  c->stub = v1::CablesimService::NewStub(c->channel);
  return c;
}

absl::StatusOr<RunSummary> ReadRunStream(grpc::ClientContext* context,
                                         grpc::ClientReader<v1::RunEvent>* reader, FrameSink* sink,
                                         const std::function<void(double, double)>& on_frame_time) {
  v1::RunEvent event;
  std::optional<FrameReader> frames;
  int columns = 0;
  double end_time = 0;
  Frame frame;
  std::optional<RunSummary> summary;
  absl::Status sink_error;
  while (reader->Read(&event)) {
    if (event.has_header()) {
      const ModelInfo info = ModelInfoFromProto(event.header().info());
      // Columns by name: a server older or newer than this client may
      // send fewer or more of them.
      const std::vector<std::string> names(event.header().columns().begin(),
                                           event.header().columns().end());
      frames.emplace(info, names);
      columns = frames->row_size();
      end_time = event.header().end_time_s();
      sink_error = sink->OnStart(info);
    } else if (event.has_frames()) {
      const v1::FrameBatch& b = event.frames();
      if (columns == 0 || b.values_size() != b.rows() * columns) {
        sink_error = absl::InternalError("malformed frame batch from the server");
      }
      for (int r = 0; sink_error.ok() && r < b.rows(); ++r) {
        frames->Read(absl::MakeConstSpan(b.values().data() + r * columns, columns), &frame);
        sink_error = sink->OnFrame(frame);
        if (on_frame_time) on_frame_time(frame.t, end_time);
      }
    } else if (event.has_summary()) {
      summary = SummaryFromProto(event.summary());
    }
    if (!sink_error.ok()) {
      context->TryCancel();
      while (reader->Read(&event)) {
      }
      (void)reader->Finish();
      return sink_error;
    }
  }
  const absl::Status status = FromGrpc(reader->Finish());
  if (!status.ok()) return status;
  if (!summary.has_value()) return absl::UnavailableError("the stream ended without a summary");
  return *summary;
}

}  // namespace cablesim
