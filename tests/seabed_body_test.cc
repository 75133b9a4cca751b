// Rigid bodies on the seabed (BodySpec contact points, Seabed::PointPotential
// in engine/forces/seabed.h) against closed forms:
//  - a block on 4 contact points of stiffness k rests sunk by m g / (4 k),
//    planar and spatial, in statics; dropped on a damped bed it comes to
//    rest there with energy.total + energy.damped at its initial value;
//  - dragged along the bed at constant speed v the pull that keeps the
//    speed is mu m g v / sqrt(v^2 + v_s^2) (Coulomb times the
//    regularisation), in any direction of the bed's plane;
//  - in statics a pull F < mu m g at the contact level moves the block by
//    u_s F / sqrt((mu m g)^2 - F^2) (the static friction's law);
//  - a chain hanging from a fixed point to a clump weight on the bed shares
//    the clump's weight with the bed (statically indeterminate);
//  - the force and matrix are the derivatives of energy.contact;
//  - bad contact fields are refused by name.

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/model/multibody_model.h"
#include "engine/analysis/static_solver.h"
#include "tests/net_force_derivatives.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// A 1000 kg block, contact points 0.5 m below its centre at (+-0.6, +-0.4)
// (the planar model sees x and y only: two places, two springs each).
constexpr double kMass = 1000, kG = 9.81, kK = 1e7, kH = 0.5;
constexpr char kPoints[] =
    R"([{"x": -0.6, "y": -0.5, "z": -0.4}, {"x": 0.6, "y": -0.5, "z": -0.4},
        {"x": -0.6, "y": -0.5, "z": 0.4}, {"x": 0.6, "y": -0.5, "z": 0.4}])";

// The block with its contact points `lift` [m] above the bed (y = 0),
// `extra` appended to the body, then `rest` to the scene.
std::string Block(const std::string& model, double lift, const std::string& contact,
                  const std::string& rest, const std::string& seabed_extra = "") {
  return absl::StrFormat(R"({
    "model": "%s",
    "gravity": {"y": -9.81},
    "bodies": [{"name": "block", "mass": %.17g, "inertia": {"x": 100, "y": 120, "z": 110},
                "position": {"y": %.17g},
                "seabed_contact": {"points": %s, "stiffness": %.17g %s}}],
    "probes": [{"name": "c", "body": "block"}],
    "seabed": {"stiffness": 1e6 %s},
    %s})",
                         model, kMass, kH + lift, kPoints, kK, contact, seabed_extra, rest);
}

Eigen::VectorXd StaticsOf(const Scene& scene, MultibodyModel* model) {
  StaticSolver solver(model, scene.solver);
  for (int k = 1; k <= 4; ++k) {
    const auto stats = solver.Solve(k / 4.0);
    EXPECT_TRUE(stats.converged) << k << ": " << stats.reason;
  }
  Eigen::VectorXd q(model->coordinates());
  model->ToFull(solver.z(), &q);
  return q;
}

// Statics: the centre sinks by m g / (4 k) (each point carries m g / 4),
// and energy.contact is 4 k p^2 / 2. Friction (0.5) holds the block in its
// plane (without it nothing resists a sideways motion). Tolerance 1e-9
// relative: the springs are linear once in the bed; Newton's tolerance.
TEST(SeabedBodyTest, BlockRestsSunkByWeightOverFourSprings) {
  const double sink = kMass * kG / (4 * kK);
  for (const char* model : {"PLANAR", "SPATIAL"}) {
    const Scene scene = SceneFromJson(
        Block(model, 0, R"(, "friction": 0.5)",
              R"("solver": {"analysis": "STATIC", "newton_tolerance": 1e-12})"));
    auto m = MultibodyModel::Build(scene);
    ASSERT_TRUE(m.ok()) << m.status();
    ASSERT_EQ(m->body_contacts(), 1);
    const Eigen::VectorXd q = StaticsOf(scene, &*m);
    const double y = q(0 + 1);  // the body is the only thing: r_c first
    std::printf("%s: centre %.9e m, expected %.9e m\n", model, y, kH - sink);
    EXPECT_NEAR(y, kH - sink, 1e-9 * kH + 1e-6 * sink);
    EXPECT_NEAR(q(0), 0, 1e-9);
    const EnergySample e = m->Energy(q, Eigen::VectorXd::Zero(q.size()), 1.0);
    EXPECT_NEAR(e.contact, 2 * kK * sink * sink, 1e-6 * 2 * kK * sink * sink);
  }
}

