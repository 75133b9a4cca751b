#include "server/metrics_endpoint.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "grpcpp/client_context.h"

namespace cablesim {
namespace {

constexpr int kPageSize = 10000;
constexpr int kFinishedWindow = 1000;

std::unique_ptr<grpc::ClientContext> Context(const std::string& token) {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
  return context;
}

std::string CodeName(grpc::StatusCode code) {
  static const char* const kNames[] = {
      "OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED", "NOT_FOUND",
      "ALREADY_EXISTS", "PERMISSION_DENIED", "RESOURCE_EXHAUSTED", "FAILED_PRECONDITION",
      "ABORTED", "OUT_OF_RANGE", "UNIMPLEMENTED", "INTERNAL", "UNAVAILABLE", "DATA_LOSS",
      "UNAUTHENTICATED"};
  const int i = static_cast<int>(code);
  return i >= 0 && i < 17 ? kNames[i] : absl::StrCat(i);
}

}  // namespace

absl::StatusOr<std::unique_ptr<MetricsEndpoint>> MetricsEndpoint::Start(
    const std::string& listen, std::shared_ptr<grpc::Channel> channel,
    const std::map<std::string, std::string>& tokens, int workers) {
  const size_t colon = listen.rfind(':');
  int port = -1;
  in_addr address{};
  if (colon == std::string::npos || !absl::SimpleAtoi(listen.substr(colon + 1), &port) ||
      port < 0 || port > 65535 ||
      ::inet_pton(AF_INET, listen.substr(0, colon).c_str(), &address) != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("--metrics-listen ", listen, ": expected an IPv4 HOST:PORT"));
  }
  std::unique_ptr<MetricsEndpoint> m(new MetricsEndpoint());
  m->fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int one = 1;
  ::setsockopt(m->fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr = address;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  socklen_t length = sizeof(addr);
  if (::bind(m->fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(m->fd_, 16) != 0 ||
      ::getsockname(m->fd_, reinterpret_cast<sockaddr*>(&addr), &length) != 0) {
    return absl::UnavailableError(
        absl::StrCat("--metrics-listen ", listen, ": ", std::strerror(errno)));
  }
  m->port_ = ntohs(addr.sin_port);
  m->workers_ = workers;
  m->channel_ = std::move(channel);
  std::set<std::string> tenants;
  for (const auto& [token, tenant] : tokens) {
    if (tenants.insert(tenant).second) m->tenant_tokens_.push_back(token);
  }
  if (m->tenant_tokens_.empty()) m->tenant_tokens_.push_back("");
  m->thread_ = std::thread([p = m.get()] { p->Serve(); });
  return m;
}

MetricsEndpoint::~MetricsEndpoint() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
}

void MetricsEndpoint::Serve() {
  while (!stop_) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) continue;
    const int client = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    timeval timeout{2, 0};
    ::setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    ::setsockopt(client, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
    std::string request;
    char buffer[1024];
    while (request.find("\r\n\r\n") == std::string::npos && request.size() < 8192) {
      const ssize_t n = ::recv(client, buffer, sizeof(buffer), 0);
      if (n <= 0) break;
      request.append(buffer, static_cast<size_t>(n));
    }
    std::string status = "404 Not Found", body = "not found: GET /metrics\n";
    if (request.rfind("GET /metrics ", 0) == 0 || request.rfind("GET /metrics?", 0) == 0) {
      status = "200 OK";
      body = Render();
    }
    const std::string response = absl::StrCat(
        "HTTP/1.0 ", status, "\r\nContent-Type: text/plain; version=0.0.4; charset=utf-8\r\n",
        "Content-Length: ", body.size(), "\r\nConnection: close\r\n\r\n", body);
    size_t sent = 0;
    while (sent < response.size()) {
      const ssize_t n = ::send(client, response.data() + sent, response.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) break;
      sent += static_cast<size_t>(n);
    }
    ::close(client);
  }
}

