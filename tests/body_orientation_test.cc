// Body orientation and angular velocity (Scene.output.orientation): a body
// spinning freely about a principal axis keeps its angular velocity, and
// its orientation is the rotation by omega t about that axis (closed form:
// torque-free rotation about a principal axis is steady); a body probe at
// a body point gives an independent reading of the same rotation.

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/output/frame_columns.h"
#include "engine/run/simulation.h"
#include "test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// A 2 kg body (principal moments 2, 2.5, 3 kg m^2) spinning at `rate`
// rad/s about world `axis` (x, y or z), no gravity, 2 s; a probe 1 m along
// the body's x axis. The steppers hold the steady spin to their accuracy
// (HHT at 1 ms, about z: the angle is off by 4.2e-8 rad after 2 s and the
// rate by 7.7e-9 rad/s, measured with the CLI); the tolerance, 1e-6, is
// far below a quaternion read with the wrong sign convention or an angle
// of the wrong axis (errors of order 1).
std::string Spin(const std::string& model, const std::string& axis, double rate) {
  return absl::StrFormat(R"({"name": "spin", "model": "%s",
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 2, "y": 2.5, "z": 3}}],
    "initial_velocity": {"angular": {"%s": %.17g}},
    "probes": [{"name": "p", "body": "b", "point": {"x": 1}}],
    "output": {"orientation": true},
    "solver": {"duration": 2, "step": 0.001, "output_interval": 0.25}})",
                         model, axis, rate);
}

TEST(BodyOrientationTest, SteadySpinAboutZIsYawAtTheRate) {
  for (const char* model : {"PLANAR", "SPATIAL"}) {
    CollectingSink sink;
    RunOk(SceneFromJson(Spin(model, "z", 0.5)), &sink);
    ASSERT_TRUE(sink.info().body_orientation);
    const std::vector<std::string> columns = FrameColumns(sink.info());
    EXPECT_THAT(columns, ::testing::Contains("bodies[0].qw"));
    EXPECT_THAT(columns, ::testing::Contains("bodies[0].yaw"));
    EXPECT_EQ(columns.back(), "bodies[0].wz");
    for (const Frame& f : sink.frames()) {
      ASSERT_EQ(f.body_orientation.size(), 10u);
      const double angle = 0.5 * f.t;
      const double* o = f.body_orientation.data();
      EXPECT_NEAR(o[0], std::cos(angle / 2), 1e-6) << model << " t " << f.t;
      EXPECT_NEAR(o[1], 0, 1e-12);
      EXPECT_NEAR(o[2], 0, 1e-12);
      EXPECT_NEAR(o[3], std::sin(angle / 2), 1e-6) << model << " t " << f.t;
      EXPECT_NEAR(o[4], 0, 1e-12);  // roll
      EXPECT_NEAR(o[5], 0, 1e-12);  // pitch
      EXPECT_NEAR(o[6], angle, 1e-6) << model << " t " << f.t;
      EXPECT_NEAR(o[9], 0.5, 1e-6) << model << " t " << f.t;
      // The probe on the body's x axis reads the same angle.
      const Eigen::Vector3d p = f.probes[0].position_m;
      EXPECT_NEAR(std::atan2(p.y(), p.x()), o[6], 1e-9);
    }
  }
}

// About world x (spatial): roll = omega t while |roll| < pi, the quaternion
// (cos, sin, 0, 0) of the half angle, the angular velocity along x; and
// about y, pitch = omega t (kept below pi/2 over the run: 0.7 rad/s, 2 s).
TEST(BodyOrientationTest, SteadySpinAboutXAndYIsRollAndPitch) {
  {
    CollectingSink sink;
    RunOk(SceneFromJson(Spin("SPATIAL", "x", 1.2)), &sink);
    for (const Frame& f : sink.frames()) {
      const double angle = 1.2 * f.t;
      const double* o = f.body_orientation.data();
      EXPECT_NEAR(o[0], std::cos(angle / 2), 1e-6) << f.t;
      EXPECT_NEAR(o[1], std::sin(angle / 2), 1e-6) << f.t;
      EXPECT_NEAR(o[4], angle, 1e-6) << f.t;
      EXPECT_NEAR(o[6], 0, 1e-9) << f.t;
      EXPECT_NEAR(o[7], 1.2, 1e-6) << f.t;
      EXPECT_NEAR(o[9], 0, 1e-9) << f.t;
    }
  }
  CollectingSink sink;
  RunOk(SceneFromJson(Spin("SPATIAL", "y", 0.7)), &sink);
  for (const Frame& f : sink.frames()) {
    const double angle = 0.7 * f.t;
    const double* o = f.body_orientation.data();
    EXPECT_NEAR(o[2], std::sin(angle / 2), 1e-6) << f.t;
    EXPECT_NEAR(o[5], angle, 1e-6) << f.t;
    EXPECT_NEAR(o[8], 0.7, 1e-6) << f.t;
    // The probe on the body's x axis tips down as the body pitches up
    // about y: x = cos(angle), z = -sin(angle).
    EXPECT_NEAR(f.probes[0].position_m.z(), -std::sin(angle), 1e-6) << f.t;
  }
}

TEST(BodyOrientationTest, NoneUnlessAskedFor) {
  std::string json = Spin("SPATIAL", "z", 0.5);
  json.replace(json.find(R"("orientation": true)"), 19, R"("orientation": false)");
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  EXPECT_FALSE(sink.info().body_orientation);
  EXPECT_TRUE(sink.frames().back().body_orientation.empty());
}

}  // namespace
}  // namespace cablesim
