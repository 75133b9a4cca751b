// The Couple stream (server/couple_service.cc) in the process: a session
// opens, steps and reports forces; each bad step message gets an error
// reply naming the field and leaves the session as it was; the stream's
// own errors (no open first, a step the lines cannot take, the per-client
// limit) end it with a status. The coupled floater's accuracy is tested
// from Python (client/python/test_couple.py) and C (couple_floater_test).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "cablesim/v1/service.grpc.pb.h"
#include "server/cablesim_server.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// A 1 m string in 4 elements along x, pinned at s = 0, its end (1, 0, 0)
// a coupled support; it starts as given (no statics), so the host starts
// at the scene's point.
constexpr char kString[] = R"({"gravity": {"z": -9.81},
  "cables": [{"name": "c", "length": 1, "elements": 4, "direction": {"x": 1},
    "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
  "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
             {"type": "PIN", "a": {"cable": "c", "s": 1}, "coupled": true}],
  "solver": {"duration": 1, "step": 0.005}})";

using Stream = grpc::ClientReaderWriter<v1::CoupleRequest, v1::CoupleResponse>;

// A message the session must refuse, and what the error must say.
struct Bad {
  v1::CoupleRequest request;
  std::string path, says;
};

class CoupleServiceTest : public ::testing::Test {
 protected:
  void Start(int max_streams_per_peer = std::numeric_limits<int>::max()) {
    ServerOptions options;
    options.log = false;
    options.limits.max_streams_per_peer = max_streams_per_peer;
    absl::StatusOr<std::unique_ptr<CablesimServer>> server = CablesimServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stub_ = v1::CablesimService::NewStub(server_->InProcessChannel());
  }
  void SetUp() override { Start(); }

  static v1::CoupleRequest Open(const std::string& scene_json) {
    v1::CoupleRequest request;
    request.mutable_open()->set_scene_json(scene_json);
    request.mutable_open()->add_points()->mutable_position()->set_x(1);
    return request;
  }
  static v1::CoupleRequest Step(double dt, double x) {
    v1::CoupleRequest request;
    request.mutable_step()->set_dt_s(dt);
    request.mutable_step()->add_points()->mutable_position()->set_x(x);
    return request;
  }
  // Sends `request` and reads its reply.
  static v1::CoupleResponse Exchange(Stream* stream, const v1::CoupleRequest& request) {
    v1::CoupleResponse reply;
    EXPECT_TRUE(stream->Write(request));
    EXPECT_TRUE(stream->Read(&reply));
    return reply;
  }

  // Each of `bad` is refused naming its field, the session left as in
  // `good` (its time, steps, forces and host work).
  static void ExpectRefused(Stream* stream, const std::vector<Bad>& bad,
                            const v1::CoupleResponse& good) {
    for (const Bad& b : bad) {
      SCOPED_TRACE(b.path);
      const v1::CoupleResponse reply = Exchange(stream, b.request);
      ASSERT_TRUE(reply.has_error());
      EXPECT_EQ(reply.error().code(), "INVALID_ARGUMENT");
      EXPECT_EQ(reply.error().path(), b.path);
      EXPECT_THAT(reply.error().message(), HasSubstr(b.says));
      v1::CoupleResponse state = reply, before = good;
      state.clear_error();
      before.clear_error();
      EXPECT_EQ(state.SerializeAsString(), before.SerializeAsString());
    }
  }

  std::unique_ptr<CablesimServer> server_;
  std::unique_ptr<v1::CablesimService::Stub> stub_;
};

