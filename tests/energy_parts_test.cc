// The energy per part (EnergyParts, engine/run/simulation.h): the parts sum to
// the totals, and single parts against closed forms (free fall, a cable at
// rest, a point load's potential).

#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "engine/output/frame_columns.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// Two cables (one jointed to the other), a body welded to the end of the
// second, a point load and a torque on the body: every kind of part, in
// the spatial model (the body is spun about x). Backward Euler, 0.2 s.
constexpr char kEveryPart[] = R"({
  "gravity": {"y": -9.81},
  "cables": [{"name": "upper", "length": 0.5, "elements": 5, "direction": {"x": 1},
              "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01},
             {"name": "lower", "length": 0.5, "elements": 4, "start": {"x": 0.5},
              "direction": {"x": 1}, "density": 2000, "youngs_modulus": 2e7,
              "diameter": 0.008}],
  "bodies": [{"name": "weight", "cylinder": {"diameter": 0.04, "height": 0.1},
              "density": 1000, "position": {"x": 1.05}, "axis": {"x": 1}}],
  "joints": [{"type": "PIN", "a": {"cable": "upper", "s": 0}},
             {"type": "PIN", "a": {"cable": "upper", "s": 0.5},
              "b": {"cable": "lower", "s": 0}},
             {"type": "FIXED", "a": {"cable": "lower", "s": 0.5},
              "b": {"body": "weight", "point": {"x": -0.05}}}],
  "loads": [{"at": {"cable": "upper", "s": 0.25}, "force": {"y": -2, "z": 1}},
            {"at": {"body": "weight"}, "force": {"x": 1}, "torque": {"x": 0.01}}],
  "solver": {"duration": 0.2, "step": 1e-3, "output_interval": 0.01,
             "integrator": "IMPLICIT_EULER"}})";

// Every frame: sum over the parts of kinetic, axial and bending is the
// total's, and the parts' gravity plus the loads' potential is the total
// potential. The two sides add the same terms in a different order (the
// potential: per element and body against one dot product over every
// coordinate), so they agree to a few eps times the sum of the terms'
// magnitudes: 1e-12 of it is 4000 times that bound for these ~100 terms,
// and far below any part (a missing element here holds > 1e-6 J).
TEST(EnergyPartsTest, PartsSumToTheTotals) {
  CollectingSink sink;
  RunOk(SceneFromJson(kEveryPart), &sink);
  ASSERT_EQ(sink.info().model, "spatial");
  ASSERT_EQ(sink.info().cable_names, (std::vector<std::string>{"upper", "lower"}));
  ASSERT_EQ(sink.info().body_names, (std::vector<std::string>{"weight"}));
  ASSERT_EQ(sink.frames().size(), 21u);
  double largest_loads = 0, largest_body_kinetic = 0;
  for (const Frame& f : sink.frames()) {
    const EnergyParts& p = f.energy_parts;
    ASSERT_EQ(p.cables.size(), 2u);
    ASSERT_EQ(p.bodies.size(), 1u);
    double kinetic = 0, gravity = 0, axial = 0, bending = 0, magnitude = 0;
    for (const PartEnergy& part : p.cables) {
      kinetic += part.kinetic;
      gravity += part.gravity;
      axial += part.axial;
      bending += part.bending;
      magnitude += part.kinetic + std::abs(part.gravity) + part.axial + part.bending;
    }
    const PartEnergy& body = p.bodies[0];
    EXPECT_EQ(body.axial, 0);
    EXPECT_EQ(body.bending, 0);
    kinetic += body.kinetic;
    gravity += body.gravity;
    magnitude += body.kinetic + std::abs(body.gravity) + std::abs(p.loads);
    const double tol = 1e-12 * magnitude;
    EXPECT_NEAR(kinetic, f.energy.kinetic, tol) << "t = " << f.t;
    EXPECT_NEAR(gravity + p.loads, f.energy.potential, tol) << "t = " << f.t;
    EXPECT_NEAR(axial, f.energy.axial, tol) << "t = " << f.t;
    EXPECT_NEAR(bending, f.energy.bending, tol) << "t = " << f.t;
    largest_loads = std::max(largest_loads, std::abs(p.loads));
    largest_body_kinetic = std::max(largest_body_kinetic, body.kinetic);
  }
  // The scene exercises what it should: the loads and the body move.
  EXPECT_GT(largest_loads, 1e-3);
  EXPECT_GT(largest_body_kinetic, 1e-4);
}

