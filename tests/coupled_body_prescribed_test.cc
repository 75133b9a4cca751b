// A coupled body driven by the host (engine/run/coupling.h) against the
// same body whose motion the scene prescribes (issue 33).
//
// tests/data/couple_body_prescribed.json: the floater body of
// couple_body_coupled.json held by a FIXED joint to ground that surges it
// at 0.5 m/s and turns it at 0.1 rad/s about the tilted axis
// (0, 0.5, 1) / |.| (yaw and pitch together), from its static equilibrium;
// output.reactions gives its three line joints' forces. The coupling
// session gets the same motion from the host at the coupling steps' ends
// (every 0.05 s): the centre's linear law and the slerp between the
// steps' orientations are exactly the scene's laws here (a constant rate
// about a fixed axis), and the session takes the same internal steps
// (solver.step 2.5 ms, 20 per coupling step), so the two runs solve the
// same equations: the body's force and moment at each step's end must
// agree to the Newton iterations' tolerance, 1e-7 of |F| (and of |F| r,
// r = 10 m, for the moment). Measured: 4.3e-11. A slerp about the wrong
// axis, the transposed rotation, or a moment about the wrong point gives
// differences of 1e-2 and more.

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "engine/run/coupling.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(CoupledBodyPrescribedTest, TheHostsMotionGivesThePrescribedMotionsForces) {
  const double kSurge = 0.5, kRate = 0.1, kDt = 0.05;
  const Eigen::Vector3d axis = Eigen::Vector3d(0, 0.5, 1).normalized();
  // The reference: the motion in the scene.
  CollectingSink sink;
  RunOk(SceneFromJson(Read("tests/data/couple_body_prescribed.json")), &sink);
  ASSERT_GE(sink.frames().size(), 21u);
  // The session: the host's motion.
  absl::StatusOr<std::unique_ptr<CouplingSession>> opened =
      CouplingSession::Open(SceneFromJson(Read("tests/data/couple_body_coupled.json")));
  ASSERT_TRUE(opened.ok()) << opened.status();
  CouplingSession& session = **opened;
  ASSERT_EQ(session.coupled_bodies(), 1);
  ASSERT_EQ(session.coupled_points(), 0);
  auto pose = [&](double t) {
    CoupledBodyKinematics b;
    b.position = Eigen::Vector3d(kSurge * t, 0, 0);
    b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(kRate * t, axis));
    b.velocity = Eigen::Vector3d(kSurge, 0, 0);
    b.angular_velocity = kRate * axis;
    return b;
  };
  ASSERT_TRUE(session.Initialize({}, {}, {pose(0)}).ok());
  // The line joints (cable on side a, the body on b) and their body points.
  const Scene& scene = SceneFromJson(Read("tests/data/couple_body_coupled.json"));
  std::vector<int> joints;
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < static_cast<int>(scene.joints.size()); ++j) {
    if (scene.joints[j].b.body != 0) continue;
    joints.push_back(j);
    points.push_back(scene.joints[j].b.point_body_m);
  }
  ASSERT_EQ(joints.size(), 3u);
  double worst = 0;
  for (int n = 0; n <= 20; ++n) {
    const double t = n * kDt;
    if (n > 0) {
      ASSERT_TRUE(session.Step(t, {}, {}, {pose(t)}).ok());
    }
    const Frame* frame = nullptr;
    for (const Frame& f : sink.frames())
      if (std::abs(f.t - t) < 1e-9) frame = &f;
    ASSERT_NE(frame, nullptr) << "no reference frame at " << t;
    // (Its six line joints and the driving FIXED joint, as the coupled
    // scene has its six and the driver.)
    ASSERT_EQ(frame->reactions.size(), scene.joints.size());
    const CoupledBodyKinematics b = pose(t);
    Eigen::Vector3d f = Eigen::Vector3d::Zero(), m = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < joints.size(); ++k) {
      const Eigen::Vector3d fk = -frame->reactions[joints[k]].force;  // on the body
      f += fk;
      m += (b.orientation * points[k]).cross(fk);
    }
    const double scale = f.norm();
    const double df = (session.body_forces()[0] - f).norm() / scale;
    const double dm = (session.body_moments()[0] - m).norm() / (10 * scale);
    worst = std::max({worst, df, dm});
    EXPECT_LE(df, 1e-7) << "t = " << t << ": " << session.body_forces()[0].transpose() << " vs "
                        << f.transpose();
    EXPECT_LE(dm, 1e-7) << "t = " << t << ": " << session.body_moments()[0].transpose() << " vs "
                        << m.transpose();
  }
  std::printf("largest difference from the prescribed run: %.3g (of |F|, |F| r)\n", worst);
}

// A coupled body is held by its host: the scene may not hold it too, nor
// hang a sliding joint on it (whose force the host would not be told of).
TEST(CoupledBodyPrescribedTest, TheSceneRefusesAJointToGroundOrASlideOnACoupledBody) {
  const std::string base = R"({"gravity": {"z": -9.81},
    "cables": [{"name": "c", "length": 1, "elements": 4, "direction": {"x": 1},
      "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1},
      "position": {"x": 1.5}, "coupled": true}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
               JOINT],
    "solver": {"analysis": "DYNAMIC", "duration": 1, "step": 0.005}})";
  auto with = [&](const std::string& joint) {
    std::string json = base;
    json.replace(json.find("JOINT"), 5, joint);
    return json;
  };
  EXPECT_EQ(testing::SceneError(with(
                R"({"type": "PIN", "a": {"cable": "c", "s": 1}, "b": {"body": "b", "point": {"x": -0.5}}})")),
            "ok");
  EXPECT_EQ(testing::SceneError(with(R"({"type": "PIN", "a": {"body": "b"}})")),
            "bodies[0].coupled: the host holds the body: joints[1] must not join it to the ground");
  EXPECT_EQ(testing::SceneError(with(
                R"({"type": "SLIDE", "a": {"body": "b", "point": {"x": -0.5}}, "b": {"cable": "c", "s": 1}})")),
            "bodies[0].coupled: joints[1]: a SLIDE joint on a coupled body is not supported");
}

}  // namespace
}  // namespace cablesim