// Dropped from 2 cm onto a bed with damping c per point (zeta = c / (2
// sqrt(k m / 4)) = 0.5), the block comes to rest sunk by m g / (4 k); the
// trapezoidal rule (generalized-alpha, rho_inf = 1) closes energy.total +
// energy.damped to 1e-3 of the damped work (the contact's kink at
// touchdown is what is left), as the chain's drop does.
TEST(SeabedBodyTest, DroppedBlockComesToRestWithTheBalanceClosed) {
  const double sink = kMass * kG / (4 * kK);
  const double c = 0.5 * 2 * std::sqrt(kK * kMass / 4);
  for (const char* model : {"PLANAR", "SPATIAL"}) {
    CollectingSink sink_frames;
    const RunSummary s = RunOk(
        SceneFromJson(Block(model, 0.02, absl::StrFormat(R"(, "damping": %.17g)", c),
                            R"("solver": {"analysis": "DYNAMIC", "duration": 1, "step": 2e-4,
                                          "output_interval": 0.01,
                                          "integrator": "GENERALIZED_ALPHA",
                                          "rho_infinity": 1})")),
        &sink_frames);
    ASSERT_FALSE(sink_frames.frames().empty());
    ASSERT_TRUE(sink_frames.info().contact);
    const Frame& last = sink_frames.frames().back();
    std::printf("%s: rest y %.6e m (expected %.6e), damped %.4f J, balance %.3e J\n", model,
                last.probes[0].position_m.y(), kH - sink, s.energy_damped,
                s.energy_final + s.energy_damped - s.energy_initial);
    // omega = 200 rad/s, zeta 0.5: after 1 s the motion is e^-100 of the
    // impact; the rest depth to 1e-6 of the sink.
    EXPECT_NEAR(last.probes[0].position_m.y(), kH - sink, 1e-6 * sink);
    EXPECT_NEAR(last.energy.contact, 2 * kK * sink * sink, 1e-5 * 2 * kK * sink * sink);
    ASSERT_GT(s.energy_damped, 0);
    EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 1e-3 * s.energy_damped);
  }
}