// A body and a cable, unattached, falling from rest under g: each moves
// rigidly with v = g t, so its kinetic energy is m g^2 t^2 / 2 and its
// gravity potential -m g . r = m g (y0 - g t^2 / 2) (y up). The steppers
// are exact for a constant acceleration (HHT's Newmark update integrates
// it exactly; the cable stays unstrained), so the parts match the closed
// form to rounding and the Newton tolerance: 1e-9 relative.
TEST(EnergyPartsTest, FreeFallMatchesTheClosedForm) {
  constexpr double kG = 9.81;
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "rope", "length": 1.0, "elements": 4, "start": {"y": 2},
                "direction": {"x": 1}, "density": 1000, "youngs_modulus": 1e7,
                "diameter": 0.01}],
    "bodies": [{"name": "ball", "mass": 3, "inertia": {"x": 0.01, "y": 0.01, "z": 0.01},
                "position": {"x": 3, "y": 1}}],
    "solver": {"duration": 0.5, "step": 1e-3, "output_interval": 0.05}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(sink.frames().size(), 11u);
  const double body_mass = 3, cable_mass = 1000 * std::numbers::pi * 0.01 * 0.01 / 4 * 1.0;
  for (const Frame& f : sink.frames()) {
    const double t = f.t, fall = 0.5 * kG * t * t;
    const PartEnergy& ball = f.energy_parts.bodies[0];
    const PartEnergy& rope = f.energy_parts.cables[0];
    const double ball_kinetic = 0.5 * body_mass * kG * kG * t * t;
    const double rope_kinetic = 0.5 * cable_mass * kG * kG * t * t;
    EXPECT_NEAR(ball.kinetic, ball_kinetic, 1e-9 * (1 + ball_kinetic)) << "t = " << t;
    EXPECT_NEAR(ball.gravity, body_mass * kG * (1 - fall), 1e-9 * body_mass * kG) << "t = " << t;
    EXPECT_NEAR(rope.kinetic, rope_kinetic, 1e-9 * (1 + rope_kinetic)) << "t = " << t;
    // The rope's centre of mass starts at y = 2.
    EXPECT_NEAR(rope.gravity, cable_mass * kG * (2 - fall), 1e-9 * cable_mass * kG)
        << "t = " << t;
    EXPECT_NEAR(rope.axial, 0, 1e-12 * rope_kinetic + 1e-15) << "t = " << t;
    EXPECT_NEAR(rope.bending, 0, 1e-12 * rope_kinetic + 1e-15) << "t = " << t;
    EXPECT_EQ(f.energy_parts.loads, 0);
  }
  // At the end: 0.5 s of fall.
  EXPECT_NEAR(sink.frames().back().energy_parts.bodies[0].kinetic,
              0.5 * body_mass * kG * kG * 0.25, 1e-9);
}

