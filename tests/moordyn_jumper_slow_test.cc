// Validation against the field's public reference: Lowe and Langley's
// flexible jumper (OMAE 2006), as MoorDyn's tests check it
// (tests/lowe_and_langley_2006.cpp in MoorDyn's repository; MoorDyn is
// BSD-3-Clause; only numbers are carried here: the deck's in the deck
// below, written for this test, and the digitised top-tension series in
// tests/data/lowe_langley_2006/, whose README says where they come from).
//
// The jumper: 170 m of 0.396 m pipe, 165 kg/m, EA 5e8 N, EI 120.8 kN m^2,
// C_d 1, C_a 1, C_a,ax 0, from an anchor at (-100, 0, -55) m to a top at
// (0, 0, -5) m in 100 m of water. Read by the MoorDyn reader
// (convert/moordyn_deck.h), which sets the axial added mass (CaAx) and the
// free surface as MoorDyn's lines have them.
//
//  - Statics: the top's reaction (11.40, 0, 45.71) kN and the anchor's
//    (-11.40, 0, 24.04) kN, each component within 0.2 kN (MoorDyn's
//    tolerance).
//  - Dynamics: the top moved by 10 sin(2 pi t / 27) m along x, y or z
//    (cases 1-3; ramped in over one period), or held in regular waves of
//    amplitude 5 m and period 10 s along 0, 45 and 90 degrees (cases 4-6;
//    the series starting 20 s after the waves start): the top tension's
//    every sample within 1 kN of the paper's (MoorDyn's tolerance).
//    Measured errors, and what they were without the axial added mass and
//    the free surface (1.5 to 12 kN): docs/moordyn-files.md, "Lowe and
//    Langley's flexible jumper". Case 5 passes by 7 N (0.993 kN), and its
//    error does not fall with the step (0.998 kN at h = 0.005 s).
//
// cablesim's top tension is the magnitude of the top support's reaction
// (output.reactions), MoorDyn's the force on its top node.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "convert/moordyn_deck.h"
#include "convert/scene_from_proto.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

// The jumper, in MoorDyn's v2 format (the numbers of MoorDyn's
// tests/Mooring/lowe_and_langley_2006/line.txt).
constexpr char kDeck[] = R"(MoorDyn v2 input file: Lowe and Langley's flexible jumper
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
jumper     0.396    165.0      500.0e6    -0.5        120.8e3    1.0    1.0    0.0     0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass    Volume      CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)    (m^3)       (m^2)  (-)
1     Fixed     -100    0       -55     0       0           0      0
2     Coupled   0       0       -5      0       0           0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1      jumper    1        2         170       68      -
---------------------- OPTIONS -----------------------------------------
3.0e6         kBot          bottom stiffness (Pa/m)
3.0e5         cBot          bottom damping (Pa-s/m)
100           WtrDpth       water depth (m)
1000.0        WtrDnsty      water density (kg/m^3)
9.807         g             gravity (m/s^2)
------------------------- need this line --------------------------------------
)";

v1::Scene JumperProto() {
  absl::StatusOr<v1::Scene> proto = SceneFromMoorDyn(kDeck, "jumper.dat");
  EXPECT_TRUE(proto.ok()) << proto.status();
  if (!proto.ok()) return v1::Scene();
  proto->mutable_output()->set_reactions(true);
  return *proto;
}

// The index of the joint named `name`, -1 if none.
int JointIndex(const v1::Scene& proto, const std::string& name) {
  for (int i = 0; i < proto.joints_size(); ++i)
    if (proto.joints(i).name() == name) return i;
  return -1;
}

TEST(MoorDynJumperSlowTest, StaticTopAndAnchorForcesWithinTwoTenthsOfAKilonewton) {
  const v1::Scene proto = JumperProto();
  const int top = JointIndex(proto, "point2"), anchor = JointIndex(proto, "point1");
  ASSERT_GE(top, 0);
  ASSERT_GE(anchor, 0);
  absl::StatusOr<Scene> scene = SceneFromProto(proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  testing::CollectingSink sink;
  testing::RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.reactions.size(), 2u);
  const Eigen::Vector3d t = f.reactions[top].force / 1e3, a = f.reactions[anchor].force / 1e3;
  std::printf("static top (%.3f, %.3f, %.3f) kN (paper 11.40, 0, 45.71), anchor (%.3f, %.3f, "
              "%.3f) kN (paper -11.40, 0, 24.04)\n",
              t.x(), t.y(), t.z(), a.x(), a.y(), a.z());
  // MoorDyn's tolerance: 0.2 kN per component.
  const Eigen::Vector3d top_ref(11.40, 0, 45.71), anchor_ref(-11.40, 0, 24.04);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(t(i), top_ref(i), 0.2) << "top component " << i;
    EXPECT_NEAR(a(i), anchor_ref(i), 0.2) << "anchor component " << i;
  }
}