// Sliding at v = 0.1 m/s along `dir` (unit, in the bed's plane) under the
// pull mu m g v / sqrt(v^2 + v_s^2) at the contact level (no tipping
// moment), the block keeps its speed: any other pull would change it by
// (F - friction) t / m (1e-2 m/s per percent of the pull over 2 s). The
// block starts at its resting depth. Tolerance 1e-6 m/s: Newton's
// tolerance (friction's slope at this speed, mu m g v_s^2 / s^3, is small,
// so an error decays slowly rather than being corrected).
TEST(SeabedBodyTest, DraggedAlongTheBedPullsWithMuMg) {
  const double mu = 0.6, v = 0.1, vs = 1e-3, sink = kMass * kG / (4 * kK);
  const double pull = mu * kMass * kG * v / std::sqrt(v * v + vs * vs);
  struct Case {
    const char* model;
    double dx, dz;
  };
  for (const Case& cs : {Case{"PLANAR", 1, 0}, Case{"SPATIAL", std::sqrt(0.5), std::sqrt(0.5)}}) {
    const std::string rest = absl::StrFormat(
        R"("loads": [{"at": {"body": "block", "point": {"y": -0.5}},
                      "force": {"x": %.17g, "z": %.17g}}],
           "initial_velocity": {"linear": {"x": %.17g, "z": %.17g}},
           "solver": {"analysis": "DYNAMIC", "duration": 2, "step": 0.01,
                      "output_interval": 0.1, "newton_tolerance": 1e-10})",
        pull * cs.dx, pull * cs.dz, v * cs.dx, v * cs.dz);
    CollectingSink frames;
    const RunSummary s =
        RunOk(SceneFromJson(Block(cs.model, -sink, R"(, "friction": 0.6)", rest)), &frames);
    ASSERT_FALSE(frames.frames().empty());
    for (const Frame& f : frames.frames()) {
      EXPECT_NEAR(f.probes[0].velocity_m_s.x(), v * cs.dx, 1e-6) << cs.model << " " << f.t;
      EXPECT_NEAR(f.probes[0].velocity_m_s.z(), v * cs.dz, 1e-6) << cs.model << " " << f.t;
    }
    // The pull's work (in energy.potential) goes into friction (damped).
    const double work = pull * v * 2;
    std::printf("%s: speed %.9f m/s, damped %.3f J (pull's work %.3f J), balance %.3e J\n",
                cs.model, frames.frames().back().probes[0].velocity_m_s.norm(), s.energy_damped,
                work, s.energy_final + s.energy_damped - s.energy_initial);
    EXPECT_NEAR(s.energy_damped, work, 1e-4 * work);
    EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 1e-4 * work);
  }
}

// Statics: a sideways pull F = 0.5 mu m g at the contact level moves the
// block by u_s F / sqrt((mu m g)^2 - F^2) = 0.577 u_s (the regularised
// static friction, seabed.h), here with u_s = 1 mm; a pull above mu m g
// has no equilibrium. Tolerance 1e-6 relative (Newton).
TEST(SeabedBodyTest, StaticFrictionHoldsAPullBelowMuMg) {
  const double mu = 0.5, us = 1e-3, n = kMass * kG;
  for (const char* model : {"PLANAR", "SPATIAL"}) {
    for (double ratio : {0.5, 0.9}) {
      const double f = ratio * mu * n;
      const Scene scene = SceneFromJson(Block(
          model, 0, R"(, "friction": 0.5)",
          absl::StrFormat(R"("loads": [{"at": {"body": "block", "point": {"y": -0.5}},
                                        "force": {"x": %.17g}}],
                             "solver": {"analysis": "STATIC", "newton_tolerance": 1e-12})",
                          f),
          absl::StrFormat(R"(, "friction_length": %.17g)", us)));
      auto m = MultibodyModel::Build(scene);
      ASSERT_TRUE(m.ok()) << m.status();
      const Eigen::VectorXd q = StaticsOf(scene, &*m);
      const double expect = us * f / std::sqrt(mu * mu * n * n - f * f);
      std::printf("%s F/(mu m g) %.1f: moved %.9e m, expected %.9e m\n", model, ratio, q(0),
                  expect);
      EXPECT_NEAR(q(0), expect, 1e-6 * expect);
    }
  }
  const Scene scene = SceneFromJson(Block(
      "PLANAR", 0, R"(, "friction": 0.5)",
      absl::StrFormat(R"("loads": [{"at": {"body": "block", "point": {"y": -0.5}},
                                    "force": {"x": %.17g}}],
                         "solver": {"analysis": "STATIC"})",
                      1.2 * mu * n)));
  auto m = MultibodyModel::Build(scene);
  ASSERT_TRUE(m.ok()) << m.status();
  StaticSolver solver(&*m, scene.solver);
  bool failed = false;
  for (int k = 1; k <= 4 && !failed; ++k) failed = !solver.Solve(k / 4.0).converged;
  EXPECT_TRUE(failed) << "a pull above mu m g found an equilibrium";
}

