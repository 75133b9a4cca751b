// `cablesim run` without --server calls the in-process service directly
// (RunInProcess) instead of through an in-process gRPC channel. The two
// paths must give the same frames, bit for bit, the same summary and the
// same errors: the reference here is the channel path, which the daemon
// and every remote client use.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <optional>
#include <string>
#include <vector>

#include "client/service_client.h"
#include "client/summary_json.h"
#include "convert/scene_file.h"

namespace cablesim {
namespace {

class CollectingSink : public FrameSink {
 public:
  absl::Status OnFrame(const Frame& frame) override {
    rows.push_back({frame.t, frame.probes[0].position_m.x(), frame.probes[0].position_m.y(),
                    frame.energy.total, frame.constraint_violation});
    return absl::OkStatus();
  }
  std::vector<std::vector<double>> rows;
};

v1::RunRequest PendulumRequest(double duration) {
  absl::StatusOr<v1::Scene> scene =
      ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/falling-pendulum.json");
  EXPECT_TRUE(scene.ok()) << scene.status();
  scene->mutable_solver()->set_duration(duration);
  v1::RunRequest request;
  *request.mutable_scene() = *scene;
  request.set_frames_per_batch(7);  // several batches
  return request;
}

absl::StatusOr<RunSummary> OverChannel(const v1::RunRequest& request, CollectingSink* sink) {
  absl::StatusOr<std::unique_ptr<Connection>> c = Connect(std::nullopt, false, 1);
  if (!c.ok()) return c.status();
  grpc::ClientContext context;
  auto reader = (*c)->stub->Run(&context, request);
  return ReadRunStream(&context, reader.get(), sink, nullptr);
}

absl::StatusOr<RunSummary> Direct(const v1::RunRequest& request, CollectingSink* sink) {
  absl::StatusOr<std::unique_ptr<Connection>> c = ConnectInProcessDirect();
  if (!c.ok()) return c.status();
  EXPECT_EQ((*c)->stub, nullptr);  // no gRPC channel was made
  return RunInProcess(c->get(), request, sink, nullptr);
}

TEST(RunInProcessTest, SameFramesAndSummaryAsTheChannel) {
  const v1::RunRequest request = PendulumRequest(0.05);
  CollectingSink channel_sink, direct_sink;
  const absl::StatusOr<RunSummary> channel = OverChannel(request, &channel_sink);
  const absl::StatusOr<RunSummary> direct = Direct(request, &direct_sink);
  ASSERT_TRUE(channel.ok()) << channel.status();
  ASSERT_TRUE(direct.ok()) << direct.status();
  ASSERT_EQ(channel_sink.rows.size(), 51u);  // t = 0, 0.001, ..., 0.05
  EXPECT_EQ(direct_sink.rows, channel_sink.rows);
  RunSummary a = *channel, b = *direct;
  a.wall_seconds = b.wall_seconds = 0;  // the only field that may differ
  EXPECT_EQ(SummaryToJson(a), SummaryToJson(b));
}

// `request` fails with INVALID_ARGUMENT over the channel, and directly with
// the same status.
void ExpectSameInvalidArgument(const v1::RunRequest& request) {
  CollectingSink channel_sink, direct_sink;
  const absl::StatusOr<RunSummary> channel = OverChannel(request, &channel_sink);
  const absl::StatusOr<RunSummary> direct = Direct(request, &direct_sink);
  ASSERT_FALSE(channel.ok());
  EXPECT_EQ(channel.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(direct.status(), channel.status());
}

TEST(RunInProcessTest, SameErrorForAnInvalidScene) {
  v1::RunRequest request = PendulumRequest(0.01);
  request.mutable_scene()->mutable_cables(0)->set_length(-1);
  ExpectSameInvalidArgument(request);
}

TEST(RunInProcessTest, SameErrorForAStringThatIsNotUtf8) {
  v1::RunRequest request = PendulumRequest(0.01);
  request.mutable_scene()->set_name(std::string("bad \xff name"));
  ExpectSameInvalidArgument(request);
}

// RunRequest.strict sets the scene's solver.strict: a run with warnings
// fails, over the channel as directly.
TEST(RunInProcessTest, StrictFailsARunWithWarningsOnBothPaths) {
  v1::RunRequest request = PendulumRequest(0.01);
  request.mutable_scene()->mutable_solver()->set_tolerance(1e-12);  // every step misses it
  CollectingSink channel_sink, direct_sink;
  absl::StatusOr<RunSummary> channel = OverChannel(request, &channel_sink);
  ASSERT_TRUE(channel.ok()) << channel.status();
  EXPECT_EQ(channel->status, "ok");
  EXPECT_EQ(channel->warnings.size(), 2u);  // the beam's static strain (plausibility), the error
  request.set_strict(true);
  channel = OverChannel(request, &channel_sink);
  const absl::StatusOr<RunSummary> direct = Direct(request, &direct_sink);
  ASSERT_TRUE(channel.ok()) << channel.status();
  ASSERT_TRUE(direct.ok()) << direct.status();
  EXPECT_EQ(channel->status, "failed");
  EXPECT_EQ(direct->status, "failed");
  EXPECT_EQ(direct->error, channel->error);
}

TEST(RunInProcessTest, ASinkErrorStopsTheRunAndIsReturned) {
  class FailingSink : public FrameSink {
   public:
    absl::Status OnFrame(const Frame&) override {
      return ++frames == 3 ? absl::DataLossError("disk full") : absl::OkStatus();
    }
    int frames = 0;
  } sink;
  const absl::StatusOr<RunSummary> direct = [&] {
    absl::StatusOr<std::unique_ptr<Connection>> c = ConnectInProcessDirect();
    EXPECT_TRUE(c.ok());
    return RunInProcess(c->get(), PendulumRequest(0.05), &sink, nullptr);
  }();
  EXPECT_EQ(direct.status(), absl::DataLossError("disk full"));
  EXPECT_EQ(sink.frames, 3);
}

// `cablesim run` computes at its caller's priority: the daemon's compute
// threads go kComputeNice levels down so that its calls keep answering, but
// the command line has none, and yielding to every other process on a busy
// machine slowed a foreground run tenfold.
TEST(RunInProcessTest, ComputesAtTheCallersPriority) {
  class NiceSink : public FrameSink {
   public:
    absl::Status OnFrame(const Frame&) override {
      errno = 0;
      nice = ::getpriority(PRIO_PROCESS, static_cast<int>(::syscall(SYS_gettid)));
      return absl::OkStatus();
    }
    int nice = 100;
  } sink;
  errno = 0;
  const int caller = ::getpriority(PRIO_PROCESS, static_cast<int>(::syscall(SYS_gettid)));
  ASSERT_EQ(errno, 0);
  if (caller >= 19) GTEST_SKIP() << "the test runs at nice 19";
  EXPECT_EQ(InProcessLimits().compute_nice, 0);
  absl::StatusOr<std::unique_ptr<Connection>> c = ConnectInProcessDirect();
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_TRUE(RunInProcess(c->get(), PendulumRequest(0.05), &sink, nullptr).ok());
  EXPECT_EQ(sink.nice, caller);
}

}  // namespace
}  // namespace cablesim
