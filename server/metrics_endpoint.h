// A Prometheus text endpoint (`cablesim-server --metrics-listen HOST:PORT`,
// off by default): plain HTTP on a port of its own, `GET /metrics`.
//
// It reads what it reports through the server's own gRPC service on the
// in-process channel, as any client would (ListJobs per state; one call per
// tenant, with a token of that tenant, when the server has tokens), so it
// needs nothing from the job manager's inside and sees exactly what the
// service answers. Series (docs/deployment.md):
//
//   cablesim_jobs_queued, cablesim_jobs_running   gauges: jobs in the store
//       in that state (with a shared PostgreSQL store: every server's)
//   cablesim_workers                              gauge: this server's
//   cablesim_steps_total                          counter: time steps of the
//       jobs seen finished (rate() of it: steps per second)
//   cablesim_jobs_finished_total{state}           counter: jobs seen
//       finished, by final state (SUCCEEDED, FAILED, CANCELLED)
//   cablesim_metrics_errors_total{code}           counter: the endpoint's
//       own calls the service refused, by gRPC status code
//
// Finished jobs are counted from the newest 1000 of each state at each
// scrape; the first scrape counts those already there.

#ifndef CABLESIM_SERVER_METRICS_ENDPOINT_H_
#define CABLESIM_SERVER_METRICS_ENDPOINT_H_

#include <atomic>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "grpcpp/channel.h"

namespace cablesim {

class MetricsEndpoint {
 public:
  // Listens on `listen` (IPv4 HOST:PORT; port 0: any free). `tokens`: the
  // server's token -> tenant map (empty: the service needs none).
  static absl::StatusOr<std::unique_ptr<MetricsEndpoint>> Start(
      const std::string& listen, std::shared_ptr<grpc::Channel> channel,
      const std::map<std::string, std::string>& tokens, int workers);
  ~MetricsEndpoint();

  int port() const { return port_; }
  // The metrics text, as GET /metrics returns it.
  std::string Render();

 private:
  MetricsEndpoint() = default;
  void Serve();

  int fd_ = -1;
  int port_ = 0;
  int workers_ = 0;
  std::shared_ptr<grpc::Channel> channel_;
  std::vector<std::string> tenant_tokens_;  // one per tenant; {""} without tokens
  std::atomic<bool> stop_{false};
  std::thread thread_;

  absl::Mutex mu_;
  // Finished jobs already counted: per state, the newest finish time seen
  // and the ids finished at that very millisecond.
  std::map<int, std::pair<int64_t, std::set<std::string>>> seen_ ABSL_GUARDED_BY(mu_);
  std::map<int, int64_t> finished_ ABSL_GUARDED_BY(mu_);
  int64_t steps_ ABSL_GUARDED_BY(mu_) = 0;
  std::map<std::string, int64_t> errors_ ABSL_GUARDED_BY(mu_);
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_METRICS_ENDPOINT_H_