// A clump weight (2000 kg, contact points as the block's) on the bed hangs
// from a 10 m chain (w = 770 N/m, EA = 5e7 N) pinned above it; laid with
// the chain unstretched and the points at the bed. At equilibrium the
// chain's bottom tension T_b and the bed's force 4 k p share the weight,
// M g = T_b + 4 k p, and the chain's stretch is the sink:
//   p = int_0^L (lambda(T_b + w s) - 1) ds,
// lambda(T) the element's stretch under T (Green-Lagrange: T = EA lambda
// (lambda^2 - 1) / 2). The reference solves this by bisection on T_b, the
// integral by Simpson's rule (1000 intervals: its error ~1e-16 of the
// stretch for a smooth lambda). Tolerance 1e-6 relative on T_b and p: the
// mesh (a straight chain under a linear tension is exact in the cubic up to
// the element's quadrature) and Newton.
TEST(SeabedBodyTest, ChainOnAClumpWeightSharesItsWeightWithTheBed) {
  constexpr double kClump = 2000, kLen = 10, kArea = 0.01, kDensity = 7850, kEa = 5e7;
  const double w = kDensity * kArea * kG, k = 1e6;
  auto lambda = [&](double t) {
    // EA lam (lam^2 - 1) / 2 = t, by Newton from 1.
    double lam = 1;
    for (int i = 0; i < 50; ++i)
      lam -= (kEa * lam * (lam * lam - 1) / 2 - t) / (kEa * (3 * lam * lam - 1) / 2);
    return lam;
  };
  auto stretch = [&](double tb) {
    const int n = 1000;
    const double h = kLen / n;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
      const double f = lambda(tb + w * i * h) - 1;
      sum += (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2)) * f;
    }
    return sum * h / 3;
  };
  double lo = 0, hi = kClump * kG;
  for (int i = 0; i < 200; ++i) {
    const double tb = 0.5 * (lo + hi);
    ((kClump * kG - tb) / (4 * k) > stretch(tb) ? lo : hi) = tb;
  }
  const double tb = 0.5 * (lo + hi), p = (kClump * kG - tb) / (4 * k);
  const double top = kH + 0.5 + kLen;  // the chain hangs from the clump's top
  const std::string json = absl::StrFormat(R"({
    "model": "PLANAR",
    "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": %.17g, "elements": 10, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "bending": "NONE",
                "points": [{"x": 0, "y": %.17g}, {"x": 0, "y": %.17g}]}],
    "bodies": [{"name": "clump", "mass": %.17g, "inertia": {"x": 200, "y": 240, "z": 220},
                "position": {"y": %.17g},
                "seabed_contact": {"points": %s, "stiffness": %.17g}}],
    "joints": [{"type": "PIN", "a": {"cable": "chain", "s": 0}},
               {"type": "PIN", "a": {"cable": "chain", "s": %.17g},
                "b": {"body": "clump", "point": {"y": 0.5}}}],
    "seabed": {"stiffness": 1e6},
    "solver": {"analysis": "STATIC", "newton_tolerance": 1e-12}})",
                                           kLen, kDensity, kEa / kArea, kArea, top, kH + 0.5,
                                           kClump, kH, kPoints, k, kLen);
  const Scene scene = SceneFromJson(json);
  auto m = MultibodyModel::Build(scene);
  ASSERT_TRUE(m.ok()) << m.status();
  const Eigen::VectorXd q = StaticsOf(scene, &*m);
  Eigen::Vector3d slope;
  const Eigen::Vector3d bottom = m->CablePosition(q, 0, kLen, &slope);
  const double lam = slope.norm();
  const double t_fe = kEa * lam * (lam * lam - 1) / 2;
  const double p_fe = -(bottom.y() - 0.5 - kH) - 0;  // the points sit 1 m below the bottom
  std::printf("clump: T_b %.6f N (reference %.6f), sink %.9e m (reference %.9e)\n", t_fe, tb,
              p_fe, p);
  EXPECT_NEAR(t_fe, tb, 1e-6 * tb);
  EXPECT_NEAR(p_fe, p, 1e-6 * p);
}

