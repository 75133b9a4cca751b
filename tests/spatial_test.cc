// Spatial scenes: which model a scene gets, a planar scene in the spatial
// model, a whole scene rotated out of the plane, rigid bodies in space and a
// body welded to a whipped cable. References are analytic (conservation laws,
// symmetry) or the planar model, which tests/dynamics_test.cc and
// tests/statics_test.cc check against analytic solutions.

#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "engine/model/model_choice.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

std::string Vec(const Eigen::Vector3d& v) {
  return absl::StrFormat(R"({"x": %.17g, "y": %.17g, "z": %.17g})", v.x(), v.y(), v.z());
}

// The issue's falling pendulum (shortened), with gravity and the cable
// direction given as vectors so the scene can be rotated.
std::string FallingPendulum(const Eigen::Matrix3d& r, const std::string& model,
                            double duration = 0.3) {
  return absl::StrFormat(R"({
    "model": "%s",
    "gravity": %s,
    "cables": [{"name": "beam", "length": 1.2, "elements": 12, "direction": %s,
                "density": 5540, "youngs_modulus": 0.7e6,
                "area": 0.0018, "second_moment": 1.215e-8}],
    "joints": [{"type": "PIN", "a": {"cable": "beam", "s": 0}}],
    "probes": [{"name": "tip", "cable": "beam", "s": 1.2},
               {"name": "mid", "cable": "beam", "s": 0.6}],
    "solver": {"duration": %g, "step": 1e-3, "output_interval": 0.01,
               "newton_tolerance": 1e-12}})",
                         model, Vec(r * Eigen::Vector3d(0, -9.81, 0)),
                         Vec(r * Eigen::Vector3d::UnitX()), duration);
}

// The paper's cable with an end cylinder (MODEL.md section 7, table 1),
// shortened, optionally rotated as a whole.
std::string CableWithCylinder(const Eigen::Matrix3d& r, const std::string& model) {
  return absl::StrFormat(R"({
    "model": "%s",
    "gravity": %s,
    "cables": [{"name": "cable", "length": 0.5, "elements": 10, "direction": %s,
                "density": 1000, "youngs_modulus": 1e7, "area": 7.85e-5,
                "second_moment": 4.91e-10}],
    "bodies": [{"name": "cylinder", "cylinder": {"diameter": 0.04, "height": 0.1},
                "density": 1000, "position": %s, "axis": %s}],
    "joints": [{"type": "PIN", "a": {"cable": "cable", "s": 0}},
               {"type": "FIXED", "a": {"cable": "cable", "s": 0.5},
                "b": {"body": "cylinder", "point": {"x": -0.05}}}],
    "probes": [{"name": "end", "cable": "cable", "s": 0.5},
               {"name": "face", "body": "cylinder", "point": {"x": 0.05}}],
    "solver": {"duration": 0.5, "step": 0.005, "output_interval": 0.01,
               "newton_tolerance": 1e-12}})",
                         model, Vec(r * Eigen::Vector3d(0, -9.81, 0)),
                         Vec(r * Eigen::Vector3d::UnitX()), Vec(r * Eigen::Vector3d(0.55, 0, 0)),
                         Vec(r * Eigen::Vector3d::UnitX()));
}

// Largest probe-position difference between two runs, each frame's probes
// mapped by `r` from the first run, relative to the largest |position|.
double MaxRelativeDifference(const CollectingSink& a, const CollectingSink& b,
                             const Eigen::Matrix3d& r = Eigen::Matrix3d::Identity()) {
  EXPECT_EQ(a.frames().size(), b.frames().size());
  double diff = 0, scale = 0;
  for (size_t k = 0; k < std::min(a.frames().size(), b.frames().size()); ++k) {
    for (size_t p = 0; p < a.frames()[k].probes.size(); ++p) {
      const Eigen::Vector3d x = r * a.frames()[k].probes[p].position_m;
      diff = std::max(diff, (x - b.frames()[k].probes[p].position_m).norm());
      scale = std::max(scale, x.norm());
    }
  }
  return diff / scale;
}

