#ifndef CABLESIM_TESTS_SERVER_TEST_UTIL_H_
#define CABLESIM_TESTS_SERVER_TEST_UTIL_H_

// Helpers for tests against a real cablesim-server on a loopback port: the
// server as a child process (so it can be killed with SIGKILL), a stub, raw
// calls for the health and reflection services, and scenes.

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "cablesim/v1/service.grpc.pb.h"
#include "convert/scene_file.h"
#include "tests/scratch_dir.h"

namespace cablesim::testing {

// A fresh empty directory under the test's temporary directory, removed
// when the test program exits having passed.
inline std::string FreshDir(const std::string& name) { return ScratchDir("cablesim_" + name); }

// Writes `text` to `path`, readable by its owner only (the server refuses
// a token file that others can read).
inline void WritePrivateFile(const std::string& path, const std::string& text) {
  std::filesystem::remove(path);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  ASSERT_GE(fd, 0) << path;
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fd);
}

// cablesim-server as a child process listening on 127.0.0.1 on a free port
// (it binds port 0 and writes the port it got to a file). `env` adds
// NAME=VALUE entries to the child's environment. The server's stderr goes
// to DIR/server.log (see WaitForLog), printed when the test has failed.
class ServerProcess {
 public:
  // `address_space_bytes` > 0: the child's RLIMIT_AS (so that a large
  // allocation fails inside the server).
  ServerProcess(std::string data_dir, std::vector<std::string> flags = {},
                std::vector<std::string> env = {}, uint64_t address_space_bytes = 0)
      : data_dir_(std::move(data_dir)),
        flags_(std::move(flags)),
        env_(std::move(env)),
        address_space_bytes_(address_space_bytes) {
    Start();
  }
  ~ServerProcess() {
    if (pid_ > 0) Kill(SIGKILL);
    if (::testing::Test::HasFailure()) {
      std::ifstream in(log_path());
      std::cerr << "---- " << log_path() << "\n" << in.rdbuf() << "----\n";
    }
  }

