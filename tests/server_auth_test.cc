// Who may call a real cablesim-server: bearer tokens from --token-file
// (missing or wrong: UNAUTHENTICATED), gRPC's TLS with a CA made here
// with openssl (and mutual TLS with --tls-client-ca), and no listening
// beyond loopback without TLS and tokens unless --insecure is given.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "absl/strings/str_format.h"
#include "client/cli.h"
#include "server/listen_address.h"
#include "server_test_util.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

constexpr char kToken[] = "tok-0123456789abcdef";

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

grpc::Status Info(v1::CablesimService::Stub* stub, const std::string& token = "") {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  v1::ServerInfo info;
  return stub->GetServerInfo(&context, v1::GetServerInfoRequest(), &info);
}

TEST(ServerAuthTest, ACallWithoutAKnownTokenIsUnauthenticated) {
  const std::string dir = testing::FreshDir("auth_tokens");
  const std::string tokens = dir + "/tokens";
  testing::WritePrivateFile(tokens, absl::StrCat("# token tenant\n", kToken, " alice\n"));
  ServerProcess server(dir, {"--token-file=" + tokens});
  auto stub = server.Stub();
  grpc::Status s = Info(stub.get());
  EXPECT_EQ(s.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(s.error_message(), HasSubstr("bearer token"));
  EXPECT_EQ(Info(stub.get(), "tok-not-a-token-at-all").error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  {
    // Every call, not only some: a job submitted without a token is refused.
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    *request.mutable_scene() = testing::Pendulum(0.01, 1e-3, 1e-3);
    v1::Job job;
    EXPECT_EQ(stub->SubmitJob(&context, request, &job).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  EXPECT_TRUE(Info(stub.get(), kToken).ok());
}

TEST(ServerAuthTest, ATenantSeesOnlyItsOwnJobsAndSweeps) {
  const std::string dir = testing::FreshDir("auth_tenants");
  const std::string tokens = dir + "/tokens";
  const std::string alice = kToken, bob = "tok-bob-0123456789ab";
  testing::WritePrivateFile(tokens, absl::StrCat(alice, " alice\n", bob, " bob\n"));
  ServerProcess server(dir, {"--token-file=" + tokens, "--workers=1"});
  auto stub = server.Stub();
  auto as = [](grpc::ClientContext* context, const std::string& token) {
    context->AddMetadata("authorization", "Bearer " + token);
  };
  v1::Job job;
  {
    grpc::ClientContext context;
    as(&context, alice);
    v1::SubmitJobRequest request;
    *request.mutable_scene() = testing::Pendulum(0.02, 1e-3, 1e-2);
    ASSERT_TRUE(stub->SubmitJob(&context, request, &job).ok());
  }
  v1::Sweep sweep;
  {
    grpc::ClientContext context;
    as(&context, alice);
    v1::SubmitSweepRequest request;
    *request.mutable_base() = testing::Pendulum(0.02, 1e-3, 1e-2);
    request.add_axes()->set_path("gravity.y");
    request.mutable_axes(0)->add_values(-9.81);
    ASSERT_TRUE(stub->SubmitSweep(&context, request, &sweep).ok());
  }
  // Bob: as if neither existed.
  {
    grpc::ClientContext context;
    as(&context, bob);
    v1::GetJobRequest request;
    request.set_id(job.id());
    v1::Job seen;
    const grpc::Status s = stub->GetJob(&context, request, &seen);
    EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    as(&context, bob);
    v1::CancelJobRequest request;
    request.set_id(job.id());
    v1::Job seen;
    EXPECT_EQ(stub->CancelJob(&context, request, &seen).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    as(&context, bob);
    v1::GetJobResultRequest request;
    request.set_id(job.id());
    auto reader = stub->GetJobResult(&context, request);
    v1::RunEvent event;
    while (reader->Read(&event)) {
    }
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    as(&context, bob);
    v1::GetSweepResultsRequest request;
    request.set_id(sweep.id());
    v1::SweepResults results;
    EXPECT_EQ(stub->GetSweepResults(&context, request, &results).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    as(&context, bob);
    v1::DeleteSweepRequest request;
    request.set_id(sweep.id());
    v1::DeleteResponse response;
    EXPECT_EQ(stub->DeleteSweep(&context, request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
  auto list = [&](const std::string& token) {
    grpc::ClientContext context;
    as(&context, token);
    v1::ListJobsResponse response;
    EXPECT_TRUE(stub->ListJobs(&context, v1::ListJobsRequest(), &response).ok());
    return response.jobs_size();
  };
  EXPECT_EQ(list(bob), 0);
  EXPECT_EQ(list(alice), 2);
  // Alice sees hers.
  grpc::ClientContext context;
  as(&context, alice);
  v1::GetJobRequest request;
  request.set_id(job.id());
  v1::Job seen;
  EXPECT_TRUE(stub->GetJob(&context, request, &seen).ok());
}

TEST(ServerAuthTest, IdsCannotBeGuessed) {
  const std::string dir = testing::FreshDir("auth_ids");
  ServerProcess server(dir, {"--workers=1"});
  auto stub = server.Stub();
  std::vector<std::string> ids;
  for (int i = 0; i < 2; ++i) {
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    *request.mutable_scene() = testing::Pendulum(0.01, 1e-3, 1e-3);
    v1::Job job;
    ASSERT_TRUE(stub->SubmitJob(&context, request, &job).ok());
    EXPECT_THAT(job.id(), ::testing::MatchesRegex("j-[A-Za-z0-9_-]{22}"));
    ids.push_back(job.id());
  }
  EXPECT_NE(ids[0], ids[1]);
  // The sequential ids of before name nothing.
  grpc::ClientContext context;
  v1::GetJobRequest request;
  request.set_id("j-000001");
  v1::Job job;
  EXPECT_EQ(stub->GetJob(&context, request, &job).error_code(), grpc::StatusCode::NOT_FOUND);
}

// Runs `command` with /bin/sh; true on exit 0.
bool Shell(const std::string& command) { return std::system(command.c_str()) == 0; }

// A CA, a certificate for localhost / 127.0.0.1 and a client certificate,
// all made now with openssl in `dir`.
void MakeCertificates(const std::string& dir) {
  const std::string cd = "cd '" + dir + "' && ";
  ASSERT_TRUE(Shell(cd +
                    "openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem "
                    "-days 1 -subj /CN=cablesim-test-ca 2>/dev/null"));
  std::ofstream(dir + "/server.ext") << "subjectAltName=DNS:localhost,IP:127.0.0.1\n";
  for (const char* who : {"server", "client"}) {
    const std::string w = who;
    ASSERT_TRUE(Shell(cd + "openssl req -newkey rsa:2048 -nodes -keyout " + w + ".key -out " + w +
                      ".csr -subj /CN=" + (w == "server" ? "localhost" : "cablesim-client") +
                      " 2>/dev/null"));
    ASSERT_TRUE(Shell(cd + "openssl x509 -req -in " + w + ".csr -CA ca.pem -CAkey ca.key " +
                      "-CAcreateserial -out " + w + ".pem -days 1" +
                      (w == "server" ? " -extfile server.ext" : "") + " 2>/dev/null"));
  }
}

std::unique_ptr<v1::CablesimService::Stub> TlsStub(const ServerProcess& server,
                                                   const std::string& dir, bool client_cert) {
  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = ReadText(dir + "/ca.pem");
  if (client_cert) {
    ssl.pem_private_key = ReadText(dir + "/client.key");
    ssl.pem_cert_chain = ReadText(dir + "/client.pem");
  }
  grpc::ChannelArguments args;
  args.SetInt("grpc.use_local_subchannel_pool", 1);
  args.SetSslTargetNameOverride("localhost");
  return v1::CablesimService::NewStub(
      grpc::CreateCustomChannel(server.address(), grpc::SslCredentials(ssl), args));
}

TEST(ServerAuthTest, TlsWithACertificateMadeAtTestTime) {
  const std::string dir = testing::FreshDir("auth_tls");
  MakeCertificates(dir);
  ServerProcess server(dir,
                       {"--tls-cert=" + dir + "/server.pem", "--tls-key=" + dir + "/server.key"});
  EXPECT_TRUE(Info(TlsStub(server, dir, false).get()).ok());
  // Plain text is not served.
  EXPECT_FALSE(Info(server.Stub().get()).ok());
}

TEST(ServerAuthTest, MutualTlsNeedsAClientCertificate) {
  const std::string dir = testing::FreshDir("auth_mtls");
  MakeCertificates(dir);
  ServerProcess server(dir, {"--tls-cert=" + dir + "/server.pem",
                             "--tls-key=" + dir + "/server.key",
                             "--tls-client-ca=" + dir + "/ca.pem"});
  EXPECT_FALSE(Info(TlsStub(server, dir, false).get()).ok());
  EXPECT_TRUE(Info(TlsStub(server, dir, true).get()).ok());
}

// `cablesim ARGS...` in this process: its exit code, stderr in `err`.
int Cli(const std::vector<std::string>& args, std::string* err) {
  std::ostringstream out, error;
  const int code = RunCli(args, out, error);
  *err = error.str();
  return code;
}

TEST(ServerAuthTest, TheCommandLineTakesTlsCaAndTokenFile) {
  const std::string dir = testing::FreshDir("auth_cli");
  MakeCertificates(dir);
  const std::string tokens = dir + "/tokens", mine = dir + "/my-token";
  testing::WritePrivateFile(tokens, absl::StrCat(kToken, " alice\n"));
  std::ofstream(mine) << "# issued to alice\n" << kToken << "\n";
  ServerProcess server(dir, {"--tls-cert=" + dir + "/server.pem",
                             "--tls-key=" + dir + "/server.key", "--token-file=" + tokens});
  // The certificate names localhost.
  const std::string address = absl::StrCat("localhost:", server.port());
  std::string err;
  EXPECT_EQ(Cli({"jobs", "--server", address, "--tls-ca", dir + "/ca.pem", "--token-file", mine},
                &err),
            0)
      << err;
  EXPECT_EQ(Cli({"jobs", "--server", address, "--tls-ca", dir + "/ca.pem"}, &err), 1);
  EXPECT_THAT(err, HasSubstr("UNAUTHENTICATED"));
  EXPECT_EQ(Cli({"jobs", "--server", address, "--token-file", mine}, &err), 1);  // no TLS
  EXPECT_EQ(Cli({"jobs", "--token-file", mine}, &err), 2);  // only with --server
}

TEST(ServerAuthTest, BeyondLoopbackOnlyWithTlsAndTokensOrInsecure) {
  const std::string dir = testing::FreshDir("auth_listen");
  const std::string log = dir + "/refused.log";
  const int status = std::system(
      absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR, "/cablesim-server' --listen=0.0.0.0:0 ",
                   "--data-dir='", dir, "' 2>'", log, "'")
          .c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_THAT(ReadText(log), HasSubstr("--insecure"));
}

// The review's reproducer: --listen 127.evil.example:PORT passed a check on
// the spelling ("starts with 127.") and bound whatever the name resolved
// to, in plain text. Now the name is resolved first and the address it
// resolves to decides.
TEST(ServerAuthTest, ALoopbackLookingNameIsJudgedByTheAddressItResolvesTo) {
  auto resolver = [](const std::string& host) -> absl::StatusOr<std::vector<std::string>> {
    if (host == "127.evil.example") return std::vector<std::string>{"203.0.113.7"};
    if (host == "localhost") return std::vector<std::string>{"127.0.0.1", "::1"};
    if (host == "sixlocal") return std::vector<std::string>{"::1"};
    if (host == "mapped") return std::vector<std::string>{"::ffff:127.0.0.2"};
    if (host == "nothing") return std::vector<std::string>{};
    return std::vector<std::string>{host};  // numeric
  };
  absl::StatusOr<ListenAddress> evil = ResolveListenAddress("127.evil.example:5000", resolver);
  ASSERT_TRUE(evil.ok()) << evil.status();
  EXPECT_FALSE(evil->loopback);
  EXPECT_EQ(evil->bind, "203.0.113.7:5000");  // bound to what was checked, not re-resolved
  absl::StatusOr<ListenAddress> local = ResolveListenAddress("localhost:0", resolver);
  ASSERT_TRUE(local.ok());
  EXPECT_TRUE(local->loopback);
  EXPECT_EQ(local->bind, "127.0.0.1:0");
  EXPECT_TRUE(ResolveListenAddress("sixlocal:7", resolver)->loopback);
  EXPECT_EQ(ResolveListenAddress("sixlocal:7", resolver)->bind, "[::1]:7");
  EXPECT_TRUE(ResolveListenAddress("mapped:7", resolver)->loopback);
  EXPECT_TRUE(ResolveListenAddress("[::1]:7", resolver)->loopback);
  EXPECT_TRUE(ResolveListenAddress("127.0.0.9:7", resolver)->loopback);
  EXPECT_FALSE(ResolveListenAddress("0.0.0.0:7", resolver)->loopback);
  EXPECT_FALSE(ResolveListenAddress("[::]:7", resolver)->loopback);
  EXPECT_FALSE(ResolveListenAddress("128.0.0.1:7", resolver)->loopback);
  EXPECT_TRUE(ResolveListenAddress("unix:/tmp/sock", resolver)->loopback);
  EXPECT_THAT(ResolveListenAddress("nothing:7", resolver).status().message(),
              HasSubstr("resolves to no address"));
  EXPECT_FALSE(ResolveListenAddress("127.0.0.1:http", resolver).ok());
  EXPECT_FALSE(ResolveListenAddress("127.0.0.1", resolver).ok());
  // The real resolver: localhost is loopback after resolution.
  absl::StatusOr<ListenAddress> real = ResolveListenAddress("localhost:0");
  ASSERT_TRUE(real.ok()) << real.status();
  EXPECT_TRUE(real->loopback);
}

// The binary refuses 127.evil.example: it either does not resolve (this
// machine has no DNS) or resolves to something that is not loopback;
// usage error (2) either way, before anything is bound.
TEST(ServerAuthTest, TheServerRefusesALoopbackLookingName) {
  const std::string dir = testing::FreshDir("auth_evil");
  const std::string log = dir + "/refused.log";
  const int status = std::system(
      absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR,
                   "/cablesim-server' --listen=127.evil.example:0 --data-dir='", dir, "' 2>'",
                   log, "'")
          .c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2) << ReadText(log);
  EXPECT_THAT(ReadText(log), HasSubstr("--listen 127.evil.example:0"));
}

// A token file that others can read or change is refused, naming the
// file and its mode (the review found a world-readable one accepted
// silently); one its group can read starts with a warning saying why
// (Kubernetes mounts secrets 0440 for the pod's group); a private one
// starts quietly.
TEST(ServerAuthTest, ATokenFileOthersCanReadIsRefused) {
  const std::string dir = testing::FreshDir("auth_token_mode");
  const std::string tokens = dir + "/tokens", log = dir + "/refused.log";
  testing::WritePrivateFile(tokens, absl::StrCat(kToken, " alice\n"));
  for (const int mode : {0644, 0604, 0606}) {
    ASSERT_EQ(::chmod(tokens.c_str(), mode), 0);
    const int status = std::system(
        absl::StrCat("timeout 60 '", CABLESIM_BIN_DIR,
                     "/cablesim-server' --listen=127.0.0.1:0 --data-dir='", dir,
                     "' --token-file='", tokens, "' 2>'", log, "'")
            .c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 1) << mode;
    EXPECT_THAT(ReadText(log), HasSubstr(tokens + ": mode 0" + absl::StrFormat("%o", mode)));
    EXPECT_THAT(ReadText(log), HasSubstr("chmod 600"));
  }
  ASSERT_EQ(::chmod(tokens.c_str(), 0640), 0);
  {
    ServerProcess server(dir, {"--token-file=" + tokens});
    auto stub = server.Stub();
    EXPECT_TRUE(Info(stub.get(), kToken).ok());
    EXPECT_TRUE(server.WaitForLog("WARNING: " + tokens + ": mode 0640 lets its group read"));
  }
  ASSERT_EQ(::chmod(tokens.c_str(), 0600), 0);
  ServerProcess server(dir, {"--token-file=" + tokens});
  auto stub = server.Stub();
  EXPECT_TRUE(Info(stub.get(), kToken).ok());
}

}  // namespace
}  // namespace cablesim
