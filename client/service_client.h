#ifndef CABLESIM_CLIENT_SERVICE_CLIENT_H_
#define CABLESIM_CLIENT_SERVICE_CLIENT_H_

// The client side of cablesim.v1.CablesimService used by the command line:
// a connection to a remote server, or to one started in this process (so
// `cablesim run` goes through the same service code either way), and the
// reading of a Run / GetJobResult stream into a FrameSink.

#include <grpcpp/grpcpp.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "engine/run/simulation.h"
#include "server/cablesim_server.h"

namespace cablesim {

struct Connection {
  std::unique_ptr<CablesimServer> local;  // set for an in-process service
  std::string local_data_dir;             // its temporary job store, if any
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::CablesimService::Stub> stub;
  ~Connection();
};

// How Connect reaches a remote server: TLS with this CA (PEM text; empty:
// plain text), and a bearer token sent with every call (empty: none).
// Set by the command line from --tls-ca and --token-file for the one
// command it runs.
struct RemoteSecurity {
  std::string tls_ca_pem;
  std::string token;
};
void SetRemoteSecurity(RemoteSecurity security);

// The costing limits of in-process services: the server's defaults
// (DefaultServerLimits), or with SetInProcessLimits(false) (the command
// line's --no-limits) none beyond the engine's.
void SetInProcessLimits(bool on);
ServerLimits InProcessLimits();

// `server` "host:port": a channel to it. Otherwise an in-process service
// with InProcessLimits(); with `jobs`, it has a job store in a fresh temporary
// directory (removed with the connection) and `workers` workers.
absl::StatusOr<std::unique_ptr<Connection>> Connect(const std::optional<std::string>& server,
                                                    bool jobs, int workers);

// An in-process service for direct calls only (RunInProcess): the same
// service as Connect's without --server, but gRPC is started only if
// something asks for c->local->InProcessChannel(); `channel` and `stub`
// stay null.
absl::StatusOr<std::unique_ptr<Connection>> ConnectInProcessDirect();

// The Run call of `request` on `c`'s in-process service, made directly
// (CablesimServiceImpl::RunTo): the same service code as over a channel,
// the events handed to `sink` as ReadRunStream does, without gRPC's
// threads, completion queues and serialisation round trips. The request is
// still checked the way the wire would check it (a request that would not
// parse answers INVALID_ARGUMENT, as RequestParseInterceptor makes it).
absl::StatusOr<RunSummary> RunInProcess(Connection* c, const v1::RunRequest& request,
                                        FrameSink* sink,
                                        const std::function<void(double, double)>& on_frame_time);

// A gRPC status as an absl::Status (same codes and message).
absl::Status FromGrpc(const grpc::Status& status);

// Reads a stream of RunEvents (header, frame batches, summary) into `sink`
// (OnStart, then OnFrame per row). `on_frame_time` (optional) sees each
// frame's t and the header's end time, for progress. A sink error cancels
// the call and is returned; so is a stream error; a stream that ends
// without a summary is Unavailable.
absl::StatusOr<RunSummary> ReadRunStream(grpc::ClientContext* context,
                                         grpc::ClientReader<v1::RunEvent>* reader, FrameSink* sink,
                                         const std::function<void(double, double)>& on_frame_time);

}  // namespace cablesim

#endif  // CABLESIM_CLIENT_SERVICE_CLIENT_H_