TEST_F(CoupleServiceTest, StepsAndRefusesBadStepsWithoutLosingTheSession) {
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = stub_->Couple(&context);
  v1::CoupleResponse reply = Exchange(stream.get(), Open(kString));
  ASSERT_FALSE(reply.has_error());
  ASSERT_EQ(reply.forces_size(), 1);
  EXPECT_EQ(reply.coupled_joints(0), 1);
  EXPECT_EQ(reply.scene_positions(0).x(), 1);
  EXPECT_DOUBLE_EQ(reply.max_jump_m(), 0.25);
  EXPECT_EQ(reply.end_time_s(), 1);
  EXPECT_EQ(reply.time_s(), 0);

  reply = Exchange(stream.get(), Step(0.01, 1.001));
  ASSERT_FALSE(reply.has_error()) << reply.error().message();
  EXPECT_DOUBLE_EQ(reply.time_s(), 0.01);
  EXPECT_EQ(reply.steps(), 2);  // 0.01 s in steps of 0.005 s
  // The string pulled 1 mm (1e-3 strain): it pulls the end back with about
  // EA e = 1e7 x 7.85e-5 x 1e-3 = 0.8 N, its weight (7.85e-2 kg) hanging.
  EXPECT_LT(reply.end_forces(0).x(), -0.3);
  EXPECT_LT(reply.end_forces(0).z(), 0);
  const v1::CoupleResponse good = reply;

  std::vector<Bad> bad;
  bad.push_back({Step(-0.01, 1.001), "dt_s", "must be > 0"});
  bad.push_back({Step(0, 1.001), "dt_s", "must be > 0"});
  bad.push_back({Step(std::nan(""), 1.001), "dt_s", "must be > 0"});
  bad.push_back({Step(2, 1.001), "dt_s", "solver.duration"});
  bad.push_back({Step(0.01, std::nan("")), "points[0].position.x", "must be finite"});
  {
    v1::CoupleRequest r = Step(0.01, 1.001);
    r.mutable_step()->mutable_points(0)->mutable_velocity()->set_z(
        std::numeric_limits<double>::infinity());
    bad.push_back({r, "points[0].velocity.z", "must be finite"});
    r = Step(0.01, 1.001);
    *r.mutable_step()->add_points() = r.step().points(0);  // a point the scene has not
    bad.push_back({r, "points", "2 coupled points given, the scene has 1"});
    r = Step(0.01, 1.001);
    r.mutable_step()->clear_points();
    bad.push_back({r, "points", "0 coupled points given"});
  }
  bad.push_back({Step(0.01, 1.5), "points[0].position", "more than the 0.25 m allowed"});
  bad.push_back({Open(kString), "open", "open already"});
  bad.push_back({v1::CoupleRequest(), "step", "a message after open is a step"});
  ExpectRefused(stream.get(), bad, good);
  reply = Exchange(stream.get(), Step(0.01, 1.002));
  ASSERT_FALSE(reply.has_error()) << reply.error().message();
  EXPECT_DOUBLE_EQ(reply.time_s(), 0.02);
  EXPECT_EQ(reply.steps(), 4);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

TEST_F(CoupleServiceTest, TheFirstMessageOpensAndABadOpenEndsTheStream) {
  struct Case {
    v1::CoupleRequest request;
    grpc::StatusCode code;
    std::string starts;
  };
  std::vector<Case> cases;
  cases.push_back({Step(0.01, 1), grpc::StatusCode::INVALID_ARGUMENT, "open:"});
  v1::CoupleRequest r = Open(kString);
  r.mutable_open()->clear_points();
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "points: 0 coupled points given"});
  r = Open(kString);
  r.mutable_open()->mutable_points(0)->mutable_position()->set_y(std::nan(""));
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "points[0].position.y: must be finite"});
  r = Open(kString);
  r.mutable_open()->mutable_points(0)->mutable_position()->set_x(1.1);
  cases.push_back({r, grpc::StatusCode::INVALID_ARGUMENT, "points[0].position: 0.1 m from"});
  std::string uncoupled = kString;
  const std::string coupled = ", \"coupled\": true";
  uncoupled.replace(uncoupled.find(coupled), coupled.size(), "");
  cases.push_back({Open(uncoupled), grpc::StatusCode::INVALID_ARGUMENT, "joints: no coupled"});
  std::string bad_length = kString;
  bad_length.replace(bad_length.find("\"length\": 1"), 11, "\"length\": -1");
  cases.push_back(
      {Open(bad_length), grpc::StatusCode::INVALID_ARGUMENT, "cables[0].length: must be > 0"});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.starts);
    grpc::ClientContext context;
    std::unique_ptr<Stream> stream = stub_->Couple(&context);
    ASSERT_TRUE(stream->Write(c.request));
    v1::CoupleResponse reply;
    EXPECT_FALSE(stream->Read(&reply));
    const grpc::Status status = stream->Finish();
    EXPECT_EQ(status.error_code(), c.code);
    EXPECT_THAT(status.error_message(), StartsWith(c.starts));
  }
}

