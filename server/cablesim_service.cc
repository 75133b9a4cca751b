#include "server/cablesim_service.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <limits>
#include <set>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cablesim/version.h"
#include "convert/plausible_ranges.h"
#include "convert/run_proto.h"
#include "convert/scene_file.h"
#include "server/energy_report.h"
#include "server/store/job_store.h"
#include "server/stream_slot.h"

namespace cablesim {

// Holds one scene-carrying unary call's place (ServerLimits::
// max_unary_calls, max_unary_calls_per_peer) and its estimated memory
// (max_inflight_bytes): a call that would go beyond any of them is
// refused at once, naming the budget, instead of growing the server.
class UnarySlot {
 public:
  UnarySlot(CablesimServiceImpl* service, const std::string& client, int64_t request_bytes)
      : service_(service),
        client_(client),
        bytes_(request_bytes > std::numeric_limits<int64_t>::max() / kRequestMemoryFactor
                   ? std::numeric_limits<int64_t>::max()
                   : request_bytes * kRequestMemoryFactor) {
    absl::MutexLock lock(&service_->mu_);
    const ServerLimits& limits = service_->limits_;
    int& mine = service_->peer_unary_calls_[client_];
    if (service_->unary_calls_ >= limits.max_unary_calls) {
      refusal_ = absl::StrCat("the server is already checking ", service_->unary_calls_,
                              " scenes, its limit is ", limits.max_unary_calls,
                              " (max_unary_calls); try again later");
    } else if (mine >= limits.max_unary_calls_per_peer) {
      refusal_ = absl::StrCat("this client (", client_, ") already has ", mine,
                              " scenes being checked, the server's limit is ",
                              limits.max_unary_calls_per_peer,
                              " (max_unary_calls_per_peer); try again later");
    } else if (bytes_ > limits.max_inflight_bytes - service_->inflight_bytes_) {
      refusal_ = absl::StrCat(
          "this request would hold about ", bytes_, " bytes while it is checked (",
          kRequestMemoryFactor, " x its ", request_bytes, " bytes) with ",
          service_->inflight_bytes_, " bytes already held by requests in flight: over the "
          "server's memory budget of ", limits.max_inflight_bytes,
          " bytes (max_inflight_bytes); try again later");
    }
    acquired_ = refusal_.empty();
    if (acquired_) {
      ++service_->unary_calls_;
      ++mine;
      service_->inflight_bytes_ += bytes_;
    } else if (mine == 0) {
      service_->peer_unary_calls_.erase(client_);
    }
  }
  ~UnarySlot() {
    if (!acquired_) return;
    absl::MutexLock lock(&service_->mu_);
    --service_->unary_calls_;
    if (--service_->peer_unary_calls_[client_] == 0) service_->peer_unary_calls_.erase(client_);
    service_->inflight_bytes_ -= bytes_;
  }
  UnarySlot(const UnarySlot&) = delete;
  UnarySlot& operator=(const UnarySlot&) = delete;
  // OK, or RESOURCE_EXHAUSTED naming the budget.
  grpc::Status status() const {
    return acquired_ ? grpc::Status::OK
                     : grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, refusal_);
  }

 private:
  CablesimServiceImpl* service_;
  const std::string client_;
  const int64_t bytes_;
  bool acquired_ = false;
  std::string refusal_;
};

namespace {

grpc::Status ToGrpc(const absl::Status& s) {
  if (s.ok()) return grpc::Status::OK;
  return grpc::Status(static_cast<grpc::StatusCode>(s.code()), std::string(s.message()));
}

constexpr int kMaxBatchValues = 128 * 1024;

int BatchSize(int requested) {
  if (requested <= 0) return 64;
  return std::min(requested, 4096);
}

bool Finished(v1::JobState s) {
  return s == v1::SUCCEEDED || s == v1::FAILED || s == v1::CANCELLED;
}

// Streams a run: header, batches of frame rows, (the caller writes the
// summary).
class StreamingSink : public FrameSink {
 public:
  StreamingSink(grpc::ServerWriterInterface<v1::RunEvent>* writer,
                CablesimServiceImpl::StreamWatch* watch,
                int batch, std::string scene_name, double end_time_s)
      : writer_(writer),
        watch_(watch),
        batch_(batch),
        scene_name_(std::move(scene_name)),
        end_time_s_(end_time_s) {}

