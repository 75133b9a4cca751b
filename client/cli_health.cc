#include "client/cli_health.h"

#include <grpcpp/generic/generic_stub.h>

#include <chrono>
#include <future>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/json_line.h"

namespace cablesim::cli_internal {
namespace {

// HealthCheckResponse.status (grpc/health/v1/health.proto), by number.
std::string ServingStatusName(int status) {
  switch (status) {
    case 0:
      return "UNKNOWN";
    case 1:
      return "SERVING";
    case 2:
      return "NOT_SERVING";
    case 3:
      return "SERVICE_UNKNOWN";
    default:
      return absl::StrCat("STATUS_", status);
  }
}

// The status field of a serialized HealthCheckResponse: field 1, a varint
// (tag byte 0x08); absent (proto3 default) means 0, UNKNOWN.
int ParseServingStatus(const std::string& bytes) {
  size_t i = 0;
  while (i < bytes.size()) {
    const uint8_t tag = static_cast<uint8_t>(bytes[i++]);
    uint64_t value = 0;
    int shift = 0;
    while (i < bytes.size() && shift < 64) {
      const uint8_t b = static_cast<uint8_t>(bytes[i++]);
      value |= static_cast<uint64_t>(b & 0x7f) << shift;
      shift += 7;
      if ((b & 0x80) == 0) break;
    }
    if (tag == 0x08) return static_cast<int>(value);
    if ((tag & 7) != 0) return -1;  // not a varint field: not this message
  }
  return 0;
}

}  // namespace

int Health(const Arguments& a, std::ostream& out, std::ostream& err) {
  if (!a.server.has_value()) return UsageError(err, "health: needs --server HOST:PORT");
  std::unique_ptr<Connection> c = ConnectOrReport(a.server, false, 0, err);
  if (c == nullptr) return kExitIoError;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
  grpc::Slice empty("");  // HealthCheckRequest{service: ""}: the whole server
  const grpc::ByteBuffer request(&empty, 1);
  grpc::ByteBuffer response;
  std::promise<grpc::Status> done;
  grpc::GenericStub stub(c->channel);
  stub.UnaryCall(&context, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &request,
                 &response, [&done](grpc::Status s) { done.set_value(std::move(s)); });
  const absl::Status status = FromGrpc(done.get_future().get());
  if (!status.ok()) {
    err << "cablesim: health of " << *a.server << ": " << status << "\n";
    return kExitIoError;
  }
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (response.Dump(&slices).ok()) {
    for (const grpc::Slice& s : slices) bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  }
  const std::string name = ServingStatusName(ParseServingStatus(bytes));
  out << JsonLine().Add("server", *a.server).Add("status", name).ToString() << "\n";
  out.flush();
  return name == "SERVING" ? kExitOk : kExitIoError;
}

}  // namespace cablesim::cli_internal