TEST_F(CoupleServiceTest, AStepTheLinesCannotTakeEndsTheSession) {
  // One Newton iteration and no halving: a stretch of the string fails.
  std::string brittle = kString;
  brittle.replace(brittle.find("\"step\": 0.005"), 13,
                  "\"step\": 0.005, \"max_newton_iterations\": 1, \"max_step_halvings\": 0");
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = stub_->Couple(&context);
  ASSERT_FALSE(Exchange(stream.get(), Open(brittle)).has_error());
  ASSERT_TRUE(stream->Write(Step(0.01, 1.2)));
  v1::CoupleResponse reply;
  EXPECT_FALSE(stream->Read(&reply));
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ABORTED);
  EXPECT_THAT(status.error_message(), HasSubstr("the lines could not be advanced"));
  EXPECT_THAT(status.error_message(), HasSubstr("t = 0"));
}

TEST_F(CoupleServiceTest, ASessionHoldsOneOfTheClientsStreams) {
  Start(/*max_streams_per_peer=*/1);
  grpc::ClientContext first_context;
  std::unique_ptr<Stream> first = stub_->Couple(&first_context);
  ASSERT_FALSE(Exchange(first.get(), Open(kString)).has_error());
  {
    grpc::ClientContext context;
    std::unique_ptr<Stream> second = stub_->Couple(&context);
    second->Write(Open(kString));
    v1::CoupleResponse reply;
    EXPECT_FALSE(second->Read(&reply));
    const grpc::Status status = second->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_THAT(status.error_message(), HasSubstr("max_streams_per_peer"));
  }
  first->WritesDone();
  EXPECT_TRUE(first->Finish().ok());
  // Freed: a new session opens.
  grpc::ClientContext context;
  std::unique_ptr<Stream> again = stub_->Couple(&context);
  EXPECT_FALSE(Exchange(again.get(), Open(kString)).has_error());
  again->WritesDone();
  EXPECT_TRUE(again->Finish().ok());
}

// The string's end held by a coupled body instead: the body's centre at
// (1.5, 0, 0), the string pinned to its point (-0.5, 0, 0).
constexpr char kStringOnBody[] = R"({"gravity": {"z": -9.81},
  "cables": [{"name": "c", "length": 1, "elements": 4, "direction": {"x": 1},
    "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
  "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
    "position": {"x": 1.5}, "coupled": true}],
  "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
             {"type": "PIN", "a": {"cable": "c", "s": 1}, "b": {"body": "b", "point": {"x": -0.5}}}],
  "solver": {"duration": 1, "step": 0.005}})";

// A body at (x, 0, 0) turned by `yaw` about z.
v1::CoupledBody BodyAt(double x, double yaw) {
  v1::CoupledBody b;
  b.mutable_position()->set_x(x);
  b.mutable_orientation()->set_w(std::cos(yaw / 2));
  b.mutable_orientation()->set_z(std::sin(yaw / 2));
  return b;
}