// The contact's generalized force is minus the derivative of
// energy.contact and its matrix the force's derivative (central
// differences, step 1e-6), for a tilted spatial block partly in a sloped
// bathymetry grid; and the damping/friction tangent is the derivative of
// the damping force where the rank-one term vanishes (a block sliding with
// no normal speed: DampingTangentError with velocities along the bed only
// would still see it; checked here with damping only).
TEST(SeabedBodyTest, ForceAndMatrixAreDerivativesOfTheContactEnergy) {
  for (const char* bed : {R"("seabed": {"stiffness": 1e6})",
                          R"("seabed": {"stiffness": 1e6, "bathymetry": {"nx": 3, "ny": 2,
                              "dx": 0.7, "dy": 1, "origin_x": -0.9, "origin_y": -0.5,
                              "depths": [0.1, -0.05, 0.2, 0.0, 0.12, -0.1]}})"}) {
    const std::string json = absl::StrFormat(R"({
      "model": "SPATIAL",
      "gravity": {"y": -9.81},
      "bodies": [{"name": "block", "mass": 1000, "inertia": {"x": 100, "y": 120, "z": 110},
                  "position": {"x": 0.1, "y": 0.45, "z": 0.05},
                  "axis": {"x": 1, "y": 0.15, "z": 0.1},
                  "seabed_contact": {"points": %s, "stiffness": 1e7}}],
      %s,
      "solver": {"analysis": "STATIC"}})",
                                             kPoints, bed);
    const Scene scene = SceneFromJson(json);
    auto m = MultibodyModel::Build(scene);
    ASSERT_TRUE(m.ok()) << m.status();
    const int nq = m->coordinates();
    Eigen::VectorXd q(nq);
    m->ToFull(m->initial_z(), &q);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nq);
    ASSERT_GT(m->Energy(q, zero, 1.0).contact, 0) << "no point in the bed";
    const testing::NetForceDerivativeErrors e = testing::NetForceDerivatives(*m, 1e-6);
    std::printf("force error %.3g of %.3g, matrix error %.3g of %.3g\n", e.force, e.force_size,
                e.matrix, e.matrix_size);
    EXPECT_LT(e.force, 1e-6 * e.force_size);
    EXPECT_LT(e.matrix, 1e-5 * e.matrix_size);
  }
}

std::string Invalid(const std::string& body_extra, const std::string& scene_extra) {
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "bodies": [{"name": "b", "mass": 1, "inertia": {"x": 1, "y": 1, "z": 1} %s}]
    %s, "solver": {"analysis": "STATIC"}})",
                                           body_extra, scene_extra);
  return testing::SceneError(json);
}

