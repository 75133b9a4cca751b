#ifndef CABLESIM_SERVER_CABLESIM_SERVICE_H_
#define CABLESIM_SERVER_CABLESIM_SERVICE_H_

// cablesim.v1.CablesimService (proto/cablesim/v1/service.proto): a thin
// layer that converts requests, validates them (convert/), checks the
// server's limits (server/request_checks.h), runs the engine
// (engine/run/simulation.h) or hands work to the JobManager, and converts the
// results back (convert/run_proto.h).
//
// Streams honour flow control: the engine runs in the RPC's thread and
// waits while a frame batch cannot be sent, so a slow reader never makes
// the server buffer more than one batch; a watchdog cancels a stream whose
// write has waited longer than the stall timeout.

#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "absl/synchronization/mutex.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "server/job_manager.h"
#include "server/page_token.h"
#include "server/request_checks.h"

namespace cablesim {

class CablesimServiceImpl final : public v1::CablesimService::Service {
 public:
  // `jobs` may be null (an in-process service for `cablesim run`): the job
  // and sweep calls then answer UNIMPLEMENTED.
  // `log`: report on stderr.
  // `tokens`: bearer token -> tenant; empty: no authentication.
  CablesimServiceImpl(JobManager* jobs, ServerLimits limits, bool log = true,
                      std::map<std::string, std::string> tokens = {});
  ~CablesimServiceImpl() override;

  grpc::Status Validate(grpc::ServerContext* context, const v1::ValidateRequest* request,
                        v1::ValidateResponse* response) override;
  grpc::Status Run(grpc::ServerContext* context, const v1::RunRequest* request,
                   grpc::ServerWriter<v1::RunEvent>* writer) override;
  // Run's body, writing to any stream: `cablesim run` without --server
  // calls it directly (client/service_client.h RunInProcess), so a run in
  // the user's own process goes through this same code without starting
  // gRPC (its threads, completion queues and in-process channel).
  grpc::Status RunTo(grpc::ServerContext* context, const v1::RunRequest* request,
                     grpc::ServerWriterInterface<v1::RunEvent>* writer);
  grpc::Status SubmitJob(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                         v1::Job* response) override;
  grpc::Status GetJob(grpc::ServerContext* context, const v1::GetJobRequest* request,
                      v1::Job* response) override;
  grpc::Status ListJobs(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                        v1::ListJobsResponse* response) override;
  grpc::Status CancelJob(grpc::ServerContext* context, const v1::CancelJobRequest* request,
                         v1::Job* response) override;
  grpc::Status WatchJob(grpc::ServerContext* context, const v1::WatchJobRequest* request,
                        grpc::ServerWriter<v1::Job>* writer) override;
  grpc::Status GetJobResult(grpc::ServerContext* context, const v1::GetJobResultRequest* request,
                            grpc::ServerWriter<v1::RunEvent>* writer) override;
  grpc::Status GetEnergy(grpc::ServerContext* context, const v1::EnergyRequest* request,
                         v1::EnergyResponse* response) override;
  grpc::Status SubmitSweep(grpc::ServerContext* context, const v1::SubmitSweepRequest* request,
                           v1::Sweep* response) override;
  grpc::Status WatchSweep(grpc::ServerContext* context, const v1::WatchSweepRequest* request,
                          grpc::ServerWriter<v1::SweepEvent>* writer) override;
  grpc::Status DeleteJob(grpc::ServerContext* context, const v1::DeleteJobRequest* request,
                         v1::DeleteResponse* response) override;
  grpc::Status DeleteSweep(grpc::ServerContext* context, const v1::DeleteSweepRequest* request,
                           v1::DeleteResponse* response) override;
  grpc::Status GetSweepResults(grpc::ServerContext* context,
                               const v1::GetSweepResultsRequest* request,
                               v1::SweepResults* response) override;
  grpc::Status GetServerInfo(grpc::ServerContext* context,
                             const v1::GetServerInfoRequest* request,
                             v1::ServerInfo* response) override;
  // A coupling session (server/couple_service.cc).
  grpc::Status Couple(grpc::ServerContext* context,
                      grpc::ServerReaderWriter<v1::CoupleResponse, v1::CoupleRequest>* stream)
      override;

  // Tracks one stream's writes for the stall watchdog.
  struct StreamWatch {
    grpc::ServerContext* context;
    std::atomic<int64_t> write_started_ns{0};  // 0: not writing
    bool counted = false;                      // holds a max_streams slot
  };
  // A counted stream whose write has waited this long for its client to
  // read is "stalled": it still counts against its own client's
  // max_streams_per_peer, but no longer against max_streams, so that
  // streams that stop reading cannot lock other clients out of Run until
  // the stall timeout cuts them (at most 2 x max_streams streams in all).
  static constexpr int64_t kStalledAfterNs = 1'000'000'000;

 private:
  // The stored result of finished job `id` (and the job): NOT_FOUND,
  // FAILED_PRECONDITION while it has no result, UNIMPLEMENTED without jobs.
  grpc::Status FinishedResult(const std::string& id, v1::Job* job, StoredResult* result) const;
  grpc::Status NoJobs() const;
  // UNAUTHENTICATED unless the call carries `authorization: Bearer T` with
  // T one of tokens_ (OK when there are none).
  // `tenant`: the token's tenant.
  grpc::Status Authorize(grpc::ServerContext* context, std::string* tenant) const;
  // NOT_FOUND unless job or sweep `id` exists and, with tokens, belongs to
  // `tenant`.
  grpc::Status Owned(const std::string& id, const std::string& tenant) const;
  // Whose share a call counts against (max_streams_per_peer,
  // max_queued_jobs_per_peer): the tenant with tokens, else the client's
  // address without its port.
  std::string ClientKey(const grpc::ServerContext* context, const std::string& tenant) const;
  void Watchdog();

  JobManager* jobs_;
  const ServerLimits limits_;
  const bool log_;
  const std::map<std::string, std::string> tokens_;
  // ListJobs' page tokens, keyed by the store's secret (set with jobs_).
  std::optional<PageTokenCodec> page_tokens_;
  absl::Mutex mu_;
  // Counted streams, in all and per peer (StreamSlot).
  int streams_ ABSL_GUARDED_BY(mu_) = 0;
  std::map<std::string, int> peer_streams_ ABSL_GUARDED_BY(mu_);
  std::map<StreamWatch*, bool> watched_ ABSL_GUARDED_BY(mu_);
  bool stop_ ABSL_GUARDED_BY(mu_) = false;
  std::thread watchdog_;

  // Scene-carrying unary calls in progress, in all and per client, and
  // the memory they are estimated to hold (UnarySlot).
  int unary_calls_ ABSL_GUARDED_BY(mu_) = 0;
  std::map<std::string, int> peer_unary_calls_ ABSL_GUARDED_BY(mu_);
  int64_t inflight_bytes_ ABSL_GUARDED_BY(mu_) = 0;

  friend class StreamSlot;
  friend class UnarySlot;
};

}  // namespace cablesim

#endif  // CABLESIM_SERVER_CABLESIM_SERVICE_H_