  absl::Status OnStart(const ModelInfo& info) override {
    v1::RunEvent header;
    v1::RunHeader* h = header.mutable_header();
    SetFrameHeader(info, h);
    h->set_scene_name(scene_name_);
    h->set_end_time_s(end_time_s_);
    if (!TimedWrite(writer_, header, watch_)) return Gone();
    event_.mutable_frames()->mutable_values()->Reserve(batch_ * h->columns_size());
    return absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    v1::FrameBatch* b = event_.mutable_frames();
    AppendFrameRow(frame, b->mutable_values());
    b->set_rows(b->rows() + 1);
    // Also bound the message (1 MiB of numbers), whatever the probe count.
    if (b->rows() >= batch_ || b->values_size() >= kMaxBatchValues) return Flush();
    return absl::OkStatus();
  }
  absl::Status Flush() {
    v1::FrameBatch* b = event_.mutable_frames();
    if (b->rows() == 0) return absl::OkStatus();
    const bool ok = TimedWrite(writer_, event_, watch_);
    b->set_rows(0);
    b->mutable_values()->Clear();
    return ok ? absl::OkStatus() : Gone();
  }
  bool gone() const { return gone_; }

 private:
  absl::Status Gone() {
    gone_ = true;
    return absl::CancelledError("the client went away");
  }
  grpc::ServerWriterInterface<v1::RunEvent>* writer_;
  CablesimServiceImpl::StreamWatch* watch_;
  const int batch_;
  const std::string scene_name_;
  const double end_time_s_;
  v1::RunEvent event_;
  bool gone_ = false;
};

// Keeps the rows of a run in memory (GetEnergy of a scene).
class RowSink : public FrameSink {
 public:
  explicit RowSink(StoredResult* result) : result_(result) {}
  absl::Status OnStart(const ModelInfo& info) override {
    SetFrameHeader(info, &result_->header);
    return absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    scratch_.Clear();
    AppendFrameRow(frame, &scratch_);
    result_->values.insert(result_->values.end(), scratch_.begin(), scratch_.end());
    return absl::OkStatus();
  }

 private:
  StoredResult* result_;
  google::protobuf::RepeatedField<double> scratch_;
};

RunControl ControlFor(grpc::ServerContext* context, const ServerLimits& limits) {
  RunControl control;
  // ServerContext::IsCancelled polls the call's completion queue (a system
  // call): at every step it doubled the cost of a small scene. Ask at most
  // every millisecond instead, so a cancelled or expired call stops at the
  // first step after that.
  control.should_stop = [context, next = int64_t{0}]() mutable {
    const int64_t now = NowNs();
    if (now < next) return false;
    next = now + 1'000'000;
    return context->IsCancelled();
  };
  control.max_steps = 2 * limits.max_steps;
  return control;
}

}  // namespace

grpc::Status CablesimServiceImpl::Owned(const std::string& id, const std::string& tenant) const {
  if (tokens_.empty() || jobs_ == nullptr) return grpc::Status::OK;
  absl::StatusOr<std::string> owner = jobs_->store()->Tenant(id);
  if (!owner.ok()) return ToGrpc(owner.status());
  if (*owner != tenant) {
    // As if it did not exist: another tenant learns nothing about it.
    return grpc::Status(grpc::StatusCode::NOT_FOUND,
                        absl::StrCat("no ", IsSweepId(id) ? "sweep" : "job", " \"", id, "\""));
  }
  return grpc::Status::OK;
}