TEST(ModelChoiceTest, AutoIsPlanarOnlyWhenTheWholeSceneLiesInThePlane) {
  struct Case {
    std::string name, json, model;
  };
  const std::string cable = R"("cables": [{"name": "c", "length": 1, "elements": 2,
      "direction": {"x": 1}, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],)";
  const std::string body = R"("bodies": [{"name": "b", "mass": 1,
      "inertia": {"x": 0.1, "y": 0.1, "z": 0.1}, "position": {"x": 1.5}}],)";
  const std::string solver = R"("solver": {"duration": 0.01}})";
  const Case cases[] = {
      {"in-plane cable, gravity and torque", "{" + cable + body + R"(
         "gravity": {"y": -9.81}, "loads": [{"at": {"body": "b"}, "torque": {"z": 1}}],)" + solver,
       "planar"},
      {"initial linear velocity out of the plane only",
       "{" + cable + R"("initial_velocity": {"linear": {"z": 0.1}},)" + solver, "spatial"},
      {"initial spin about a horizontal axis only",
       "{" + cable + R"("initial_velocity": {"angular": {"y": 4}},)" + solver, "spatial"},
      {"spin about z with an origin off the plane",
       "{" + cable + R"("initial_velocity": {"angular": {"z": 4}, "origin": {"z": 3}},)" + solver,
       "planar"},
      {"gravity along z", "{" + cable + R"("gravity": {"z": -9.81},)" + solver, "spatial"},
      {"a load along z", "{" + cable + R"("loads": [{"at": {"cable": "c", "s": 1},
         "force": {"z": 1}}],)" + solver, "spatial"},
      {"a body point off the plane", "{" + cable + body + R"("probes": [{"name": "p",
         "body": "b", "point": {"z": 0.1}}],)" + solver, "spatial"},
      {"a body axis off the plane", "{" + cable + R"("bodies": [{"name": "b", "mass": 1,
         "inertia": {"x": 0.1, "y": 0.1, "z": 0.1}, "axis": {"x": 1, "z": 1}}],)" + solver,
       "spatial"},
      {"a cable laid out of the plane", R"({"cables": [{"name": "c", "length": 1,
         "points": [{"x": 0}, {"x": 0.5}, {"x": 0.5, "z": 0.5}], "density": 1000,
         "youngs_modulus": 1e7, "diameter": 0.01}],)" + solver, "spatial"},
      {"a planar scene forced to SPATIAL", "{\"model\": \"SPATIAL\", " + cable + solver,
       "spatial"},
  };
  for (const Case& c : cases) {
    const auto info = DescribeModel(SceneFromJson(c.json));
    ASSERT_TRUE(info.ok()) << c.name << ": " << info.status();
    EXPECT_EQ(info->model, c.model) << c.name;
    // 2 D coordinates per node.
    EXPECT_EQ(info->coordinates % (c.model == "planar" ? 4 : 6), 0) << c.name;
  }
}

TEST(ModelChoiceTest, PlanarModelNeedsFewerCoordinatesAndMultipliers) {
  const Eigen::Matrix3d id = Eigen::Matrix3d::Identity();
  const auto planar = DescribeModel(SceneFromJson(CableWithCylinder(id, "PLANAR")));
  const auto spatial = DescribeModel(SceneFromJson(CableWithCylinder(id, "SPATIAL")));
  ASSERT_TRUE(planar.ok() && spatial.ok());
  // 11 nodes of 4 or 6, a body of 4 or 12 (natural coordinates).
  EXPECT_EQ(planar->coordinates, 11 * 4 + 4);
  EXPECT_EQ(spatial->coordinates, 11 * 6 + 12);
  // FIXED joint 2 + 1 or 3 + 2 rows, body axes 1 or 6 rows.
  EXPECT_EQ(planar->multipliers, 4);
  EXPECT_EQ(spatial->multipliers, 11);
}

