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

// An in-process service: the user's own process, with the server's default
// costing limits (a 1e9-step scene is refused at once, naming the limit,
// rather than grinding silently), unless --no-limits (InProcessLimits).
// Streams, unary-call bounds, the memory budget and the stall timeout
// protect a server from other clients: none here.
ServerOptions InProcessOptions(int workers) {
  ServerOptions options;
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
  return options;
}

}  // namespace

void SetRemoteSecurity(RemoteSecurity security) { Security() = std::move(security); }

namespace {
bool& InProcessLimitsOn() {
  static bool on = true;
  return on;
}
}  // namespace

void SetInProcessLimits(bool on) { InProcessLimitsOn() = on; }

namespace {

ServerLimits NoLimits() {
  ServerLimits none;  // no limits beyond the engine's
  none.max_elements = std::numeric_limits<int>::max();
  none.max_steps = std::numeric_limits<int64_t>::max() / 4;
  none.max_frames = std::numeric_limits<int64_t>::max();
  none.max_trajectory_values = std::numeric_limits<int64_t>::max();
  none.max_sweep_items = std::numeric_limits<int>::max();
  return none;
}

}  // namespace

ServerLimits InProcessLimits() {
  ServerLimits limits = InProcessLimitsOn() ? DefaultServerLimits() : NoLimits();
  // A run in the command line's own process computes at the caller's
  // priority: no calls or health checks to keep answering beside it.
  limits.compute_nice = 0;
  return limits;
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

// Every method of the service: UNAVAILABLE is retried (3 attempts in all,
// 0.1 s then up to 0.2 s apart, randomized by gRPC).
constexpr char kRetryServiceConfig[] = R"json({
  "methodConfig": [{
    "name": [{"service": "cablesim.v1.CablesimService"}],
    "retryPolicy": {
      "maxAttempts": 3,
      "initialBackoff": "0.1s",
      "maxBackoff": "1s",
      "backoffMultiplier": 2,
      "retryableStatusCodes": ["UNAVAILABLE"]
    }
  }]
})json";