std::string CablesimServiceImpl::ClientKey(const grpc::ServerContext* context,
                                           const std::string& tenant) const {
  return tokens_.empty() ? StreamSlot::PeerOf(context) : absl::StrCat("tenant ", tenant);
}

grpc::Status CablesimServiceImpl::Authorize(grpc::ServerContext* context,
                                            std::string* tenant) const {
  if (tokens_.empty()) return grpc::Status::OK;
  const auto& metadata = context->client_metadata();
  const auto it = metadata.find("authorization");
  if (it == metadata.end()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "authorization: this server needs a bearer token (metadata "
                        "\"authorization: Bearer TOKEN\")");
  }
  const absl::string_view value(it->second.data(), it->second.size());
  constexpr absl::string_view kBearer = "Bearer ";
  const auto token = absl::StartsWith(value, kBearer)
                         ? tokens_.find(std::string(value.substr(kBearer.size())))
                         : tokens_.end();
  if (token == tokens_.end()) {
    return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                        "authorization: not a token this server knows");
  }
  *tenant = token->second;
  return grpc::Status::OK;
}

CablesimServiceImpl::CablesimServiceImpl(JobManager* jobs, ServerLimits limits, bool log,
                                         std::map<std::string, std::string> tokens)
    : jobs_(jobs), limits_(limits), log_(log), tokens_(std::move(tokens)) {
  if (jobs_ != nullptr) page_tokens_.emplace(jobs_->store()->page_token_secret());
  watchdog_ = std::thread([this] { Watchdog(); });
}

CablesimServiceImpl::~CablesimServiceImpl() {
  {
    absl::MutexLock lock(&mu_);
    stop_ = true;
  }
  watchdog_.join();
}

void CablesimServiceImpl::Watchdog() {
  const absl::Duration period =
      std::clamp(limits_.stall_timeout / 10, absl::Milliseconds(10), absl::Milliseconds(500));
  const int64_t stall_ns = absl::ToInt64Nanoseconds(limits_.stall_timeout);
  absl::MutexLock lock(&mu_);
  while (true) {
    auto stopping = [this]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { return stop_; };
    if (mu_.AwaitWithTimeout(absl::Condition(&stopping), period)) return;
    const int64_t now = NowNs();
    for (auto& [watch, unused] : watched_) {
      const int64_t started = watch->write_started_ns.load();
      if (started != 0 && now - started > stall_ns) {
        if (log_)
          std::cerr << "cablesim-server: cancelling a stream whose client has read nothing for "
                    << absl::FormatDuration(limits_.stall_timeout) << " (" << watch->context->peer()
                    << ")\n";
        watch->context->TryCancel();
        watch->write_started_ns = 0;
      }
    }
  }
}