TEST(SpatialModelTest, PlanarSceneRunAsSpatialFollowsThePlanarTrajectory) {
  // The issue asks for agreement within 1e-9 relative. Newton runs to 1e-12
  // here so that its stopping point does not blur the comparison.
  const Eigen::Matrix3d id = Eigen::Matrix3d::Identity();
  for (const auto& make : {+[](const std::string& m) { return FallingPendulum(Eigen::Matrix3d::Identity(), m); },
                           +[](const std::string& m) { return CableWithCylinder(Eigen::Matrix3d::Identity(), m); }}) {
    CollectingSink planar, spatial;
    const RunSummary sp = RunOk(SceneFromJson(make("PLANAR")), &planar);
    const RunSummary ss = RunOk(SceneFromJson(make("SPATIAL")), &spatial);
    EXPECT_EQ(sp.info.model, "planar");
    EXPECT_EQ(ss.info.model, "spatial");
    const double rel = MaxRelativeDifference(planar, spatial, id);
    std::printf("planar vs spatial model: max relative probe difference %.3g\n", rel);
    EXPECT_LT(rel, 1e-9);
    for (const Frame& f : spatial.frames())
      for (const ProbeSample& p : f.probes) EXPECT_EQ(p.position_m.z(), 0);
  }
}

TEST(SpatialModelTest, SceneRotatedOutOfThePlaneFollowsTheRotatedPlanarTrajectory) {
  // Rotating the whole scene (gravity included) rotates its solution: the
  // spatial model must reproduce the planar run, rotated, to the Newton
  // tolerance (1e-12 here; compared at 1e-9 relative).
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  // The cylinder is axisymmetric, so the body frame's y axis convention
  // (which does not rotate with the scene) must not matter either.
  using Maker = std::string (*)(const Eigen::Matrix3d&, const std::string&);
  const std::pair<const char*, Maker> scenes[] = {
      {"falling pendulum", [](const Eigen::Matrix3d& m, const std::string& model) {
         return FallingPendulum(m, model);
       }},
      {"cable with cylinder", &CableWithCylinder}};
  for (const auto& [name, make] : scenes) {
    CollectingSink planar, rotated;
    RunOk(SceneFromJson(make(Eigen::Matrix3d::Identity(), "AUTO")), &planar);
    const RunSummary s = RunOk(SceneFromJson(make(r, "AUTO")), &rotated);
    EXPECT_EQ(s.info.model, "spatial") << name;
    const double rel = MaxRelativeDifference(planar, rotated, r);
    std::printf("rotated %s: max relative probe difference %.3g\n", name, rel);
    EXPECT_LT(rel, 1e-9) << name;
  }
}

// A free asymmetric body, no gravity: probes at its centre and at the tips
// of its unit axes give e_k = p_k - c and their rates.
struct BodyState {
  double kinetic = 0;
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();  // about the centre
};

BodyState FreeBodyState(const Frame& f, const Eigen::Vector3d& inertia) {
  Eigen::Matrix3d e, ed;
  for (int k = 0; k < 3; ++k) {
    e.col(k) = f.probes[k + 1].position_m - f.probes[0].position_m;
    ed.col(k) = f.probes[k + 1].velocity_m_s - f.probes[0].velocity_m_s;
  }
  // omega = e^T-frame: skew(omega) = edot e^T for an orthonormal frame.
  const Eigen::Matrix3d w = ed * e.transpose();
  const Eigen::Vector3d omega(w(2, 1), w(0, 2), w(1, 0));
  const Eigen::Vector3d body_omega = e.transpose() * omega;
  BodyState s;
  s.kinetic = 0.5 * body_omega.dot(inertia.cwiseProduct(body_omega));
  s.momentum = e * inertia.cwiseProduct(body_omega);
  return s;
}