// The statics' rounding floor (newton_convergence.h) for the bed's static
// friction on body contact points: the block pressed 1 mm into the bed and
// moved about half a friction_length (1e-5 m, the default) from where the
// analysis starts, where the regularised law is stiffest (mu N /
// friction_length = 5e8 N/m per point). Coordinates are known to eps |q|:
// 200 random roundings of q and q_start (each coordinate moved by
// +-eps |q_i|) must change no entry of the friction force by more than its
// floor. Before the bodies' friction had a floor it was 0 here, and the
// roundings move the force by up to 3e-7 N (measured: 0.28 and 0.31 of the
// floor). A chain on the bed, printed, not checked: its floor is built from
// the element's summed matrix (MultibodyModel::StaticFriction), which can
// cancel between points; measured 0.93 of it (3.7 with eps in place of
// kSumRounding).
TEST(SeabedBodyTest, StaticFrictionFloorBoundsWhatRoundingTheCoordinatesDoes) {
  const std::string chain = R"({
    "model": "SPATIAL", "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": 10, "elements": 8,
                "points": [{"x": 0.3, "y": -0.001, "z": 0.2}, {"x": 10.3, "y": -0.001, "z": 0.2}],
                "density": 7850, "area": 0.001, "youngs_modulus": 1e10, "bending": "NONE"}],
    "seabed": {"stiffness": 1e6, "friction_axial": 0.5, "friction_transverse": 1.0},
    "solver": {"analysis": "STATIC"}})";
  const std::vector<std::string> scenes = {
      Block("PLANAR", -1e-3, R"(, "friction": 0.5)", R"("solver": {"analysis": "STATIC"})"),
      Block("SPATIAL", -1e-3, R"(, "friction": 0.5)", R"("solver": {"analysis": "STATIC"})"),
      chain};
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (size_t c = 0; c < scenes.size(); ++c) {
    const Scene scene = SceneFromJson(scenes[c]);
    auto m = MultibodyModel::Build(scene);
    ASSERT_TRUE(m.ok()) << m.status();
    ASSERT_TRUE(m->has_static_friction()) << c;
    const int n = m->dofs(), nq = m->coordinates();
    Eigen::VectorXd z = m->initial_z(), q0(nq), q(nq);
    m->ToFull(z, &q0);
    for (int i = 0; i < n; ++i) z(i) += 0.5e-5 * unit(rng);
    m->ToFull(z, &q);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(n), floor = Eigen::VectorXd::Zero(n);
    m->StaticFriction(q, q0, &f, nullptr, 1.0, &floor);
    ASSERT_GT(f.lpNorm<Eigen::Infinity>(), 0) << c;
    double worst = 0, largest = 0;  // of |change| / floor, and of |change|
    for (int trial = 0; trial < 200; ++trial) {
      Eigen::VectorXd qr = q, q0r = q0, fr = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < nq; ++i) {
        qr(i) += (unit(rng) < 0 ? -kEps : kEps) * std::abs(q(i));
        q0r(i) += (unit(rng) < 0 ? -kEps : kEps) * std::abs(q0(i));
      }
      m->StaticFriction(qr, q0r, &fr, nullptr, 1.0);
      for (int i = 0; i < n; ++i) {
        const double change = std::abs(fr(i) - f(i));
        largest = std::max(largest, change);
        if (change > 0) worst = std::max(worst, floor(i) > 0 ? change / floor(i) : HUGE_VAL);
      }
    }
    std::printf("scene %zu: largest change %.3g N, at most %.3g of its floor\n", c, largest,
                worst);
    EXPECT_GT(largest, 0) << c;  // the roundings do move the force
    if (c < 2) {
      EXPECT_LE(worst, 1.0) << c;
    }
  }
}

TEST(SeabedBodyTest, BadContactFieldsAreNamed) {
  const std::string bed = R"(, "seabed": {"stiffness": 1e5})";
  EXPECT_EQ(Invalid(R"(, "seabed_contact": {"points": [{"y": -1}], "stiffness": 1e5})", bed),
            "ok");
  EXPECT_EQ(Invalid(R"(, "seabed_contact": {"points": [{"y": -1}], "stiffness": 1e5})", ""),
            "bodies[0].seabed_contact: needs a seabed");
  EXPECT_EQ(Invalid(R"(, "seabed_contact": {"stiffness": 1e5})", bed),
            "bodies[0].seabed_contact.points: at least one point is required");
  EXPECT_EQ(Invalid(R"(, "seabed_contact": {"points": [{"y": -1}]})", bed),
            "bodies[0].seabed_contact.stiffness: must be > 0 (got 0)");
  EXPECT_EQ(
      Invalid(R"(, "seabed_contact": {"points": [{"y": -1}], "stiffness": 1, "damping": -1})",
              bed),
      "bodies[0].seabed_contact.damping: must be >= 0 (got -1)");
  EXPECT_EQ(
      Invalid(R"(, "seabed_contact": {"points": [{"y": -1}], "stiffness": 1, "friction": -2})",
              bed),
      "bodies[0].seabed_contact.friction: must be >= 0 (got -2)");
  EXPECT_EQ(Invalid("", R"(, "seabed": {"stiffness": 1e5, "friction_length": -1})"),
            "seabed.friction_length: must be > 0 (got -1)");
}

}  // namespace
}  // namespace cablesim