grpc::Status CablesimServiceImpl::FinishedResult(const std::string& id, v1::Job* job,
                                                 StoredResult* result) const {
  if (jobs_ == nullptr) return NoJobs();
  absl::StatusOr<v1::Job> found = jobs_->Get(id);
  if (!found.ok()) return ToGrpc(found.status());
  if (!Finished(found->state()) || !found->has_summary()) {
    return grpc::Status(
        grpc::StatusCode::FAILED_PRECONDITION,
        absl::StrCat("job ", found->id(), " is ", v1::JobState_Name(found->state()), ": no result"));
  }
  absl::StatusOr<StoredResult> stored = jobs_->store()->GetResult(found->id());
  if (!stored.ok()) return ToGrpc(stored.status());
  *job = *std::move(found);
  *result = *std::move(stored);
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::NoJobs() const {
  return grpc::Status(grpc::StatusCode::UNIMPLEMENTED,
                      "this service has no job store (start cablesim-server with --data-dir)");
}

grpc::Status CablesimServiceImpl::Validate(grpc::ServerContext* context,
                                           const v1::ValidateRequest* request,
                                           v1::ValidateResponse* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  UnarySlot slot(this, ClientKey(context, tenant),
                 static_cast<int64_t>(request->ByteSizeLong()));
  if (grpc::Status held = slot.status(); !held.ok()) return held;
  // The same checks as Run and SubmitJob, limits included (so a scene the
  // server would refuse is never called valid, and costs no more to
  // validate than to refuse).
  const absl::StatusOr<v1::Scene> scene =
      SceneOrDeckOfRequest(request->has_scene(), request->scene(), request->scene_json(),
                           request->scene_moordyn());
  absl::StatusOr<CheckedScene> checked =
      scene.ok() ? CheckScene(*scene, limits_, ControlFor(context, limits_).should_stop)
                 : absl::StatusOr<CheckedScene>(scene.status());
  if (checked.ok()) {
    response->set_valid(true);
    *response->mutable_model() = ModelInfoToProto(checked->info);
    for (const std::string& w : checked->scene.warnings) response->add_warnings(w);
    return grpc::Status::OK;
  }
  const absl::StatusCode code = checked.status().code();
  if (code != absl::StatusCode::kInvalidArgument && code != absl::StatusCode::kResourceExhausted) {
    return ToGrpc(checked.status());
  }
  response->set_valid(false);
  SetFieldError(checked.status(), response->add_errors());
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::Run(grpc::ServerContext* context, const v1::RunRequest* request,
                                      grpc::ServerWriter<v1::RunEvent>* writer) {
  return RunTo(context, request, writer);
}

grpc::Status CablesimServiceImpl::RunTo(grpc::ServerContext* context,
                                        const v1::RunRequest* request,
                                        grpc::ServerWriterInterface<v1::RunEvent>* writer) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  StreamSlot slot(this, context, /*counted=*/true, ClientKey(context, tenant));
  if (!slot.acquired()) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, slot.refusal());
  }
  absl::StatusOr<v1::Scene> scene =
      SceneOrDeckOfRequest(request->has_scene(), request->scene(), request->scene_json(),
                           request->scene_moordyn());
  if (!scene.ok()) return ToGrpc(scene.status());
  if (request->strict()) scene->mutable_solver()->set_strict(true);
  absl::StatusOr<CheckedScene> checked =
      CheckScene(*scene, limits_, ControlFor(context, limits_).should_stop);
  if (!checked.ok()) return ToGrpc(checked.status());
  StreamingSink sink(writer, slot.watch(), BatchSize(request->frames_per_batch()),
                     checked->scene.name, checked->end_time_s);
  absl::StatusOr<RunSummary> summary =
      RunSceneWithinMemory(&*checked, &sink, ControlFor(context, limits_),
                             limits_.compute_nice);
  if (!summary.ok()) return ToGrpc(summary.status());
  if (sink.gone() || context->IsCancelled()) {
    return grpc::Status(grpc::StatusCode::CANCELLED, "the client cancelled or went away");
  }
  if (!sink.Flush().ok()) return grpc::Status(grpc::StatusCode::CANCELLED, "the client went away");
  v1::RunEvent last;
  *last.mutable_summary() = SummaryToProto(*summary);
  if (!TimedWrite(writer, last, slot.watch())) {
    return grpc::Status(grpc::StatusCode::CANCELLED, "the client went away");
  }
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::SubmitJob(grpc::ServerContext* context,
                                            const v1::SubmitJobRequest* request,
                                            v1::Job* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  UnarySlot slot(this, ClientKey(context, tenant),
                 static_cast<int64_t>(request->ByteSizeLong()));
  if (grpc::Status held = slot.status(); !held.ok()) return held;
  if (jobs_ == nullptr) return NoJobs();
  absl::StatusOr<v1::Scene> scene =
      SceneOrDeckOfRequest(request->has_scene(), request->scene(), request->scene_json(),
                           request->scene_moordyn());
  if (!scene.ok()) return ToGrpc(scene.status());
  if (request->strict()) scene->mutable_solver()->set_strict(true);
  absl::StatusOr<v1::Job> job = jobs_->Submit(*scene, ClientKey(context, tenant), tenant,
                                              ControlFor(context, limits_).should_stop);
  if (!job.ok()) return ToGrpc(job.status());
  *response = std::move(*job);
  if (log_) std::cerr << "cablesim-server: job " << response->id() << " queued\n";
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::GetJob(grpc::ServerContext* context,
                                         const v1::GetJobRequest* request,
                                         v1::Job* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  absl::StatusOr<v1::Job> job = jobs_->Get(request->id());
  if (!job.ok()) return ToGrpc(job.status());
  *response = std::move(*job);
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::ListJobs(grpc::ServerContext* context,
                                           const v1::ListJobsRequest* request,
                                           v1::ListJobsResponse* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  const int asked = request->page_size() > 0 ? request->page_size() : request->limit();
  const int limit = asked <= 0 ? 100 : std::min(asked, 10000);
  // Keyset paging: the token hides and authenticates the order key of the
  // last job listed (page_token.h), bound to the tenant and the filters.
  const std::string query = absl::StrCat(static_cast<int>(request->state()), "/",
                                         request->sweep_id());
  int64_t after_key = 0;
  if (!request->page_token().empty()) {
    absl::StatusOr<int64_t> key = page_tokens_->Decode(request->page_token(), tenant, query);
    if (!key.ok()) return ToGrpc(key.status());
    after_key = *key;
  }
  // One more than asked, to know whether another page follows.
  std::vector<int64_t> keys;
  absl::StatusOr<std::vector<v1::Job>> jobs =
      jobs_->store()->ListJobs(request->state(), request->sweep_id(), limit + 1, after_key,
                               tokens_.empty() ? nullptr : &tenant, &keys);
  if (!jobs.ok()) return ToGrpc(jobs.status());
  // Never a response over the message limit: stop at half of it.
  const size_t budget = static_cast<size_t>(limits_.max_message_bytes) / 2;
  size_t bytes = 0;
  for (size_t i = 0; i < jobs->size(); ++i) {
    v1::Job& job = (*jobs)[i];
    const size_t size = job.ByteSizeLong() + 8;
    const bool full = static_cast<int>(i) == limit || (i > 0 && bytes + size > budget);
    if (full) {
      absl::StatusOr<std::string> token = page_tokens_->Encode(keys[i - 1], tenant, query);
      if (!token.ok()) return ToGrpc(token.status());
      response->set_next_page_token(*token);
      break;
    }
    // A row that fails its checksum (JobStore::ListJobs' placeholder):
    // left out and counted, the rest of the page served.
    if (job.state() == v1::JOB_STATE_UNSPECIFIED) {
      response->set_damaged_skipped(response->damaged_skipped() + 1);
      continue;
    }
    jobs_->AddProgress(&job);
    bytes += size;
    *response->add_jobs() = std::move(job);
  }
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::CancelJob(grpc::ServerContext* context,
                                            const v1::CancelJobRequest* request,
                                            v1::Job* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  absl::StatusOr<v1::Job> job = jobs_->Cancel(request->id());
  if (!job.ok()) return ToGrpc(job.status());
  *response = std::move(*job);
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::DeleteJob(grpc::ServerContext* context,
                                            const v1::DeleteJobRequest* request,
                                            v1::DeleteResponse* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  absl::StatusOr<int64_t> freed = jobs_->DeleteJob(request->id());
  if (!freed.ok()) return ToGrpc(freed.status());
  response->set_freed_bytes(*freed);
  if (log_) std::cerr << "cablesim-server: job " << request->id() << " deleted\n";
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::DeleteSweep(grpc::ServerContext* context,
                                              const v1::DeleteSweepRequest* request,
                                              v1::DeleteResponse* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  absl::StatusOr<int64_t> freed = jobs_->DeleteSweep(request->id());
  if (!freed.ok()) return ToGrpc(freed.status());
  response->set_freed_bytes(*freed);
  if (log_) std::cerr << "cablesim-server: sweep " << request->id() << " deleted\n";
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::WatchJob(grpc::ServerContext* context,
                                           const v1::WatchJobRequest* request,
                                           grpc::ServerWriter<v1::Job>* writer) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  StreamSlot slot(this, context, /*counted=*/false);
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  std::string last;
  while (true) {
    const uint64_t seen = jobs_->version();
    absl::StatusOr<v1::Job> job = jobs_->Get(request->id());
    if (!job.ok()) return ToGrpc(job.status());
    std::string now = job->SerializeAsString();
    if (now != last) {
      if (!TimedWrite(writer, *job, slot.watch())) {
        return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
      }
      last = std::move(now);
    }
    if (Finished(job->state())) return grpc::Status::OK;
    if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    if (jobs_->shutting_down()) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    }
    jobs_->WaitForChange(seen, absl::Seconds(1));
  }
}

grpc::Status CablesimServiceImpl::GetJobResult(grpc::ServerContext* context,
                                               const v1::GetJobResultRequest* request,
                                               grpc::ServerWriter<v1::RunEvent>* writer) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  v1::Job job;
  StoredResult result;
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  if (grpc::Status s = FinishedResult(request->id(), &job, &result); !s.ok()) return s;
  StreamSlot slot(this, context, /*counted=*/false);
  v1::RunEvent event;
  *event.mutable_header() = result.header;
  event.mutable_header()->set_scene_name(job.name());
  event.mutable_header()->set_end_time_s(job.end_time_s());
  if (!TimedWrite(writer, event, slot.watch())) {
    return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
  }
  const size_t columns = std::max(1, result.header.columns_size());
  const size_t batch = BatchSize(request->frames_per_batch());
  const size_t rows = result.values.size() / columns;
  const size_t rows_per_message = std::max<size_t>(1, std::min(batch, kMaxBatchValues / columns));
  for (size_t r = 0; r < rows; r += rows_per_message) {
    const size_t n = std::min(rows_per_message, rows - r);
    event.mutable_frames()->set_rows(static_cast<int>(n));
    event.mutable_frames()->mutable_values()->Assign(result.values.begin() + r * columns,
                                                     result.values.begin() + (r + n) * columns);
    if (!TimedWrite(writer, event, slot.watch())) {
      return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
    }
  }
  *event.mutable_summary() = job.summary();
  if (!TimedWrite(writer, event, slot.watch())) {
    return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
  }
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::GetEnergy(grpc::ServerContext* context,
                                            const v1::EnergyRequest* request,
                                            v1::EnergyResponse* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (request->has_scene()) {
    StreamSlot slot(this, context, /*counted=*/true, ClientKey(context, tenant));
    if (!slot.acquired()) {
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, slot.refusal());
    }
    absl::StatusOr<CheckedScene> checked =
        CheckScene(request->scene(), limits_, ControlFor(context, limits_).should_stop);
    if (!checked.ok()) return ToGrpc(checked.status());
    StoredResult result;
    RowSink sink(&result);
    absl::StatusOr<RunSummary> summary =
        RunSceneWithinMemory(&*checked, &sink, ControlFor(context, limits_),
                             limits_.compute_nice);
    if (!summary.ok()) return ToGrpc(summary.status());
    if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    *response = EnergyFromTrajectory(result.header, result.values, SummaryToProto(*summary));
    return grpc::Status::OK;
  }
  if (request->job_id().empty()) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "source: give job_id or scene");
  }
  v1::Job job;
  StoredResult result;
  if (grpc::Status s = Owned(request->job_id(), tenant); !s.ok()) return s;
  if (grpc::Status s = FinishedResult(request->job_id(), &job, &result); !s.ok()) return s;
  *response = EnergyFromTrajectory(result.header, result.values, job.summary());
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::SubmitSweep(grpc::ServerContext* context,
                                              const v1::SubmitSweepRequest* request,
                                              v1::Sweep* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  UnarySlot slot(this, ClientKey(context, tenant),
                 static_cast<int64_t>(request->ByteSizeLong()));
  if (grpc::Status held = slot.status(); !held.ok()) return held;
  if (jobs_ == nullptr) return NoJobs();
  v1::SubmitSweepRequest submitted = *request;
  if (!request->base_json().empty()) {
    absl::StatusOr<v1::Scene> base =
        SceneOfRequest(request->has_base(), request->base(), request->base_json(), "base_json");
    if (!base.ok()) return ToGrpc(base.status());
    *submitted.mutable_base() = std::move(*base);
    submitted.clear_base_json();
  }
  absl::StatusOr<v1::Sweep> sweep =
      jobs_->SubmitSweep(submitted, ClientKey(context, tenant), tenant);
  if (!sweep.ok()) return ToGrpc(sweep.status());
  *response = std::move(*sweep);
  if (log_)
    std::cerr << "cablesim-server: sweep " << response->id() << " queued (" << response->items()
              << " items)\n";
  return grpc::Status::OK;
}

namespace {

v1::SweepItem ItemOf(JobManager* jobs, const v1::Sweep& sweep, const v1::Job& job) {
  v1::SweepItem item;
  item.set_index(job.sweep_index());
  for (double v : SweepAxisValues(sweep.axes(), job.sweep_index())) item.add_axis_values(v);
  item.set_job_id(job.id());
  item.set_state(job.state());
  if (job.has_summary()) *item.mutable_summary() = job.summary();
  if (Finished(job.state())) {
    absl::StatusOr<StoredResult> result = jobs->store()->GetResult(job.id());
    if (result.ok()) {
      const size_t columns = std::max(1, result->header.columns_size());
      if (result->values.size() >= columns) {
        item.mutable_final_values()->Assign(result->values.end() - columns, result->values.end());
      }
      *item.mutable_energy() =
          EnergyFromTrajectory(result->header, result->values, job.summary()).report();
    }
    if (job.state() == v1::SUCCEEDED) {
      for (std::string& f : ThresholdFailures(sweep.thresholds(), job.summary()))
        item.add_threshold_failures(std::move(f));
    }
  }
  return item;
}

}  // namespace

grpc::Status CablesimServiceImpl::WatchSweep(grpc::ServerContext* context,
                                             const v1::WatchSweepRequest* request,
                                             grpc::ServerWriter<v1::SweepEvent>* writer) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  StreamSlot slot(this, context, /*counted=*/false);
  std::set<std::string> reported;
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  // The `finished` count of the last event sent (-1: none yet, so the
  // first pass sends the progress as it is): the sweep row and its
  // items are read one after the other, so an item can finish in between
  // and be reported with the count from before it; the last event must
  // still carry the final count (a client's progress ends at items/items).
  int64_t sent_finished = -1;
  // Sends the sweep's progress, with `item` when given; false when the
  // client is gone.
  auto send = [&](const v1::Sweep& sweep, const v1::Job* item) {
    v1::SweepEvent event;
    *event.mutable_progress() = sweep;
    if (item != nullptr) *event.mutable_item() = ItemOf(jobs_, sweep, *item);
    sent_finished = sweep.finished();
    return TimedWrite(writer, event, slot.watch());
  };
  while (true) {
    const uint64_t seen = jobs_->version();
    absl::StatusOr<v1::Sweep> sweep = jobs_->store()->GetSweep(request->id());
    if (!sweep.ok()) return ToGrpc(sweep.status());
    absl::StatusOr<std::vector<v1::Job>> items =
        jobs_->store()->ListJobs(v1::JOB_STATE_UNSPECIFIED, request->id(), sweep->items());
    if (!items.ok()) return ToGrpc(items.status());
    bool sent = sent_finished >= 0 || send(*sweep, nullptr);
    // Oldest item first.
    for (auto it = items->rbegin(); sent && it != items->rend(); ++it) {
      if (!Finished(it->state()) || reported.count(it->id())) continue;
      reported.insert(it->id());
      sent = send(*sweep, &*it);
    }
    const bool done = sweep->finished() == sweep->items();
    if (sent && done && sent_finished != sweep->finished()) sent = send(*sweep, nullptr);
    if (!sent) return grpc::Status(grpc::StatusCode::CANCELLED, "client gone");
    if (done) return grpc::Status::OK;
    if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "cancelled");
    if (jobs_->shutting_down()) {
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, "the server is shutting down");
    }
    jobs_->WaitForChange(seen, absl::Seconds(1));
  }
}