TEST(SpatialBodyTest, TorqueFreeAsymmetricBodyKeepsEnergyAndMomentumToTheStepperOrder) {
  // Exact solution: kinetic energy and angular momentum constant (Euler's
  // equations). The drift over 2 s must shrink at the stepper's order when
  // the step halves: by 2 for backward Euler (ratio in [0.4, 0.6]), by 4 for
  // HHT (ratio in [0.2, 0.3]); energy must never rise under backward Euler.
  const Eigen::Vector3d inertia(2.0, 3.0, 4.0);
  auto run = [&](const std::string& integrator, double step) {
    const std::string json = absl::StrFormat(R"({
      "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 2, "y": 3, "z": 4},
                  "axis": {"x": 1, "y": 0.2, "z": 0.1}}],
      "initial_velocity": {"angular": {"x": 0.3, "y": 0.2, "z": 1.5}},
      "probes": [{"name": "c", "body": "b"}, {"name": "ex", "body": "b", "point": {"x": 1}},
                 {"name": "ey", "body": "b", "point": {"y": 1}},
                 {"name": "ez", "body": "b", "point": {"z": 1}}],
      "solver": {"duration": 2, "step": %g, "output_interval": 0.1,
                 "newton_tolerance": 1e-12, "integrator": "%s"}})",
                                             step, integrator);
    CollectingSink sink;
    const RunSummary s = RunOk(SceneFromJson(json), &sink);
    EXPECT_EQ(s.info.model, "spatial");
    const BodyState first = FreeBodyState(sink.frames().front(), inertia);
    const BodyState last = FreeBodyState(sink.frames().back(), inertia);
    // The engine's own diagnostics agree with the probes (about the origin,
    // the centre does not move).
    EXPECT_NEAR((sink.frames().front().angular_momentum - first.momentum).norm(), 0,
                1e-9 * first.momentum.norm());
    EXPECT_NEAR(sink.frames().front().energy.kinetic, first.kinetic, 1e-9 * first.kinetic);
    if (integrator == "IMPLICIT_EULER") {
      for (size_t k = 1; k < sink.frames().size(); ++k) {
        EXPECT_LE(sink.frames()[k].energy.total,
                  sink.frames()[k - 1].energy.total + 1e-12 * first.kinetic);
      }
    }
    return std::pair<double, double>(
        std::abs(last.kinetic - first.kinetic) / first.kinetic,
        (last.momentum - first.momentum).norm() / first.momentum.norm());
  };
  struct Order {
    const char* integrator;
    double lo, hi;
  };
  for (const Order& o : {Order{"IMPLICIT_EULER", 0.4, 0.6}, Order{"HHT", 0.2, 0.3}}) {
    const auto coarse = run(o.integrator, 4e-3), fine = run(o.integrator, 2e-3);
    std::printf("free body, %s, h = 4e-3 / 2e-3: energy drift %.3g / %.3g, momentum drift "
                "%.3g / %.3g\n",
                o.integrator, coarse.first, fine.first, coarse.second, fine.second);
    EXPECT_LT(coarse.first, 0.05) << o.integrator;
    EXPECT_LT(coarse.second, 0.05) << o.integrator;
    EXPECT_GT(fine.first / coarse.first, o.lo) << o.integrator;
    EXPECT_LT(fine.first / coarse.first, o.hi) << o.integrator;
    EXPECT_GT(fine.second / coarse.second, o.lo) << o.integrator;
    EXPECT_LT(fine.second / coarse.second, o.hi) << o.integrator;
  }
}

TEST(SpatialBodyTest, ConstantTorqueSpinsABodyUpAsTorqueOverInertia) {
  // A body at rest under a constant torque about its principal axis z:
  // theta(t) = tau t^2 / (2 I_z). Backward Euler is first order; at h = 1e-3
  // over 1 s the angle error is about h / t = 0.1 %, checked at 0.5 %. The
  // torque's work (accumulated from the rotation) balances the kinetic
  // energy to the same order. Planar and spatial (forced) runs alike.
  for (const std::string model : {"PLANAR", "SPATIAL"}) {
    const std::string json = absl::StrFormat(R"({
      "model": "%s",
      "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 0.3, "y": 0.4, "z": 0.5}}],
      "loads": [{"at": {"body": "b"}, "torque": {"z": 0.2}}],
      "probes": [{"name": "tip", "body": "b", "point": {"x": 1}}],
      "solver": {"duration": 1, "step": 1e-3, "output_interval": 0.1}})",
                                             model);
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    const Frame& last = sink.frames().back();
    const double theta = std::atan2(last.probes[0].position_m.y(), last.probes[0].position_m.x());
    const double exact = 0.2 / (2 * 0.5);
    EXPECT_NEAR(theta, exact, 0.005 * exact) << model;
    EXPECT_LT(std::abs(last.energy.total), 0.005 * last.energy.kinetic) << model;
    EXPECT_NEAR(last.angular_momentum.z(), 0.2 * 1.0, 0.005 * 0.2) << model;  // tau t
  }
}

