#include "server/request_parse_interceptor.h"

#include <string>

#include "absl/strings/str_cat.h"

namespace cablesim {
namespace {

using grpc::experimental::InterceptionHookPoints;

class RequestParseInterceptor : public grpc::experimental::Interceptor {
 public:
  explicit RequestParseInterceptor(std::string method) : method_(std::move(method)) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    // The server hands interceptors a null message when the request could
    // not be parsed.
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::POST_RECV_MESSAGE) &&
        methods->GetRecvMessage() == nullptr) {
      unparsed_ = true;
    }
    if (unparsed_ && methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS) &&
        methods->GetSendStatus().error_code() == grpc::StatusCode::INTERNAL) {
      methods->ModifySendStatus(grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          absl::StrCat("request: not a valid request message for ", method_,
                       " (malformed protobuf, a field of the wrong type, or a string that is "
                       "not valid UTF-8)")));
    }
    methods->Proceed();
  }

 private:
  const std::string method_;
  bool unparsed_ = false;
};

}  // namespace

grpc::experimental::Interceptor* RequestParseInterceptorFactory::CreateServerInterceptor(
    grpc::experimental::ServerRpcInfo* info) {
  return new RequestParseInterceptor(info->method() ? info->method() : "this method");
}

}  // namespace cablesim