grpc::Status CablesimServiceImpl::GetSweepResults(grpc::ServerContext* context,
                                                  const v1::GetSweepResultsRequest* request,
                                                  v1::SweepResults* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  if (jobs_ == nullptr) return NoJobs();
  if (grpc::Status s = Owned(request->id(), tenant); !s.ok()) return s;
  absl::StatusOr<v1::Sweep> sweep = jobs_->store()->GetSweep(request->id());
  if (!sweep.ok()) return ToGrpc(sweep.status());
  absl::StatusOr<std::vector<v1::Job>> jobs =
      jobs_->store()->ListJobs(v1::JOB_STATE_UNSPECIFIED, request->id(), sweep->items());
  if (!jobs.ok()) return ToGrpc(jobs.status());
  *response->mutable_sweep() = *sweep;
  for (auto it = jobs->rbegin(); it != jobs->rend(); ++it) {
    if (it->state() == v1::JOB_STATE_UNSPECIFIED) continue;  // a damaged row (ListJobs)
    *response->add_items() = ItemOf(jobs_, *sweep, *it);
    if (response->final_columns().empty() && Finished(it->state())) {
      absl::StatusOr<StoredResult> result = jobs_->store()->GetResult(it->id());
      if (result.ok()) *response->mutable_final_columns() = result->header.columns();
    }
  }
  return grpc::Status::OK;
}

