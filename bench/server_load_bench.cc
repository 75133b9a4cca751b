// Load on a real cablesim-server over loopback: N concurrent clients, each
// on its own connection, for a fixed time, in a mix of four kinds (by
// client number modulo 4):
//   run:    short Run streams (the falling pendulum for 0.02 s), one after
//           the other, read at once;
//   slow:   Run streams of a 2 s pendulum read one batch of 8 frames every
//           50 ms (flow control holds the run back), cancelled after 1 s;
//   submit: SubmitJob of the short pendulum, one after the other;
//   watch:  SubmitJob, then WatchJob until the job has finished.
// Beside them one probe calls grpc.health.v1.Health/Check every 100 ms.
// Per client count it prints the calls finished OK per second, p50 and p99
// latency per kind, how many calls were refused (RESOURCE_EXHAUSTED or
// UNAVAILABLE) and how fast (p99), the health check's p99 and failures,
// and the daemon's peak memory (VmHWM in /proc/PID/status). A fresh daemon
// (default limits, --workers=2) serves each client count.
//
// Usage: server_load_bench [--clients=32,64,128,256] [--seconds=5]
// (cablesim-server is taken from this binary's directory). Exit 1 when a
// health check fails or a refusal takes more than 1 s.

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "convert/scene_file.h"

namespace cablesim {
namespace {

using Clock = std::chrono::steady_clock;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// A daemon on 127.0.0.1, a free port, its own data directory.
class Daemon {
 public:
  Daemon(const std::string& binary, const std::string& dir) : dir_(dir) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string port_file = dir + "/port";
    std::vector<std::string> args = {binary, "--listen=127.0.0.1:0", "--port-file=" + port_file,
                                     "--data-dir=" + dir + "/data", "--workers=2"};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string log = dir + "/server.log";
    pid_ = fork();
    if (pid_ == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      if (fd >= 0) ::dup2(fd, STDERR_FILENO);
      execv(argv[0], argv.data());
      _exit(127);
    }
    for (int i = 0; i < 1000 && port_ == 0; ++i) {
      std::ifstream in(port_file);
      if (!(in >> port_)) port_ = 0;
      if (port_ == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  ~Daemon() {
    ::kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    std::filesystem::remove_all(dir_);
  }
  int port() const { return port_; }
  // VmHWM [MB]: the resident set's peak so far.
  double PeakMb() const {
    std::ifstream in(absl::StrCat("/proc/", pid_, "/status"));
    std::string line;
    while (std::getline(in, line)) {
      if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024;
    }
    return 0;
  }
  std::shared_ptr<grpc::Channel> Channel() const {
    grpc::ChannelArguments args;
    args.SetInt("grpc.use_local_subchannel_pool", 1);  // a connection per client
    return grpc::CreateCustomChannel(absl::StrCat("127.0.0.1:", port_),
                                     grpc::InsecureChannelCredentials(), args);
  }

 private:
  std::string dir_;
  pid_t pid_ = -1;
  int port_ = 0;
};

struct Sample {
  std::string kind;
  grpc::StatusCode code;
  double ms;
};

class Recorder {
 public:
  void Add(const std::string& kind, grpc::StatusCode code, double ms) {
    std::lock_guard<std::mutex> lock(mu_);
    samples_.push_back({kind, code, ms});
  }
  std::vector<Sample> samples() {
    std::lock_guard<std::mutex> lock(mu_);
    return samples_;
  }

 private:
  std::mutex mu_;
  std::vector<Sample> samples_;
};

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())))];
}

bool Refusal(grpc::StatusCode c) {
  return c == grpc::StatusCode::RESOURCE_EXHAUSTED || c == grpc::StatusCode::UNAVAILABLE;
}

v1::Scene Pendulum(double duration_s, double step_s, double output_interval_s) {
  v1::Scene scene =
      *ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/falling-pendulum.json");
  scene.mutable_solver()->set_duration(duration_s);
  scene.mutable_solver()->set_step(step_s);
  scene.mutable_solver()->set_output_interval(output_interval_s);
  return scene;
}