TEST(SpatialBodyTest, CylinderWeldedToAWhippedCableStaysAlongItsTangent) {
  // A cable pinned at the origin, spun about the vertical and falling, with
  // a cylinder FIXED at its end. Every frame: the end and the cylinder face
  // coincide, and the joint rows (the tangent's components along the body's
  // y and z axes, |r_x| sin(angle)) stay below the Newton tolerance scale.
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "cable", "length": 0.5, "elements": 10, "direction": {"x": 1},
                "density": 1000, "youngs_modulus": 1e7, "area": 7.85e-5,
                "second_moment": 4.91e-10}],
    "bodies": [{"name": "cylinder", "cylinder": {"diameter": 0.04, "height": 0.1},
                "density": 1000, "position": {"x": 0.55}}],
    "joints": [{"type": "PIN", "a": {"cable": "cable", "s": 0}},
               {"type": "FIXED", "a": {"cable": "cable", "s": 0.5},
                "b": {"body": "cylinder", "point": {"x": -0.05}}}],
    "initial_velocity": {"angular": {"y": 4}},
    "probes": [{"name": "end", "cable": "cable", "s": 0.5},
               {"name": "face", "body": "cylinder", "point": {"x": -0.05}}],
    "solver": {"duration": 2, "step": 0.002, "output_interval": 0.01}})";
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  EXPECT_EQ(s.info.model, "spatial");
  double zmax = 0;
  for (const Frame& f : sink.frames()) {
    EXPECT_LT((f.probes[0].position_m - f.probes[1].position_m).norm(), 1e-8) << "t = " << f.t;
    EXPECT_LT(f.constraint_violation, 1e-8) << "t = " << f.t;
    zmax = std::max(zmax, std::abs(f.probes[0].position_m.z()));
  }
  EXPECT_GT(zmax, 0.1);  // it really left the plane
  std::printf("welded cylinder: max constraint violation %.3g over %lld steps\n",
              s.max_constraint_violation, static_cast<long long>(s.steps));
}

TEST(SpatialStaticsTest, CantileverLoadedAlongZBendsAsTheInPlaneOne) {
  // By symmetry of the round section, a tip load along -z deflects a clamped
  // cable exactly as the same load along -y; the planar run is checked
  // against Mattiasson's large-deflection values in statics_test.cc.
  auto run = [](const std::string& dir) {
    const std::string json = absl::StrFormat(R"({
      "cables": [{"name": "c", "length": 1, "elements": 8, "direction": {"x": 1},
                  "density": 1000, "youngs_modulus": 2e11, "diameter": 0.01}],
      "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0}}],
      "loads": [{"at": {"cable": "c", "s": 1}, "force": {"%s": -500}}],
      "probes": [{"name": "tip", "cable": "c", "s": 1}],
      "solver": {"analysis": "STATIC", "load_steps": 5}})",
                                             dir);
    CollectingSink sink;
    const RunSummary s = RunOk(SceneFromJson(json), &sink);
    return std::pair<std::string, Eigen::Vector3d>(s.info.model,
                                                   sink.frames().back().probes[0].position_m);
  };
  const auto [pm, py] = run("y");
  const auto [sm, sz] = run("z");
  EXPECT_EQ(pm, "planar");
  EXPECT_EQ(sm, "spatial");
  EXPECT_NEAR(sz.x(), py.x(), 1e-9);
  EXPECT_NEAR(sz.z(), py.y(), 1e-9);
  EXPECT_NEAR(sz.y(), 0, 1e-12);
  EXPECT_GT(-py.y(), 0.05);  // a large deflection, not a linear one
}