grpc::Status CablesimServiceImpl::GetServerInfo(grpc::ServerContext* context,
                                                const v1::GetServerInfoRequest*,
                                                v1::ServerInfo* response) {
  std::string tenant;
  if (grpc::Status auth = Authorize(context, &tenant); !auth.ok()) return auth;
  response->set_version(CABLESIM_VERSION);
  response->set_build_type(CABLESIM_BUILD_TYPE);
  response->set_sanitizers(CABLESIM_SANITIZERS);
  response->set_max_elements(limits_.max_elements);
  response->set_max_steps(limits_.max_steps);
  response->set_max_frames(limits_.max_frames);
  response->set_max_trajectory_values(limits_.max_trajectory_values);
  response->set_max_sweep_items(limits_.max_sweep_items);
  response->set_max_streams(limits_.max_streams);
  response->set_max_message_bytes(limits_.max_message_bytes);
  response->set_stall_timeout_s(absl::ToDoubleSeconds(limits_.stall_timeout));
  response->set_max_scene_bytes(kMaxSceneBytes);
  response->set_max_scene_nesting(kMaxSceneNesting);
  // The converter's bound on names, or the server's own on every string
  // of a request (--max-name-bytes) when that is lower.
  response->set_max_name_bytes(static_cast<int32_t>(
      std::min<int64_t>(plausible::kMaxNameBytes, limits_.max_name_bytes)));
  response->set_jobs(jobs_ != nullptr);
  response->set_max_modes(limits_.max_modes);
  response->set_max_modal_bytes(limits_.max_modal_bytes);
  response->set_max_coordinates(limits_.max_coordinates);
  response->set_max_streams_per_peer(limits_.max_streams_per_peer);
  response->set_max_queued_jobs_per_peer(limits_.max_queued_jobs_per_peer);
  if (limits_.retention_max_age != absl::InfiniteDuration()) {
    response->set_retention_max_age_s(absl::ToDoubleSeconds(limits_.retention_max_age));
  }
  if (limits_.retention_max_bytes != std::numeric_limits<int64_t>::max()) {
    response->set_retention_max_bytes(limits_.retention_max_bytes);
  }
  return grpc::Status::OK;
}

}  // namespace cablesim