// A straight unstretched cable along x, pinned, no gravity and no load:
// it stays at rest and holds no energy but rounding's. Bounds: the strain
// energy that coordinates known to 16 eps (1 + |q0|) can hold (README,
// "Energy checks and their floor"), sum over elements of
// (EA + EI / l^2) l d^2 with d = 16 eps (1 + |q0|) / l, and the kinetic
// energy of that displacement over a step, m (16 eps (1 + |q0|) / h)^2 / 2.
// A cable that moved or strained at all would exceed them by far.
TEST(EnergyPartsTest, CableAtRestHoldsNoEnergy) {
  const std::string json = R"({
    "cables": [{"name": "c", "length": 2.0, "elements": 8, "direction": {"x": 1},
                "density": 1000, "youngs_modulus": 1e9, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "solver": {"duration": 0.05, "step": 1e-3, "output_interval": 0.01}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(sink.frames().size(), 6u);
  const double area = std::numbers::pi * 0.01 * 0.01 / 4, second_moment = std::numbers::pi * std::pow(0.01, 4) / 64;
  const double l = 0.25, q0 = 2.0, eps = std::numeric_limits<double>::epsilon();
  const double d = 16 * eps * (1 + q0);
  const double strain_floor = 8 * (1e9 * area + 1e9 * second_moment / (l * l)) * l * (d / l) *
                              (d / l);
  const double kinetic_floor = 0.5 * 1000 * area * 2.0 * (d / 1e-3) * (d / 1e-3);
  for (const Frame& f : sink.frames()) {
    ASSERT_EQ(f.energy_parts.cables.size(), 1u);
    const PartEnergy& c = f.energy_parts.cables[0];
    EXPECT_LE(std::abs(c.kinetic), kinetic_floor) << "t = " << f.t;
    EXPECT_EQ(c.gravity, 0) << "t = " << f.t;
    EXPECT_LE(std::abs(c.axial), strain_floor) << "t = " << f.t;
    EXPECT_LE(std::abs(c.bending), strain_floor) << "t = " << f.t;
  }
  // The first frame is the scene as laid out, at rest.
  EXPECT_EQ(sink.frames()[0].energy_parts.cables[0].kinetic, 0);
}

// STATIC: the loads' potential is -alpha F . r at the point loaded (alpha
// the load factor, r from the probe there, an independent linear form of
// the coordinates): to rounding, 1e-12 of |F| |r|.
TEST(EnergyPartsTest, PointLoadPotentialIsMinusForceDotPosition) {
  const std::string json = R"({
    "cables": [{"name": "rod", "length": 1.0, "elements": 8, "direction": {"x": 1},
                "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "FIXED", "a": {"cable": "rod", "s": 0}}],
    "loads": [{"at": {"cable": "rod", "s": 1.0}, "force": {"x": 20, "y": -100}}],
    "probes": [{"name": "tip", "cable": "rod", "s": 1.0}],
    "solver": {"analysis": "STATIC", "load_steps": 4}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(sink.frames().size(), 4u);
  const Eigen::Vector3d force(20, -100, 0);
  for (const Frame& f : sink.frames()) {
    const Eigen::Vector3d& r = f.probes[0].position_m;
    EXPECT_NEAR(f.energy_parts.loads, -f.t * force.dot(r), 1e-12 * force.norm() * r.norm())
        << "load factor " << f.t;
    // No gravity: the rod's part holds the strain, and the loads the rest.
    EXPECT_EQ(f.energy_parts.cables[0].gravity, 0);
    EXPECT_GT(f.energy_parts.cables[0].bending, 0);
  }
}

// MODAL: the shapes carry no energy, but every frame has its parts (the CSV
// and the service write a column per part in every row).
TEST(EnergyPartsTest, ModalFramesHaveEveryPart) {
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": 1.0, "elements": 6, "direction": {"y": -1},
                "density": 1000, "youngs_modulus": 1e8, "diameter": 0.01}],
    "bodies": [{"name": "b", "mass": 1, "inertia": {"z": 0.001}, "position": {"y": -1}}],
    "joints": [{"type": "PIN", "a": {"cable": "chain", "s": 0}},
               {"type": "PIN", "a": {"cable": "chain", "s": 1.0}, "b": {"body": "b"}}],
    "probes": [{"name": "b", "body": "b"}],
    "solver": {"analysis": "MODAL", "modes": 3}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  ASSERT_EQ(sink.frames().size(), 4u);
  for (const Frame& f : sink.frames()) {
    EXPECT_EQ(f.energy_parts.cables.size(), 1u);
    EXPECT_EQ(f.energy_parts.bodies.size(), 1u);
  }
  // The equilibrium frame: the body's gravity potential is -m g . r = 9.81 y
  // (1 kg; the chain stretched a little below y = -1), to rounding.
  const Frame& rest = sink.frames()[0];
  EXPECT_NEAR(rest.energy_parts.bodies[0].gravity, 9.81 * rest.probes[0].position_m.y(), 1e-12);
  EXPECT_LT(rest.probes[0].position_m.y(), -1);
}

// FrameReader finds the columns by name: rows with the columns reordered,
// or without the parts (written before they existed), read back.
TEST(EnergyPartsTest, FrameReaderFindsColumnsByName) {
  ModelInfo info;
  info.probe_names = {"p"};
  info.cable_names = {"c"};
  info.body_names = {"b"};
  std::vector<std::string> columns = FrameColumns(info);
  ASSERT_EQ(static_cast<int64_t>(columns.size()), FrameRowSize(1, 1, 1));
  std::vector<double> row(columns.size());
  for (size_t i = 0; i < row.size(); ++i) row[i] = static_cast<double>(i);
  // Reversed: every value moves.
  std::vector<std::string> reversed(columns.rbegin(), columns.rend());
  std::vector<double> reversed_row(row.rbegin(), row.rend());
  Frame frame;
  FrameReader(info, reversed).Read(reversed_row, &frame);
  std::vector<double> back;
  ForEachFrameValue(frame, [&back](double v) { back.push_back(v); });
  EXPECT_EQ(back, row);
  // The columns before the parts only: the parts read as 0.
  columns.resize(1 + kValuesPerProbe + kTotalValues);
  row.resize(columns.size());
  FrameReader(info, columns).Read(row, &frame);
  EXPECT_EQ(frame.energy.total, 14);
  EXPECT_EQ(frame.constraint_violation, 15);
  EXPECT_EQ(frame.energy_parts.cables[0].kinetic, 0);
  EXPECT_EQ(frame.energy_parts.bodies[0].gravity, 0);
  EXPECT_EQ(frame.energy_parts.loads, 0);
}

}  // namespace
}  // namespace cablesim