  void Start() {
    const std::string port_file = absl::StrCat(data_dir_, "/port");
    std::filesystem::remove(port_file);
    std::vector<std::string> args = {absl::StrCat(CABLESIM_BIN_DIR, "/cablesim-server"),
                                     "--listen=127.0.0.1:0", "--port-file=" + port_file};
    // With --store among the flags, DIR holds only the port file and the
    // log.
    bool store = false;
    for (const std::string& f : flags_) store |= f.rfind("--store", 0) == 0;
    if (!store) args.push_back("--data-dir=" + data_dir_);
    args.insert(args.end(), flags_.begin(), flags_.end());
    // Everything the child needs is prepared before fork (after it, only
    // async-signal-safe calls).
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> env_strings = env_;
    for (char** e = environ; *e != nullptr; ++e) env_strings.push_back(*e);
    std::vector<char*> envp;
    for (std::string& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);
    const std::string log = log_path();
    const pid_t parent = ::getpid();
    pid_ = fork();
    if (pid_ == 0) {
      // The server dies with the test process: a test killed by CTest's
      // timeout (or a crash) leaves no server behind, parked at a gate or
      // holding a port, for later tests to trip over.
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (::getppid() != parent) _exit(127);  // the test died before prctl
      const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
      if (fd >= 0) ::dup2(fd, STDERR_FILENO);
      if (address_space_bytes_ > 0) {
        const struct rlimit limit = {address_space_bytes_, address_space_bytes_};
        ::setrlimit(RLIMIT_AS, &limit);
      }
      execve(argv[0], argv.data(), envp.data());
      _exit(127);
    }
    ASSERT_GT(pid_, 0);
    // Until the port file appears or the server exits (no time limit that
    // could decide the verdict: a hung start is ctest's timeout).
    while (port_ == 0) {
      std::ifstream in(port_file);
      if (in >> port_) break;
      port_ = 0;
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        FAIL() << "cablesim-server exited during start-up (status " << status << ")";
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  // Waits until the server's stderr contains `text`; false if the server
  // exits first (or after a hang guard of 120 s, which no event the tests
  // wait for comes near).
  bool WaitForLog(const std::string& text) const {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < give_up) {
      std::ifstream in(log_path());
      const std::string log((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (log.find(text) != std::string::npos) return true;
      if (pid_ <= 0 || ::kill(pid_, 0) != 0) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  // Sends `signal` and waits for the process; returns its wait status.
  int Kill(int signal) {
    ::kill(pid_, signal);
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    port_ = 0;
    return status;
  }

  // Restarts on the same data directory (a new port).
  void Restart() { Start(); }

  pid_t pid() const { return pid_; }
  std::string log_path() const { return absl::StrCat(data_dir_, "/server.log"); }
  int port() const { return port_; }
  std::string address() const { return absl::StrCat("127.0.0.1:", port_); }
  std::shared_ptr<grpc::Channel> Channel() const { return Channel(grpc::ChannelArguments()); }
  std::shared_ptr<grpc::Channel> Channel(grpc::ChannelArguments args) const {
    args.SetMaxReceiveMessageSize(64 << 20);
    // A fresh connection per channel (no sharing between test clients).
    args.SetInt("grpc.use_local_subchannel_pool", 1);
    return grpc::CreateCustomChannel(address(), grpc::InsecureChannelCredentials(), args);
  }
  std::unique_ptr<v1::CablesimService::Stub> Stub() const {
    return v1::CablesimService::NewStub(Channel());
  }

 private:
  std::string data_dir_;
  std::vector<std::string> flags_;
  std::vector<std::string> env_;
  uint64_t address_space_bytes_ = 0;
  pid_t pid_ = -1;
  int port_ = 0;
};

// Starts a cablesim-server on `data_dir` expected to refuse to start;
// returns its exit code (124: still running after 60 s, so it did not
// refuse) and its stderr in `log`.
inline int StartRefused(const std::string& data_dir, std::string* log) {
  const std::string log_path = absl::StrCat(data_dir, "/refused.log");
  const int status = std::system(absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR,
                                              "/cablesim-server' --listen=127.0.0.1:0 --data-dir='",
                                              data_dir, "' 2>'", log_path, "'")
                                     .c_str());
  std::ifstream in(log_path);
  log->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// One request message and the first response message of `method`, as raw
// bytes (for services whose .proto is not installed: health, reflection).
inline grpc::Status RawCall(const std::shared_ptr<grpc::Channel>& channel,
                            const std::string& method, const std::string& request,
                            std::string* response) {
  grpc::GenericStub stub(channel);
  grpc::CompletionQueue cq;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  auto call = stub.PrepareCall(&context, method, &cq);
  void* tag;
  bool ok;
  auto step = [&](int t) {
    EXPECT_TRUE(cq.Next(&tag, &ok));
    EXPECT_EQ(tag, reinterpret_cast<void*>(t));
    return ok;
  };
  call->StartCall(reinterpret_cast<void*>(1));
  step(1);
  grpc::Slice slice(request);
  grpc::ByteBuffer out(&slice, 1);
  call->Write(out, reinterpret_cast<void*>(2));
  step(2);
  call->WritesDone(reinterpret_cast<void*>(3));
  step(3);
  grpc::ByteBuffer in;
  call->Read(&in, reinterpret_cast<void*>(4));
  if (step(4)) {
    std::vector<grpc::Slice> slices;
    (void)in.Dump(&slices);
    response->clear();
    for (const grpc::Slice& s : slices) {
      response->append(reinterpret_cast<const char*>(s.begin()), s.size());
    }
  }
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(5));
  step(5);
  cq.Shutdown();
  while (cq.Next(&tag, &ok)) {
  }
  return status;
}

// The falling pendulum of scenes/ with another duration, step and output
// interval.
inline v1::Scene Pendulum(double duration_s, double step_s, double output_interval_s) {
  auto scene = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/falling-pendulum.json"));
  EXPECT_TRUE(scene.ok()) << scene.status();
  scene->mutable_solver()->set_duration(duration_s);
  scene->mutable_solver()->set_step(step_s);
  scene->mutable_solver()->set_output_interval(output_interval_s);
  return *scene;
}

// The test-only job gate of cablesim-server (JobManager::
// set_test_only_gate_dir): jobs whose scene name starts with "gated" stop
// after their first frame until Open(their id).
class JobGate {
 public:
  explicit JobGate(const std::string& data_dir) : dir_(absl::StrCat(data_dir, "/gate")) {
    std::filesystem::create_directories(dir_);
  }
  // The environment entry that turns the gate on (ServerProcess's `env`).
  std::string env() const { return absl::StrCat("CABLESIM_TEST_ONLY_JOB_GATE=", dir_); }
  void Open(const std::string& job_id) const { std::ofstream(absl::StrCat(dir_, "/", job_id)); }

 private:
  std::string dir_;
};

// SubmitJob of `scene`, expected to succeed; the job queued.
inline v1::Job Submit(v1::CablesimService::Stub* stub, const v1::Scene& scene) {
  grpc::ClientContext context;
  v1::SubmitJobRequest request;
  *request.mutable_scene() = scene;
  v1::Job job;
  const grpc::Status s = stub->SubmitJob(&context, request, &job);
  EXPECT_TRUE(s.ok()) << s.error_message();
  return job;
}

// DeleteJob of job `id`, or with `sweep` DeleteSweep of sweep `id`;
// `freed`, when given, receives the bytes freed.
inline grpc::Status Delete(v1::CablesimService::Stub* stub, const std::string& id, bool sweep,
                           int64_t* freed) {
  grpc::ClientContext context;
  v1::DeleteResponse response;
  grpc::Status s;
  if (sweep) {
    v1::DeleteSweepRequest request;
    request.set_id(id);
    s = stub->DeleteSweep(&context, request, &response);
  } else {
    v1::DeleteJobRequest request;
    request.set_id(id);
    s = stub->DeleteJob(&context, request, &response);
  }
  if (freed) *freed = response.freed_bytes();
  return s;
}
inline grpc::Status DeleteJob(v1::CablesimService::Stub* stub, const std::string& id,
                              int64_t* freed = nullptr) {
  return Delete(stub, id, false, freed);
}
inline grpc::Status DeleteSweep(v1::CablesimService::Stub* stub, const std::string& id,
                                int64_t* freed = nullptr) {
  return Delete(stub, id, true, freed);
}

// Waits (WatchJob) until job `id` is in `state` or finished; returns the
// job as last seen.
inline v1::Job WaitForState(v1::CablesimService::Stub* stub, const std::string& id,
                            v1::JobState state) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  v1::WatchJobRequest request;
  request.set_id(id);
  auto reader = stub->WatchJob(&context, request);
  v1::Job job;
  while (reader->Read(&job) && job.state() != state) {
  }
  context.TryCancel();
  (void)reader->Finish();
  return job;
}

// GetJobResult of job `id` read to the end: its status and frame rows.
struct JobResultRead {
  grpc::Status status;
  int64_t rows = 0;
};
inline JobResultRead ReadJobResult(v1::CablesimService::Stub* stub, const std::string& id) {
  grpc::ClientContext context;
  v1::GetJobResultRequest request;
  request.set_id(id);
  auto reader = stub->GetJobResult(&context, request);
  v1::RunEvent event;
  JobResultRead read;
  while (reader->Read(&event)) read.rows += event.has_frames() ? event.frames().rows() : 0;
  read.status = reader->Finish();
  return read;
}

inline v1::JobState WaitForJob(v1::CablesimService::Stub* stub, const std::string& id,
                               v1::Job* last = nullptr) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(120));
  v1::WatchJobRequest request;
  request.set_id(id);
  auto reader = stub->WatchJob(&context, request);
  v1::Job job, latest;
  while (reader->Read(&job)) latest = job;
  EXPECT_TRUE(reader->Finish().ok());
  if (last) *last = latest;
  return latest.state();
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_SERVER_TEST_UTIL_H_
