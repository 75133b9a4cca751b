// The gRPC cost of a coupling step against its physics (docs/coupling.md,
// "What a coupling step costs"): the three-line buoy
// (scenes/mooring-three-line-buoy.json) with its buoy replaced by the host
// (the three fairleads coupled supports), driven 1 m in surge and heave
// over 10 s at a coupling step of 0.05 s (one scene step inside each): the
// scene and motion of bench/couple_bench.cc, whose CPU time per iteration
// is the physics alone (CouplingSession::Step in the benchmark's thread).
//
//   Couple/ServerLoopback: one Couple message and its reply through
//                          cablesim-server's service over TCP on 127.0.0.1
//                          (the client blocking on each reply, as a host
//                          does). The counter process_cpu_us is the whole
//                          process's CPU time per step (the server's
//                          threads are in the process too): on a busy
//                          machine the wall time says little; this minus
//                          couple_bench's CPU time is the service's work
//                          (client and server together).
//
// Run both with --benchmark_repetitions=5 and read the medians.

#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bench/sweep_bench_util.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/coupling.h"
#include "server/cablesim_server.h"

namespace cablesim {
namespace {

constexpr double kStep = 0.05;
const double kOmega = 2 * std::numbers::pi / 10;

// The buoy scene with the fairleads (the joints to the buoy) as coupled
// supports, the buoy and its probe gone; long enough for any iteration
// count.
v1::Scene CoupledBuoy() {
  v1::Scene scene =
      *ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/mooring-three-line-buoy.json");
  for (v1::Joint& joint : *scene.mutable_joints()) {
    if (joint.b().body().empty()) continue;
    joint.clear_b();
    joint.set_coupled(true);
  }
  scene.clear_bodies();
  v1::Scene kept = scene;
  kept.clear_probes();
  for (const v1::Probe& p : scene.probes())
    if (p.body().empty()) *kept.add_probes() = p;
  kept.mutable_solver()->set_duration(1e5);
  return kept;
}

double ProcessCpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Sets the process_cpu_us counter from the process's CPU time since `start`.
void CountProcessCpu(benchmark::State& state, double start) {
  state.counters["process_cpu_us"] =
      benchmark::Counter(1e6 * (ProcessCpuSeconds() - start) /
                         static_cast<double>(std::max<int64_t>(1, state.iterations())));
}

// The fairlead's displacement and velocity at time t.
Eigen::Vector3d Offset(double t) { return Eigen::Vector3d(1, 0, 1) * std::sin(kOmega * t); }
Eigen::Vector3d Rate(double t) { return Eigen::Vector3d(1, 0, 1) * kOmega * std::cos(kOmega * t); }

void SetPoint(const Eigen::Vector3d& x, const Eigen::Vector3d& v, v1::CoupledPoint* p) {
  p->mutable_position()->set_x(x.x());
  p->mutable_position()->set_y(x.y());
  p->mutable_position()->set_z(x.z());
  p->mutable_velocity()->set_x(v.x());
  p->mutable_velocity()->set_y(v.y());
  p->mutable_velocity()->set_z(v.z());
}

void BM_CoupleServerLoopback(benchmark::State& state) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  options.limits = NoLimits();
  options.log = false;
  auto server = *CablesimServer::Start(options);
  auto channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", server->port()),
                                     grpc::InsecureChannelCredentials());
  auto stub = v1::CablesimService::NewStub(channel);
  {
    grpc::ClientContext context;
    auto stream = stub->Couple(&context);
    v1::CoupleRequest request;
    v1::CoupleResponse reply;
    *request.mutable_open()->mutable_scene() = CoupledBuoy();
    // The host starts at the scene's points (as the engine places them).
    std::vector<Eigen::Vector3d> p0;
    {
      auto session = CouplingSession::Open(*SceneFromProto(CoupledBuoy()));
      for (int i = 0; i < (*session)->coupled_points(); ++i)
        p0.push_back((*session)->scene_position(i));
    }
    for (const Eigen::Vector3d& p : p0)
      SetPoint(p, Eigen::Vector3d::Zero(), request.mutable_open()->add_points());
    if (!stream->Write(request) || !stream->Read(&reply)) {
      state.SkipWithError(stream->Finish().error_message().c_str());
      return;
    }
    long k = 0;
    request.Clear();
    v1::CoupleStep* step = request.mutable_step();
    step->set_dt_s(kStep);
    for (size_t i = 0; i < p0.size(); ++i) step->add_points();
    const double cpu = ProcessCpuSeconds();
    for (auto _ : state) {
      const double t = kStep * static_cast<double>(++k);
      for (size_t i = 0; i < p0.size(); ++i)
        SetPoint(p0[i] + Offset(t), Rate(t), step->mutable_points(static_cast<int>(i)));
      if (!stream->Write(request) || !stream->Read(&reply) || reply.has_error()) {
        state.SkipWithError(reply.has_error() ? reply.error().message().c_str() : "stream ended");
        break;
      }
      benchmark::DoNotOptimize(reply.forces(0).x());
    }
    CountProcessCpu(state, cpu);
    stream->WritesDone();
    stream->Finish();
  }
  stub.reset();
  channel.reset();
  server->Shutdown(absl::ZeroDuration());
}
BENCHMARK(BM_CoupleServerLoopback)->Unit(benchmark::kMicrosecond)->MinTime(3)->UseRealTime();

}  // namespace
}  // namespace cablesim

BENCHMARK_MAIN();