// One client's loop until `end`.
void Client(int index, const Daemon& daemon, Clock::time_point end, Recorder* rec) {
  auto stub = v1::CablesimService::NewStub(daemon.Channel());
  const v1::Scene shortrun = Pendulum(0.02, 1e-3, 1e-2);
  const v1::Scene longrun = Pendulum(2, 1e-4, 1e-3);
  const int kind = index % 4;
  while (Clock::now() < end) {
    const auto t0 = Clock::now();
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    grpc::Status status;
    std::string name;
    if (kind == 0 || kind == 1) {
      name = kind == 0 ? "run" : "slow";
      v1::RunRequest request;
      *request.mutable_scene() = kind == 0 ? shortrun : longrun;
      if (kind == 1) request.set_frames_per_batch(8);
      auto reader = stub->Run(&context, request);
      v1::RunEvent event;
      bool cancelled = false;
      while (reader->Read(&event)) {
        if (kind == 1) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
          if (!cancelled && Clock::now() - t0 > std::chrono::seconds(1)) {
            context.TryCancel();
            cancelled = true;
          }
        }
      }
      status = reader->Finish();
      // A slow stream that the client itself ended counts as served.
      if (cancelled && status.error_code() == grpc::StatusCode::CANCELLED) status = grpc::Status::OK;
    } else {
      name = kind == 2 ? "submit" : "watch";
      v1::SubmitJobRequest request;
      *request.mutable_scene() = shortrun;
      v1::Job job;
      status = stub->SubmitJob(&context, request, &job);
      if (kind == 3 && status.ok()) {
        grpc::ClientContext watch_context;
        watch_context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
        v1::WatchJobRequest watch;
        watch.set_id(job.id());
        auto reader = stub->WatchJob(&watch_context, watch);
        v1::Job seen;
        while (reader->Read(&seen)) {
        }
        status = reader->Finish();
      }
    }
    rec->Add(name, status.error_code(), Ms(Clock::now() - t0));
    // A refused client waits a little before trying again, as a polite one does.
    if (Refusal(status.error_code())) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// grpc.health.v1.Health/Check every 100 ms until `end`.
void HealthProbe(const Daemon& daemon, Clock::time_point end, Recorder* rec) {
  auto channel = daemon.Channel();
  grpc::GenericStub stub(channel);
  while (Clock::now() < end) {
    const auto t0 = Clock::now();
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(1));
    grpc::CompletionQueue cq;
    grpc::Slice empty;
    grpc::ByteBuffer request(&empty, 1), response;
    auto call = stub.PrepareUnaryCall(&context, "/grpc.health.v1.Health/Check", request, &cq);
    call->StartCall();
    grpc::Status status;
    call->Finish(&response, &status, reinterpret_cast<void*>(1));
    void* tag;
    bool ok;
    cq.Next(&tag, &ok);
    cq.Shutdown();
    while (cq.Next(&tag, &ok)) {
    }
    rec->Add("health", status.error_code(), Ms(Clock::now() - t0));
    std::this_thread::sleep_until(t0 + std::chrono::milliseconds(100));
  }
}

int Main(int argc, char** argv) {
  std::vector<int> counts = {32, 64, 128, 256};
  double seconds = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--clients=", 0) == 0) {
      counts.clear();
      for (absl::string_view c : absl::StrSplit(arg.substr(10), ',')) {
        int n = 0;
        if (!absl::SimpleAtoi(c, &n) || n < 1) return 2;
        counts.push_back(n);
      }
    } else if (arg.rfind("--seconds=", 0) == 0) {
      seconds = std::atof(arg.c_str() + 10);
    } else {
      std::fprintf(stderr, "usage: server_load_bench [--clients=32,64,...] [--seconds=S]\n");
      return 2;
    }
  }
  const std::string binary =
      (std::filesystem::path(argv[0]).parent_path() / "cablesim-server").string();
  bool healthy = true;
  std::printf("%7s %8s | %-27s | %-27s | %-27s | %-27s | %16s | %14s | %7s\n", "clients", "ok/s",
              "run n p50 p99 ms", "slow n p50 p99 ms", "submit n p50 p99 ms", "watch n p50 p99 ms",
              "refused n p99 ms", "health p99 fail", "peak MB");
  for (int n : counts) {
    Daemon daemon(binary, absl::StrCat(std::filesystem::temp_directory_path().string(),
                                       "/cablesim_load_", ::getpid(), "_", n));
    if (daemon.port() == 0) {
      std::fprintf(stderr, "%s did not start\n", binary.c_str());
      return 1;
    }
    Recorder rec;
    const auto end =
        Clock::now() + std::chrono::milliseconds(static_cast<int64_t>(seconds * 1000));
    std::vector<std::thread> threads;
    threads.emplace_back(HealthProbe, std::cref(daemon), end, &rec);
    for (int c = 0; c < n; ++c) threads.emplace_back(Client, c, std::cref(daemon), end, &rec);
    const auto start = Clock::now();
    for (std::thread& t : threads) t.join();
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    std::map<std::string, std::vector<double>> ok;
    std::vector<double> refused;
    int64_t served = 0, health_fail = 0, other = 0;
    for (const Sample& s : rec.samples()) {
      if (s.kind == "health") {
        if (s.code != grpc::StatusCode::OK) ++health_fail;
        ok["health"].push_back(s.ms);
      } else if (s.code == grpc::StatusCode::OK) {
        ok[s.kind].push_back(s.ms);
        ++served;
      } else if (Refusal(s.code)) {
        refused.push_back(s.ms);
      } else {
        ++other;
      }
    }
    auto cell = [&](const std::string& kind) {
      const std::vector<double>& v = ok[kind];
      return absl::StrCat(v.size(), " ", static_cast<int>(Percentile(v, 0.5) + 0.5), " ",
                          static_cast<int>(Percentile(v, 0.99) + 0.5));
    };
    std::printf("%7d %8.0f | %-27s | %-27s | %-27s | %-27s | %7zu %8.1f | %7.1f %6lld | %7.0f\n", n,
                static_cast<double>(served) / wall, cell("run").c_str(), cell("slow").c_str(),
                cell("submit").c_str(), cell("watch").c_str(), refused.size(),
                Percentile(refused, 0.99), Percentile(ok["health"], 0.99),
                static_cast<long long>(health_fail), daemon.PeakMb());
    if (other > 0) std::printf("        (%lld calls failed otherwise)\n", static_cast<long long>(other));
    std::fflush(stdout);
    if (health_fail > 0 || Percentile(refused, 0.99) > 1000) healthy = false;
  }
  return healthy ? 0 : 1;
}

}  // namespace
}  // namespace cablesim

int main(int argc, char** argv) { return cablesim::Main(argc, argv); }