TEST_F(CoupleServiceTest, ACoupledBodyStepsAndRefusesBadPoses) {
  grpc::ClientContext context;
  std::unique_ptr<Stream> stream = stub_->Couple(&context);
  v1::CoupleRequest open;
  open.mutable_open()->set_scene_json(kStringOnBody);
  *open.mutable_open()->add_bodies() = BodyAt(1.5, 0);
  v1::CoupleResponse reply = Exchange(stream.get(), open);
  ASSERT_FALSE(reply.has_error()) << reply.error().message();
  ASSERT_EQ(reply.coupled_bodies_size(), 1);
  EXPECT_EQ(reply.coupled_bodies(0), 0);
  EXPECT_EQ(reply.body_scene_positions(0).x(), 1.5);
  EXPECT_NEAR(reply.body_scene_orientations(0).w(), 1, 1e-12);
  EXPECT_EQ(reply.forces_size(), 0);
  ASSERT_EQ(reply.body_forces_size(), 1);
  EXPECT_EQ(reply.host_work_j(), 0);

  // Turned by 0.01 rad and moved 1 mm out: the string's end moves to
  // (1.5 + 0.001, 0, 0) - 0.5 (cos 0.01, sin 0.01, 0), a stretch of
  // about 1 mm: it pulls the body back towards the anchor.
  auto step = [](double dt, const v1::CoupledBody& body) {
    v1::CoupleRequest r;
    r.mutable_step()->set_dt_s(dt);
    *r.mutable_step()->add_bodies() = body;
    return r;
  };
  reply = Exchange(stream.get(), step(0.01, BodyAt(1.501, 0.01)));
  ASSERT_FALSE(reply.has_error()) << reply.error().message();
  const v1::Vec3 f = reply.body_end_forces(0), m = reply.body_end_moments(0);
  EXPECT_LT(f.x(), -0.3);
  // One pin: the moment about the centre is r x F with r the pin's arm
  // R (-0.5, 0, 0), to the constraint's tolerance.
  const double rx = -0.5 * std::cos(0.01), ry = -0.5 * std::sin(0.01);
  EXPECT_NEAR(m.z(), rx * f.y() - ry * f.x(), 1e-6 * std::abs(f.x()));
  EXPECT_NEAR(m.x(), ry * f.z(), 1e-6 * std::abs(f.x()));
  EXPECT_NEAR(m.y(), -rx * f.z(), 1e-6 * std::abs(f.x()));
  EXPECT_NE(reply.host_work_j(), 0);
  const v1::CoupleResponse good = reply;

  std::vector<Bad> bad;
  {
    v1::CoupledBody b = BodyAt(1.502, 0.02);
    b.mutable_orientation()->set_w(1.1);
    bad.push_back({step(0.01, b), "bodies[0].orientation", "must be a unit quaternion"});
    b = BodyAt(1.502, 0.02);
    b.mutable_orientation()->set_y(std::nan(""));
    bad.push_back({step(0.01, b), "bodies[0].orientation.y", "must be finite"});
    b = BodyAt(1.502, 0.02);
    b.mutable_angular_velocity()->set_x(std::numeric_limits<double>::infinity());
    bad.push_back({step(0.01, b), "bodies[0].angular_velocity.x", "must be finite"});
    v1::CoupleRequest r = step(0.01, BodyAt(1.502, 0.02));
    *r.mutable_step()->add_bodies() = BodyAt(1.502, 0.02);  // a body the scene has not
    bad.push_back({r, "bodies", "2 coupled bodies given, the scene has 1"});
    bad.push_back({step(0.01, BodyAt(1.502, 1.0)), "bodies[0]", "more than the 0.25 m allowed"});
  }
  ExpectRefused(stream.get(), bad, good);
  reply = Exchange(stream.get(), step(0.01, BodyAt(1.502, 0.02)));
  ASSERT_FALSE(reply.has_error()) << reply.error().message();
  EXPECT_DOUBLE_EQ(reply.time_s(), 0.02);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

}  // namespace
}  // namespace cablesim