std::string MetricsEndpoint::Render() {
  auto stub = v1::CablesimService::NewStub(channel_);
  absl::MutexLock lock(&mu_);
  // Jobs queued and running: every page, for every tenant.
  auto count = [&](v1::JobState state) -> int64_t {
    int64_t n = 0;
    for (const std::string& token : tenant_tokens_) {
      v1::ListJobsRequest request;
      request.set_state(state);
      request.set_page_size(kPageSize);
      while (true) {
        v1::ListJobsResponse response;
        const grpc::Status status = stub->ListJobs(Context(token).get(), request, &response);
        if (!status.ok()) {
          ++errors_[CodeName(status.error_code())];
          break;
        }
        n += response.jobs_size();
        if (response.next_page_token().empty()) break;
        request.set_page_token(response.next_page_token());
      }
    }
    return n;
  };
  const int64_t queued = count(v1::QUEUED), running = count(v1::RUNNING);
  // Finished jobs not counted before (the newest kFinishedWindow per state).
  for (const v1::JobState state : {v1::SUCCEEDED, v1::FAILED, v1::CANCELLED}) {
    auto& [newest, at_newest] = seen_[state];
    int64_t next_newest = newest;
    std::set<std::string> next_at_newest = at_newest;
    for (const std::string& token : tenant_tokens_) {
      v1::ListJobsRequest request;
      request.set_state(state);
      request.set_limit(kFinishedWindow);
      v1::ListJobsResponse response;
      const grpc::Status status = stub->ListJobs(Context(token).get(), request, &response);
      if (!status.ok()) {
        ++errors_[CodeName(status.error_code())];
        continue;
      }
      for (const v1::Job& job : response.jobs()) {
        const int64_t at = job.finished_unix_ms();
        if (at < newest || (at == newest && at_newest.count(job.id()) > 0)) continue;
        ++finished_[state];
        steps_ += job.summary().steps();
        if (at > next_newest) {
          next_newest = at;
          next_at_newest.clear();
        }
        if (at == next_newest) next_at_newest.insert(job.id());
      }
    }
    newest = next_newest;
    at_newest = std::move(next_at_newest);
  }
  std::string out;
  // One series without labels: its HELP and TYPE lines, then its value.
  auto series = [&out](const char* name, const char* type, const char* help, int64_t value) {
    absl::StrAppend(&out, "# HELP ", name, " ", help, "\n# TYPE ", name, " ", type, "\n", name,
                    " ", value, "\n");
  };
  series("cablesim_jobs_queued", "gauge",
         "Jobs waiting in the job store (a shared store: every server's).", queued);
  series("cablesim_jobs_running", "gauge", "Jobs running (a shared store: on every server).",
         running);
  series("cablesim_workers", "gauge", "Job worker threads of this server.", workers_);
  series("cablesim_steps_total", "counter", "Time steps of the jobs seen finished.", steps_);
  absl::StrAppend(&out,
                  "# HELP cablesim_jobs_finished_total Jobs seen finished, by final state.\n"
                  "# TYPE cablesim_jobs_finished_total counter\n");
  for (const auto& [state, name] : {std::pair{v1::SUCCEEDED, "SUCCEEDED"},
                                    std::pair{v1::FAILED, "FAILED"},
                                    std::pair{v1::CANCELLED, "CANCELLED"}}) {
    absl::StrAppend(&out, "cablesim_jobs_finished_total{state=\"", name, "\"} ",
                    finished_[state], "\n");
  }
  absl::StrAppend(&out,
                  "# HELP cablesim_metrics_errors_total Calls of this endpoint the service "
                  "refused, by gRPC status code.\n"
                  "# TYPE cablesim_metrics_errors_total counter\n");
  for (const auto& [code, n] : errors_) {
    absl::StrAppend(&out, "cablesim_metrics_errors_total{code=\"", code, "\"} ", n, "\n");
  }
  return out;
}

}  // namespace cablesim
