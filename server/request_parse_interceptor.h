#ifndef CABLESIM_SERVER_REQUEST_PARSE_INTERCEPTOR_H_
#define CABLESIM_SERVER_REQUEST_PARSE_INTERCEPTOR_H_

// gRPC answers a request message it cannot parse (malformed protobuf, or a
// string field that is not UTF-8) with INTERNAL and an empty message, as if
// the server had failed. This interceptor turns that answer into
// INVALID_ARGUMENT naming the method and what was wrong: the request was
// bad, the server is fine.

#include <grpcpp/support/server_interceptor.h>

#include <memory>

namespace cablesim {

class RequestParseInterceptorFactory
    : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_REQUEST_PARSE_INTERCEPTOR_H_