TEST(SpatialJointTest, WeldedCablesFollowTheContinuousCablePastVertical) {
  // A 2 m cable pinned at the origin, falling from horizontal while spun
  // about the vertical, once as one cable of 8 elements and once as 1.5 m +
  // 0.5 m cables (6 + 2 elements, the same nodes) FIXED end to end. Equal
  // slopes make the weld a shared node, so the two discrete systems are the
  // same: probes agree to the Newton tolerance (1e-12 here) all the way
  // through the vertical, where rows tied to the initial tangent would lose
  // rank.
  const std::string common = R"(
    "gravity": {"y": -9.81},
    "initial_velocity": {"angular": {"y": 1.0}},
    "solver": {"duration": 1.2, "step": 2e-3, "output_interval": 0.01,
               "newton_tolerance": 1e-12})";
  const std::string one = R"({"cables": [{"name": "a", "length": 2, "elements": 8,
      "direction": {"x": 1}, "density": 1000, "youngs_modulus": 1e8, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "a", "s": 0}}],
    "probes": [{"name": "tip", "cable": "a", "s": 2}, {"name": "joint", "cable": "a", "s": 1.5}],)" +
                          common + "}";
  const std::string two = R"({"cables": [
      {"name": "a", "length": 1.5, "elements": 6, "direction": {"x": 1}, "density": 1000,
       "youngs_modulus": 1e8, "diameter": 0.01},
      {"name": "b", "length": 0.5, "elements": 2, "start": {"x": 1.5}, "direction": {"x": 1},
       "density": 1000, "youngs_modulus": 1e8, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "a", "s": 0}},
               {"type": "FIXED", "a": {"cable": "a", "s": 1.5}, "b": {"cable": "b", "s": 0}}],
    "probes": [{"name": "tip", "cable": "b", "s": 0.5}, {"name": "joint", "cable": "b", "s": 0}],)" +
                          common + "}";
  CollectingSink continuous, welded;
  RunOk(SceneFromJson(one), &continuous);
  const RunSummary s = RunOk(SceneFromJson(two), &welded);
  EXPECT_EQ(s.info.model, "spatial");
  EXPECT_EQ(s.info.multipliers, 6);  // 3 position rows, 3 slope rows
  const double rel = MaxRelativeDifference(continuous, welded);
  std::printf("welded vs continuous cable: max relative probe difference %.3g\n", rel);
  EXPECT_LT(rel, 1e-9);
  // It did swing through the vertical below the pin.
  double lowest = 0;
  for (const Frame& f : welded.frames()) lowest = std::min(lowest, f.probes[1].position_m.y());
  EXPECT_LT(lowest, -1.4);
}

TEST(SpatialJointTest, WeldOfTwoCablesNeedsParallelTangents) {
  const auto info = DescribeModel(SceneFromJson(R"({"cables": [
      {"name": "a", "length": 1, "direction": {"x": 1}, "density": 1000, "youngs_modulus": 1e8,
       "diameter": 0.01},
      {"name": "b", "length": 1, "start": {"x": 1}, "direction": {"y": 1, "z": 1}, "density": 1000,
       "youngs_modulus": 1e8, "diameter": 0.01}],
    "joints": [{"type": "FIXED", "a": {"cable": "a", "s": 1}, "b": {"cable": "b", "s": 0}}],
    "solver": {"duration": 0.1}})"));
  ASSERT_FALSE(info.ok());
  EXPECT_NE(info.status().message().find("joints[0]: FIXED between two cables needs their tangents"),
            std::string::npos)
      << info.status();
}

TEST(SpatialJointTest, InitialVelocityIsProjectedOntoTheJoints) {
  // A free body (m = 1, I_z = 0.5) pinned to ground at body point (-1, 0),
  // given the rigid velocity (0, 1) which the pin forbids. The projection in
  // the kinetic-energy metric is the inelastic impulse: the body turns about
  // the pin with omega = m / (m + I) = 2/3 rad/s, so its centre moves at
  // (0, 2/3) m/s. Planar and spatial alike.
  for (const std::string model : {"PLANAR", "SPATIAL"}) {
    const std::string json = absl::StrFormat(R"({"model": "%s",
      "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 0.3, "y": 0.3, "z": 0.5},
                  "position": {"x": 1}}],
      "joints": [{"type": "PIN", "a": {"body": "b", "point": {"x": -1}}}],
      "initial_velocity": {"linear": {"y": 1}},
      "probes": [{"name": "c", "body": "b"}, {"name": "pin", "body": "b", "point": {"x": -1}}],
      "solver": {"duration": 0.01, "step": 1e-3}})",
                                             model);
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    const Frame& f0 = sink.frames().front();
    EXPECT_NEAR(f0.probes[0].velocity_m_s.y(), 2.0 / 3.0, 1e-12) << model;
    EXPECT_NEAR(f0.probes[0].velocity_m_s.x(), 0, 1e-12) << model;
    EXPECT_NEAR(f0.probes[1].velocity_m_s.norm(), 0, 1e-12) << model;
  }
}