// The paper's series: (time since the end of the ramp [s], tension [kN]).
std::vector<std::pair<double, double>> Reference(int c) {
  std::vector<std::pair<double, double>> out;
  std::ifstream in(absl::StrFormat("%s/tests/data/lowe_langley_2006/case%d.csv",
                                   CABLESIM_SOURCE_DIR, c));
  std::string line;
  while (std::getline(in, line)) {
    double t = 0, v = 0;
    char comma = 0;
    std::istringstream s(line);
    if (s >> t >> comma >> v) out.push_back({t, v});
  }
  EXPECT_GT(out.size(), 200u) << "case " << c;
  return out;
}

struct Errors {
  double max_kn = NAN, rms_kn = NAN;
  int samples = 0, outside = 0;
};

// Runs case c (1..6) with time step h [s] and compares the top tension
// with the paper's series.
Errors RunCase(int c, double h) {
  v1::Scene proto = JumperProto();
  const int top = JointIndex(proto, "point2");
  EXPECT_GE(top, 0);
  if (top < 0) return {};
  double lead_s;  // the time before the series starts [s]
  double length_s;
  if (c <= 3) {
    // The top moves by A F(t) sin(omega t) along axis c - 1, F the quintic
    // ramp 6 f^5 - 15 f^4 + 10 f^3 of f = t / T over the first period:
    // the harmonic, plus a table of (F - 1) A sin(omega t) at 0.01 s
    // knots over [0, T] (zero after it; the table's error, A omega^2 (0.01
    // s)^2 / 8 = 7e-5 m, is within the ramp).
    const double amplitude = 10, period = 27, omega = 2 * kPi / period;
    v1::Joint* j = proto.mutable_joints(top);
    j->set_coupled(false);
    v1::TimeFunction* f = c == 1   ? j->mutable_motion()->mutable_x()
                          : c == 2 ? j->mutable_motion()->mutable_y()
                                   : j->mutable_motion()->mutable_z();
    f->mutable_harmonic()->set_amplitude(amplitude);
    f->mutable_harmonic()->set_frequency(1 / period);
    v1::TimeFunction* ramp = f->add_sum();
    const int knots = 2700;
    for (int k = 0; k <= knots; ++k) {
      const double t = period * k / knots, x = t / period;
      const double ramp_factor = x * x * x * (6 * x * x - 15 * x + 10);
      ramp->mutable_table()->add_times(t);
      ramp->mutable_table()->add_values(k == knots ? 0.0
                                                   : (ramp_factor - 1) * amplitude *
                                                         std::sin(omega * t));
    }
    lead_s = period;
    length_s = 80;
  } else {
    // Regular waves from t = 0 (no ramp, as MoorDyn's test starts them),
    // amplitude 5 m, period 10 s, direction (c - 4) 45 degrees.
    const double phases_deg[] = {230, 165, 0};
    const double direction = (c - 4) * 0.25 * kPi;
    v1::Waves::Regular* w = proto.mutable_fluid()->mutable_waves()->add_regular();
    w->set_height(10);
    w->set_period(10);
    w->mutable_direction()->set_x(std::cos(direction));
    w->mutable_direction()->set_y(std::sin(direction));
    w->set_phase(phases_deg[c - 4] * kPi / 180);
    lead_s = 20;
    length_s = 30;
  }
  v1::Solver* s = proto.mutable_solver();
  s->set_analysis(v1::DYNAMIC);
  s->set_initial_state(v1::Solver::STATIC);
  s->set_duration(lead_s + length_s);
  s->set_step(h);
  s->set_output_interval(0.1);
  absl::StatusOr<Scene> scene = SceneFromProto(proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  if (!scene.ok()) return {};
  testing::CollectingSink sink;
  const RunSummary summary = testing::RunOk(*scene, &sink);
  const std::vector<std::pair<double, double>> ref = Reference(c);
  Errors e;
  double sum2 = 0, max = 0;
  size_t frame = 0;
  for (const auto& [t_ref, tension] : ref) {
    const double t = lead_s + t_ref;
    while (frame + 1 < sink.frames().size() &&
           std::abs(sink.frames()[frame + 1].t - t) <= std::abs(sink.frames()[frame].t - t))
      ++frame;
    if (frame >= sink.frames().size() || std::abs(sink.frames()[frame].t - t) > 1e-6) continue;
    const double got = sink.frames()[frame].reactions[top].force.norm() / 1e3;
    const double d = std::abs(got - tension);
    max = std::max(max, d);
    sum2 += d * d;
    ++e.samples;
    if (d > 1.0) ++e.outside;
  }
  if (e.samples > 0) {
    e.max_kn = max;
    e.rms_kn = std::sqrt(sum2 / e.samples);
  }
  std::printf("case %d, h = %g s: top tension max error %.3f kN, rms %.3f kN, %d of %d samples "
              "beyond 1 kN (%lld steps, %.1f s)\n",
              c, h, e.max_kn, e.rms_kn, e.outside, e.samples,
              static_cast<long long>(summary.steps), summary.wall_seconds);
  EXPECT_EQ(e.samples, static_cast<int>(ref.size()));
  return e;
}

// MoorDyn's tolerance: every sample within 1 kN.
constexpr double kTolerance = 1.0;
constexpr double kStep = 0.01;

TEST(MoorDynJumperSlowTest, Case1SurgeWithinOneKilonewton) {
  EXPECT_LT(RunCase(1, kStep).max_kn, kTolerance);
}
TEST(MoorDynJumperSlowTest, Case2SwayWithinOneKilonewton) {
  EXPECT_LT(RunCase(2, kStep).max_kn, kTolerance);
}
TEST(MoorDynJumperSlowTest, Case3HeaveWithinOneKilonewton) {
  EXPECT_LT(RunCase(3, kStep).max_kn, kTolerance);
}
TEST(MoorDynJumperSlowTest, Case4WavesAlongTheJumperWithinOneKilonewton) {
  EXPECT_LT(RunCase(4, kStep).max_kn, kTolerance);
}
TEST(MoorDynJumperSlowTest, Case5WavesAt45DegreesWithinOneKilonewton) {
  EXPECT_LT(RunCase(5, kStep).max_kn, kTolerance);
}
TEST(MoorDynJumperSlowTest, Case6WavesAcrossTheJumperWithinOneKilonewton) {
  EXPECT_LT(RunCase(6, kStep).max_kn, kTolerance);
}

// The deck's points are not an equilibrium: the reader lays the 170 m
// line through a sag point, and the ANCF nodes at the kink start with
// 1.06e7 J of strain energy. A DYNAMIC run from them as given fails on its
// energy guard within the first steps; the failure says how to start from
// equilibrium, as MoorDyn starts its decks, and that start runs.
TEST(MoorDynJumperSlowTest, AStartFromTheDecksPointsSaysHowToStartFromEquilibrium) {
  v1::Scene proto = JumperProto();
  v1::Solver* s = proto.mutable_solver();
  s->set_analysis(v1::DYNAMIC);
  s->set_duration(0.2);
  s->set_step(0.01);
  absl::StatusOr<Scene> as_given = SceneFromProto(proto);
  ASSERT_TRUE(as_given.ok()) << as_given.status();
  testing::CollectingSink sink;
  const absl::StatusOr<RunSummary> failed = RunScene(*as_given, &sink);
  ASSERT_TRUE(failed.ok()) << failed.status();
  EXPECT_EQ(failed->status, "failed");
  EXPECT_NE(failed->error.find("solver.initial_state: STATIC starts from one"),
            std::string::npos)
      << failed->error;
  s->set_initial_state(v1::Solver::STATIC);
  absl::StatusOr<Scene> from_rest = SceneFromProto(proto);
  ASSERT_TRUE(from_rest.ok()) << from_rest.status();
  testing::CollectingSink rest_sink;
  testing::RunOk(*from_rest, &rest_sink);
}

}  // namespace
}  // namespace cablesim