absl::StatusOr<std::unique_ptr<Connection>> Connect(const std::optional<std::string>& server,
                                                    bool jobs, int workers) {
  auto c = std::make_unique<Connection>();
  if (server.has_value()) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(64 << 20);
    // A target may name several servers (ipv4:A:P,B:Q, or a DNS name with
    // several addresses): spread the calls over all that answer.
    args.SetLoadBalancingPolicyName("round_robin");
    // A call that fails UNAVAILABLE before any answer came back (a server
    // that stopped while this client still had its connection, a write to
    // a closed socket: "Broken pipe") is tried again, on the next server,
    // up to twice (gRPC's retry policy). Without it, the first call after a
    // server stops can fail although the others answer. A SubmitJob whose
    // server died between storing the job and answering can so leave one
    // job more (ListJobs shows it).
    args.SetServiceConfigJSON(kRetryServiceConfig);
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
    ServerOptions options = InProcessOptions(workers);
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

namespace {

// Turns a stream of RunEvents into OnStart/OnFrame calls on a sink and the
// summary: ReadRunStream's and RunInProcess's one reader.
class RunEventReader {
 public:
  RunEventReader(FrameSink* sink, const std::function<void(double, double)>& on_frame_time)
      : sink_(sink), on_frame_time_(on_frame_time) {}

  // The sink's error (or a malformed batch's): the stream must stop.
  absl::Status OnEvent(const v1::RunEvent& event) {
    if (event.has_header()) {
      const ModelInfo info = ModelInfoFromProto(event.header().info());
      // Columns by name: a server older or newer than this client may
      // send fewer or more of them.
      const std::vector<std::string> names(event.header().columns().begin(),
                                           event.header().columns().end());
      frames_.emplace(info, names);
      columns_ = frames_->row_size();
      end_time_ = event.header().end_time_s();
      return sink_->OnStart(info);
    }
    if (event.has_frames()) {
      const v1::FrameBatch& b = event.frames();
      if (columns_ == 0 || b.values_size() != b.rows() * columns_) {
        return absl::InternalError("malformed frame batch from the server");
      }
      for (int r = 0; r < b.rows(); ++r) {
        frames_->Read(absl::MakeConstSpan(b.values().data() + r * columns_, columns_), &frame_);
        if (absl::Status s = sink_->OnFrame(frame_); !s.ok()) return s;
        if (on_frame_time_) on_frame_time_(frame_.t, end_time_);
      }
      return absl::OkStatus();
    }
    if (event.has_summary()) summary_ = SummaryFromProto(event.summary());
    return absl::OkStatus();
  }
  // The stream's end: `status` is the call's.
  absl::StatusOr<RunSummary> Finish(const absl::Status& status) const {
    if (!status.ok()) return status;
    if (!summary_.has_value()) return absl::UnavailableError("the stream ended without a summary");
    return *summary_;
  }

 private:
  FrameSink* sink_;
  const std::function<void(double, double)>& on_frame_time_;
  std::optional<FrameReader> frames_;
  int columns_ = 0;
  double end_time_ = 0;
  Frame frame_;
  std::optional<RunSummary> summary_;
};

// The server side of a direct call: each written event goes straight to
// the reader; a reader error makes the write fail, as a client that went
// away would.
class DirectRunWriter final : public grpc::ServerWriterInterface<v1::RunEvent> {
 public:
  explicit DirectRunWriter(RunEventReader* reader) : reader_(reader) {}
  void SendInitialMetadata() override {}
  bool Write(const v1::RunEvent& event, grpc::WriteOptions) override {
    if (!error_.ok()) return false;
    error_ = reader_->OnEvent(event);
    return error_.ok();
  }
  const absl::Status& error() const { return error_; }

 private:
  RunEventReader* reader_;
  absl::Status error_;
};

}  // namespace

absl::StatusOr<RunSummary> ReadRunStream(grpc::ClientContext* context,
                                         grpc::ClientReader<v1::RunEvent>* reader, FrameSink* sink,
                                         const std::function<void(double, double)>& on_frame_time) {
  RunEventReader events(sink, on_frame_time);
  v1::RunEvent event;
  while (reader->Read(&event)) {
    const absl::Status sink_error = events.OnEvent(event);
    if (!sink_error.ok()) {
      context->TryCancel();
      while (reader->Read(&event)) {
      }
      (void)reader->Finish();
      return sink_error;
    }
  }
  return events.Finish(FromGrpc(reader->Finish()));
}

absl::StatusOr<std::unique_ptr<Connection>> ConnectInProcessDirect() {
  auto c = std::make_unique<Connection>();
  ServerOptions options = InProcessOptions(1);
  options.defer_grpc = true;
  absl::StatusOr<std::unique_ptr<CablesimServer>> local = CablesimServer::Start(options);
  if (!local.ok()) return local.status();
  c->local = std::move(*local);
  return c;
}

absl::StatusOr<RunSummary> RunInProcess(Connection* c, const v1::RunRequest& request,
                                        FrameSink* sink,
                                        const std::function<void(double, double)>& on_frame_time) {
  // What the server would receive: the request through the wire format
  // (a string that is not UTF-8 does not survive it).
  v1::RunRequest received;
  if (!received.ParseFromString(request.SerializeAsString())) {
    return absl::InvalidArgumentError(
        "request: not a valid request message for /cablesim.v1.CablesimService/Run (malformed "
        "protobuf, a field of the wrong type, or a string that is not valid UTF-8)");
  }
  RunEventReader events(sink, on_frame_time);
  DirectRunWriter writer(&events);
  grpc::ServerContext context;
  const grpc::Status status = c->local->service()->RunTo(&context, &received, &writer);
  if (!writer.error().ok()) return writer.error();
  return events.Finish(FromGrpc(status));
}

}  // namespace cablesim