TEST(SpatialJointTest, JointsThatGroundingMakesConstantAreDropped) {
  // A clamped cable end welded to a body that is welded to ground: after
  // the elimination no row can change, so none is kept.
  for (const std::string model : {"PLANAR", "SPATIAL"}) {
    const Scene scene = SceneFromJson(absl::StrFormat(R"({"model": "%s",
      "gravity": {"y": -9.81},
      "cables": [{"name": "c", "length": 1, "elements": 4, "direction": {"x": 1},
                  "density": 1000, "youngs_modulus": 1e8, "diameter": 0.01}],
      "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 0.3, "y": 0.3, "z": 0.5},
                  "position": {"x": -0.1}}],
      "joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0}},
                 {"type": "FIXED", "a": {"body": "b"}},
                 {"type": "FIXED", "a": {"cable": "c", "s": 0}, "b": {"body": "b", "point": {"x": 0.1}}}],
      "solver": {"duration": 0.01, "step": 1e-3}})",
                                                      model));
    const auto info = DescribeModel(scene);
    ASSERT_TRUE(info.ok()) << info.status();
    EXPECT_EQ(info->multipliers, 0) << model;
    CollectingSink sink;
    RunOk(scene, &sink);
  }
}

TEST(SpatialBodyTest, TorqueWorkDoesNotDependOnTheOutputInterval) {
  // The torque's work is summed over steps, not frames: a body turned by a
  // constant torque through several turns reports the same final energy
  // balance whether frames come every 0.01 s or once a second (1e-9 of the
  // kinetic energy).
  double totals[2];
  int k = 0;
  for (double interval : {0.01, 1.0}) {
    const std::string json = absl::StrFormat(R"({"model": "SPATIAL",
      "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 0.3, "y": 0.35, "z": 0.1}}],
      "joints": [{"type": "PIN", "a": {"body": "b"}}],
      "loads": [{"at": {"body": "b"}, "torque": {"z": 0.2}}],
      "solver": {"duration": 3, "step": 1e-3, "output_interval": %g,
                 "newton_tolerance": 1e-12}})",
                                             interval);
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    const Frame& last = sink.frames().back();
    EXPECT_GT(last.energy.kinetic, 1.0);  // several turns: 0.2^2 9 / (2 0.1)
    totals[k++] = last.energy.total / last.energy.kinetic;
  }
  EXPECT_NEAR(totals[0], totals[1], 1e-9);
}

TEST(SpatialBodyTest, FreeSpinDecaysAtBackwardEulersKnownRate) {
  // Backward Euler damps rotation in natural coordinates as it damps any
  // oscillation: for a free spin, the index-3 step gives
  // 2 sin(dth_{n+1}) = sin(dth_{n+1} + dth_n), so dth_{n+1} = dth_n (1 -
  // dth_n^2) to leading order, i.e. d omega / dt = -h omega^3 and
  // omega(t) = omega0 / sqrt(1 + 2 omega0^2 h t). Kinetic energy ratio after
  // 1 s at omega0 = 10 rad/s: 1 / (1 + 200 h). Checked at 0.5 % (the next
  // terms are O((omega h)^2)). The README quotes this cost.
  for (const std::string model : {"PLANAR", "SPATIAL"}) {
    for (double h : {1e-3, 5e-4}) {
      const std::string json = absl::StrFormat(R"({"model": "%s",
        "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 0.06, "y": 0.06, "z": 0.1}}],
        "initial_velocity": {"angular": {"z": 10}},
        "solver": {"duration": 1, "step": %g, "output_interval": 1,
                   "integrator": "IMPLICIT_EULER"}})",
                                               model, h);
      CollectingSink sink;
      const RunSummary s = RunOk(SceneFromJson(json), &sink);
      const double ratio = s.energy_final / s.energy_initial;
      const double expected = 1 / (1 + 200 * h);
      EXPECT_NEAR(ratio, expected, 0.005 * expected) << model << " h = " << h;
    }
  }
}

}  // namespace
}  // namespace cablesim
