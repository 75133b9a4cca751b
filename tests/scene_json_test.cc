// Scenes given to the service as JSON text (scene_json, base_json) are
// parsed by the server with the CLI's strict parser, so a client in any
// language gets the same checks as `cablesim validate`: an unknown enum name
// that a lenient client library would turn into the default is an error.
// Also GetServerInfo, the other call for clients in other languages.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>

#include "cablesim/v1/service.grpc.pb.h"
#include "cablesim/version.h"
#include "convert/scene_file.h"
#include "server/cablesim_server.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;

constexpr char kScene[] = R"({"cables": [{"name": "c", "length": 1, "elements": 2,
  "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
  "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
  "solver": {"duration": 0.01, "step": 0.005}})";
constexpr char kCurvy[] = R"({"cables": [{"name": "c", "length": 1, "bending": "CURVY",
  "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 0.01}})";

class SceneJsonTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("cablesim_scene_json_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    ServerOptions options;
    options.data_dir = dir_.string();
    options.log = false;
    absl::StatusOr<std::unique_ptr<CablesimServer>> server = CablesimServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CablesimService::NewStub(server_->InProcessChannel());
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  std::filesystem::path dir_;
  std::unique_ptr<CablesimServer> server_;
  std::unique_ptr<v1::CablesimService::Stub> stub_;
};

TEST_F(SceneJsonTest, ValidateParsesTheTextStrictly) {
  {
    grpc::ClientContext context;
    v1::ValidateRequest request;
    request.set_scene_json(kScene);
    v1::ValidateResponse response;
    ASSERT_TRUE(stub_->Validate(&context, request, &response).ok());
    EXPECT_TRUE(response.valid());
    EXPECT_EQ(response.model().elements(), 2);
  }
  grpc::ClientContext context;
  v1::ValidateRequest request;
  request.set_scene_json(kCurvy);
  v1::ValidateResponse response;
  ASSERT_TRUE(stub_->Validate(&context, request, &response).ok());
  EXPECT_FALSE(response.valid());
  ASSERT_EQ(response.errors_size(), 1);
  EXPECT_EQ(response.errors(0).path(), "scene_json");
  EXPECT_THAT(response.errors(0).message(), HasSubstr("CURVY"));
}

TEST_F(SceneJsonTest, RunAndSubmitRefuseWhatTheCliRefuses) {
  {
    grpc::ClientContext context;
    v1::RunRequest request;
    request.set_scene_json(R"({"cables": {"name": "c"}})");
    auto reader = stub_->Run(&context, request);
    v1::RunEvent event;
    while (reader->Read(&event)) {
    }
    const grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("cables: must be a list"));
  }
  grpc::ClientContext context;
  v1::SubmitJobRequest request;
  request.set_scene_json(kCurvy);
  v1::Job job;
  const grpc::Status status = stub_->SubmitJob(&context, request, &job);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("scene_json: "));
}

TEST_F(SceneJsonTest, RunAndSubmitAcceptTheText) {
  {
    grpc::ClientContext context;
    v1::RunRequest request;
    request.set_scene_json(kScene);
    auto reader = stub_->Run(&context, request);
    v1::RunEvent event;
    bool summary = false;
    while (reader->Read(&event)) summary = summary || event.has_summary();
    ASSERT_TRUE(reader->Finish().ok());
    EXPECT_TRUE(summary);
  }
  grpc::ClientContext context;
  v1::SubmitJobRequest request;
  request.set_scene_json(kScene);
  v1::Job job;
  ASSERT_TRUE(stub_->SubmitJob(&context, request, &job).ok());
  EXPECT_FALSE(job.id().empty());
}

TEST_F(SceneJsonTest, BothFormsAtOnceAreRefused) {
  grpc::ClientContext context;
  v1::ValidateRequest request;
  request.set_scene_json(kScene);
  request.mutable_scene()->set_name("x");
  v1::ValidateResponse response;
  ASSERT_TRUE(stub_->Validate(&context, request, &response).ok());
  EXPECT_FALSE(response.valid());
  EXPECT_THAT(response.errors(0).message(), HasSubstr("not both"));
}

TEST_F(SceneJsonTest, SweepBaseAsText) {
  v1::SubmitSweepRequest request;
  v1::SweepAxis* axis = request.add_axes();
  axis->set_path("solver.step");
  axis->add_values(0.005);
  request.set_base_json(kCurvy);
  {
    grpc::ClientContext context;
    v1::Sweep sweep;
    const grpc::Status status = stub_->SubmitSweep(&context, request, &sweep);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("base_json: "));
  }
  request.set_base_json(kScene);
  grpc::ClientContext context;
  v1::Sweep sweep;
  ASSERT_TRUE(stub_->SubmitSweep(&context, request, &sweep).ok());
  EXPECT_EQ(sweep.items(), 1);
}

// GetServerInfo says what --version says and the limits this server
// enforces, the input limits included.
TEST_F(SceneJsonTest, ServerInfoGivesVersionAndLimits) {
  grpc::ClientContext context;
  v1::ServerInfo info;
  ASSERT_TRUE(stub_->GetServerInfo(&context, v1::GetServerInfoRequest(), &info).ok());
  EXPECT_EQ(info.version(), CABLESIM_VERSION);
  EXPECT_EQ(info.build_type(), CABLESIM_BUILD_TYPE);
  EXPECT_EQ(info.max_elements(), ServerLimits().max_elements);
  EXPECT_EQ(info.max_message_bytes(), ServerLimits().max_message_bytes);
  EXPECT_EQ(info.max_scene_bytes(), kMaxSceneBytes);
  EXPECT_EQ(info.max_scene_nesting(), kMaxSceneNesting);
  EXPECT_EQ(info.max_name_bytes(), 256);
  EXPECT_TRUE(info.jobs());
}

}  // namespace
}  // namespace cablesim
