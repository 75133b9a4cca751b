// MoorDyn decks' BODIES, ROD TYPES, RODS and SeafloorFile
// (convert/moordyn_deck.cc, docs/moordyn-files.md "Bodies and rods" and
// "Seafloor file"): each translation against a hand calculation, statics
// of floating and hanging rods and bodies against Archimedes, the refusals
// naming the deck's line and field, and the CLI's import and run. The
// decks are written here.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "client/cli.h"
#include "tests/cli_test_util.h"
#include "convert/moordyn_deck.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "tests/test_util.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81, kRho = 1025;

using testing::CollectingSink;
using testing::RunOk;

// The deck's text with its sections: a header, then `body`, then options
// (g 9.81, rho 1025, depth 200).
std::string Deck(const std::string& body) {
  return absl::StrCat(R"(--------------------- MoorDyn Input File ------------------------------------
A deck written for cablesim's tests
)",
                      body, R"(---------------------- OPTIONS -----------------------------------------
9.81          g             gravity
1025          WtrDnsty      water density (kg/m^3)
200           WtrDpth       water depth (m)
------------------------- need this line --------------------------------------
)");
}

v1::Scene Read(const std::string& text, MoorDynFileReader files = nullptr) {
  absl::StatusOr<v1::Scene> scene = SceneFromMoorDyn(text, "test.dat", std::move(files));
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : v1::Scene{};
}

std::string Refusal(const std::string& text, MoorDynFileReader files = nullptr) {
  absl::StatusOr<v1::Scene> scene = SceneFromMoorDyn(text, "bad.dat", std::move(files));
  EXPECT_FALSE(scene.ok());
  if (scene.ok()) return "";
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(scene.status().message());
}

const v1::Body& BodyNamed(const v1::Scene& s, const std::string& name) {
  for (const v1::Body& b : s.bodies())
    if (b.name() == name) return b;
  ADD_FAILURE() << "no body " << name;
  return s.bodies(0);
}

// The scene's statics with a probe on `body`'s centre; the last frame.
Frame Statics(v1::Scene proto, const std::string& body, CollectingSink* sink) {
  v1::Probe* p = proto.add_probes();
  p->set_name("centre");
  p->set_body(body);
  const absl::StatusOr<Scene> scene = SceneFromProto(proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  if (!scene.ok()) return Frame{};
  RunOk(*scene, sink);
  EXPECT_FALSE(sink->frames().empty());
  if (sink->frames().empty()) return Frame{};
  // The probe "centre" first (the deck's own probes after it).
  Frame last = sink->frames().back();
  const int k = testing::ProbeIndex(sink->info(), "centre");
  EXPECT_GE(k, 0);
  if (k > 0) std::swap(last.probes[0], last.probes[k]);
  return last;
}

// A free vertical rod (d 1 m, 10 m long, 400 kg/m) placed with its centre
// at -1 m: it floats at the draft s where its mass equals the displaced
// water's, w L = rho (pi d^2 / 4) s (Archimedes), so its centre settles at
// L / 2 - s. A deck of a rod alone (no line types).
constexpr char kFloatingRod[] = R"(---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
spar          1.0      400       0.8    1.0     0.6      0.7
---------------------- RODS ----------------------------------------
ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs
(#)  (name)    (#/key)    (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
1    spar      Free       3     0     -6    3     0     4    5         p
)";

TEST(MoorDynBodiesTest, FreeVerticalRodFloatsAtItsDraft) {
  const v1::Scene s = Read(Deck(kFloatingRod));
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& rod = s.bodies(0);
  const double area = kPi / 4, length = 10, mass = 400 * length;
  EXPECT_EQ(rod.name(), "rod1");
  EXPECT_DOUBLE_EQ(rod.mass(), mass);
  EXPECT_DOUBLE_EQ(rod.position().z(), -1);
  EXPECT_DOUBLE_EQ(rod.axis().z(), 1);
  // A solid cylinder: m r^2 / 2 about its axis, m (3 r^2 + L^2) / 12 across.
  EXPECT_DOUBLE_EQ(rod.inertia().x(), mass * 0.25 / 2);
  EXPECT_DOUBLE_EQ(rod.inertia().y(), mass * (3 * 0.25 + 100) / 12);
  const v1::BodyHydrodynamics& h = rod.hydrodynamics();
  EXPECT_DOUBLE_EQ(h.diameter(), 1);
  EXPECT_DOUBLE_EQ(h.height(), length);
  EXPECT_DOUBLE_EQ(h.drag_coefficient(), 0.8);
  EXPECT_DOUBLE_EQ(h.added_mass(), 1.0);
  // One end (A) under water where it is placed: CdEnd on the end area;
  // CaEnd on that end's (2/3) pi r^3 over the submerged volume (6 m).
  EXPECT_DOUBLE_EQ(h.heave_drag_coefficient(), 0.6);
  EXPECT_NEAR(h.heave_added_mass(), 0.7 * (2.0 / 3 * kPi * 0.125) / (area * 6), 1e-15);

  CollectingSink sink;
  const Frame last = Statics(s, "rod1", &sink);
  ASSERT_EQ(last.probes.size(), 1u);
  const double draft = mass / (kRho * area);
  const double z = last.probes[0].position_m.z();
  std::printf("rod centre %.12g m, Archimedes %.12g m (draft %.9g m)\n", z, length / 2 - draft,
              draft);
  // Buoyancy is linear in the height while the rod pierces the surface:
  // Newton lands on the balance to its tolerance (1e-9 of the length).
  EXPECT_NEAR(z, length / 2 - draft, 1e-9 * length);
  EXPECT_NEAR(last.probes[0].position_m.x(), 3, 1e-9);
}

// MoorDyn's rod_tests/AddedMass.txt: a free horizontal rod (d 0.5 m, 2 m
// long, 100 kg/m) placed 10 m down, lighter than the water it displaces,
// rises to the surface. Its buoyancy is the vertical cylinder's of the same
// length (BodyFluidLoad), so it floats where w L = rho (pi d^2 / 4) s, its
// centre at L / 2 - s, and nothing moves it across: x and y stay where the
// deck put them. At that draft the buoyancy cancels the weight in the
// same entries, and Newton measured its residual against that rounding
// (relative residual 1 after 500 iterations at load factor 0.7) until the
// terms' own size set the scale (MultibodyModel::NetForce).
TEST(MoorDynBodiesTest, FreeHorizontalRodRisesToItsDraftWhereItIs) {
  // The deck's own rows and options (MoorDyn's default g, 9.80665).
  const v1::Scene s = Read(R"(--------------------- MoorDyn Input File ------------------------------------
Put a buoyant rod with no drag but added mass 10 meters under water.
---------------------- ROD TYPES ------------------------------------
TypeName   Diam   Mass/m    Cd     Ca    CdEnd      CaEnd
(name)    (m)    (kg/m)    (-)    (-)   (-)        (-)
floatRod   0.5  100.0      0.0    1.0    0.0       0.0
---------------------- RODS ----------------------------------------
ID     RodType   Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs   RodOutputs
(#)    (name)    (#/key)     (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
1      floatRod  free        0     -1    -10   0   1.0   -10    4       -
-------------------------- SOLVER    OPTIONS-----------------------------------
3.0e6     kb           - bottom stiffness
3.0e5     cb           - bottom damping
16.0      WtrDpth      - water depth
0         TmaxIC       - max time for ic gen (s)
------------------------- need this line --------------------------------------
)");
  ASSERT_EQ(s.bodies_size(), 1);
  CollectingSink sink;
  const Frame last = Statics(s, "rod1", &sink);
  ASSERT_EQ(last.probes.size(), 1u);
  const double length = 2, mass = 100 * length, area = kPi * 0.25 / 4;
  const double expected = length / 2 - mass / (kRho * area);
  const Eigen::Vector3d r = last.probes[0].position_m;
  std::printf("rod centre (%.3g, %.3g, %.12g) m, Archimedes z %.12g m\n", r.x(), r.y(), r.z(),
              expected);
  // Buoyancy is linear in the height while the rod pierces the surface:
  // Newton lands on the balance to its tolerance (1e-9 of the length).
  EXPECT_NEAR(r.z(), expected, 1e-9 * length);
  // Nothing acts across: the centre stays at x = y = 0 exactly.
  EXPECT_EQ(r.x(), 0);
  EXPECT_EQ(r.y(), 0);
}

// MoorDyn's seafloor.txt without its seafloor: a 10 kg point on a
// neutrally buoyant line (the water's density, EA 1e9 N, 32 m) from a
// fixed point, placed 29.7 m away and 10 m to the side. The line is laid
// with a corner (a slack chord), stretched 0.1 % (a tension of 1e6 N at
// the layout), and must swing under the point to relax; at rest the point
// hangs straight below the fixed point, the line's tension its weight m g
// all along, so at z = -L (1 + m g / EA). The first load increment took
// 748 Newton iterations (StaticSolver::kLayoutIterations), and failed
// after 500 at each of its 12 bisections. Tolerances: the axial position
// to 1e-9 m (the line's axial stiffness EA / L = 3e7 N/m against the
// solve's residual), across to 1e-6 m (the pendulum's m g / L = 3 N/m).
TEST(MoorDynBodiesTest, PointOnANeutrallyBuoyantLineSwingsUnderItsFixedPoint) {
  const v1::Scene s = Read(R"(--------------------- MoorDyn Input File ------------------------------------
A pendulum on a line as dense as the water
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
main       0.1     7.853981634  1.0E9      -0.01       0          0.0    0.0    0.0     0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       -1       0       0      0       0      0
2     Free      10      -1       -28    1E1    0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     main       1        2         32.0      20      p
---------------------- OPTIONS -----------------------------------------
1000.0        WtrDnsty      water density (kg/m^3)
500           WtrDpth       water depth (m)
------------------------- need this line --------------------------------------
)");
  ASSERT_EQ(s.bodies_size(), 1);
  CollectingSink sink;
  const Frame last = Statics(s, "point2", &sink);
  ASSERT_EQ(last.probes.size(), 1u);
  const double weight = 10 * 9.80665, z = -32 * (1 + weight / 1e9);
  const Eigen::Vector3d r = last.probes[0].position_m;
  std::printf("point (%.9g, %.9g, %.12g) m, below the fixed point at z %.12g m\n", r.x(), r.y(),
              r.z(), z);
  EXPECT_NEAR(r.z(), z, 1e-9);
  EXPECT_NEAR(r.x(), 0, 1e-6);
  EXPECT_NEAR(r.y(), -1, 1e-6);
}

// A float in the surface (MoorDyn's tripod.txt's kind): a short, thick,
// buoyant line (d 0.8 m, 0.6 m, 130 kg/m) whose top end is free, on a
// tether (1.1 m) from a junction held by three legs (20.2 m, taut under
// the float's lift) to anchors 16 m down (the bed 4 m below them: no line
// touches it), laid tilted and off-centre. The float's section pierces the surface, so its buoyancy
// above the level is STATIC's dry fraction of the section (cable_buoyancy.h),
// which under the point-wise switch had no equilibrium (Newton hopped
// between a Gauss point wet and dry for 500 iterations at each of 12
// bisections). At rest the anchors hold the lines' weight in water less the
// float's buoyancy, and what the float loses above the level is, for its
// straight axis (EI 9e9 N m^2: it bends by under 1e-8 m) between its end
// nodes at heights h0, h1 over a length L, rho A g L (R G(h1 / R) -
// R G(h0 / R)) / (h1 - h0) (G the dry fraction's integral; its level
// limit g(h0 / R) L). Tolerance 1e-6 of the float's buoyancy: the
// solve's residual (8e-9 relative) and the float's bending.
TEST(MoorDynBodiesTest, FloatInTheSurfaceOnATetheredTripodBalancesItsWeights) {
  v1::Scene s = Read(R"(--------------------- MoorDyn Input File ------------------------------------
A float on a tether and three legs
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
float      0.8     130        2.0E9      -0.5        9.0E9      1.2    1.0    0.4     1.0
tether     0.025   3.8        2.5E7      -0.5        990        1.2    1.0    0.08    1.0
leg        0.01    0.195      5.0E6      -0.5        31         1.2    1.0    0.08    1.0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Free      0       0       -0.2    0      0       0      0
2     Free      0.55    0.1     0.1     0      0       0      0
3     Free      -0.1    0       -1.3    0      0       0      0
4     Fixed     14      0       -16     0      0       0      0
5     Fixed     -5.9    12.7    -16     0      0       0      0
6     Fixed     -8.0    -11.5   -16     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     float      1        2         0.6       3       p
2     tether     3        1         1.1       5       p
3     leg        3        4         20.2      14      p
4     leg        3        5         20.2      14      p
5     leg        3        6         20.2      14      p
---------------------- OPTIONS -----------------------------------------
20.0          WtrDpth       water depth (m)
------------------------- need this line --------------------------------------
)");
  s.mutable_output()->set_shape(true);
  s.mutable_output()->set_reactions(true);
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  const RunSummary summary = RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Frame& last = sink.frames().back();
  // The float's end nodes (cable 0, 3 elements: nodes 0 to 3).
  ASSERT_GE(last.nodes.size(), 4u);
  const Eigen::Vector3d a = last.nodes[0], b = last.nodes[3];
  const double g = 9.80665, rho = 1025, r = 0.4, area = kPi * r * r;
  const double float_length = 0.6, h0 = a.z(), h1 = b.z();
  auto big_g = [](double u) {
    u = std::clamp(u, -1.0, 1.0);
    const double c = 1 - u * u;
    return (u * std::acos(-u) + std::sqrt(c) - c * std::sqrt(c) / 3) / kPi;
  };
  auto dry_fraction = [](double u) {
    u = std::clamp(u, -1.0, 1.0);
    return (std::acos(-u) + u * std::sqrt(1 - u * u)) / kPi;
  };
  const double dry_length = std::abs(h1 - h0) > 1e-9
                                ? float_length * r * (big_g(h1 / r) - big_g(h0 / r)) / (h1 - h0)
                                : float_length * dry_fraction(h0 / r);
  // Weights in water [N] (down): mu - rho A per length, times g L.
  auto wet = [&](double mu, double d, double length) {
    return (mu - rho * kPi * d * d / 4) * g * length;
  };
  const double weights = wet(130, 0.8, 0.6) + wet(3.8, 0.025, 1.1) + 3 * wet(0.195, 0.01, 20.2);
  const double lost = rho * area * g * dry_length;
  // The anchors: the joints to ground (the others join line ends). A
  // joint's reaction is the force on its side a, the line.
  ASSERT_EQ(last.reactions.size(), static_cast<size_t>(s.joints_size()));
  double held = 0;  // the anchors' upward force on the lines
  int anchors = 0;
  for (int j = 0; j < s.joints_size(); ++j) {
    if (s.joints(j).has_b()) continue;
    held += last.reactions[j].force.z();
    ++anchors;
  }
  EXPECT_EQ(anchors, 3);
  std::printf("float from z %.6f to %.6f m (dry %.6f m); anchors hold %.9g N, weights %.9g N "
              "+ buoyancy lost %.9g N = %.9g N; residual %.3g\n",
              h0, h1, dry_length, held, weights, lost, weights + lost,
              summary.max_newton_residual);
  // The float pierces the surface (else the test tests nothing new).
  EXPECT_LT(std::min(h0, h1), r);
  EXPECT_GT(std::max(h0, h1), -r);
  // The anchors pull the lines down by their loads: held = weights + lost.
  EXPECT_NEAR(held, weights + lost, 1e-6 * rho * area * g * float_length);
}

// A free body (BODIES) of volume 8 m^3 and 5000 kg with its CG 0.5 m
// below its reference point: a vertical cylinder as tall as wide
// (d = (4 V / pi)^(1/3)) at the CG, floating where m = rho A s. (Its
// drag, at the reference point, would be refused: BODIES CG below.)
constexpr char kFloater[] = R"(---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)
1       free      0     0      0     0       0      0      5000  -0.5  2000    8        0      0.8
)";
TEST(MoorDynBodiesTest, FreeBodyFloatsAtItsDraft) {
  const v1::Scene s = Read(Deck(kFloater));
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& b = s.bodies(0);
  EXPECT_EQ(b.name(), "body1");
  EXPECT_DOUBLE_EQ(b.mass(), 5000);
  EXPECT_DOUBLE_EQ(b.position().z(), -0.5);  // CG = z only
  EXPECT_DOUBLE_EQ(b.inertia().x(), 2000);
  const double d = std::cbrt(4 * 8 / kPi), area = kPi * d * d / 4;
  EXPECT_DOUBLE_EQ(b.hydrodynamics().diameter(), d);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().height(), d);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().drag_coefficient(), 0);
  EXPECT_FALSE(b.hydrodynamics().has_drag_area());
  EXPECT_DOUBLE_EQ(b.hydrodynamics().added_mass(), 0.8);
  CollectingSink sink;
  const Frame last = Statics(s, "body1", &sink);
  ASSERT_EQ(last.probes.size(), 1u);
  const double z = last.probes[0].position_m.z(), expected = d / 2 - 5000 / (kRho * area);
  std::printf("body centre %.12g m, Archimedes %.12g m\n", z, expected);
  EXPECT_NEAR(z, expected, 1e-9 * d);
}

// A vertical rod (d 0.3 m, 6 m, 150 kg/m) hanging from a rope (EA 1e9 N,
// 20 kg/m, 30 m) from a fixed point at -20 m by its end B: at rest the
// rope's tension at the rod is the rod's weight less its buoyancy,
// g (w L - rho (pi d^2 / 4) L), and its top end hangs below the fixed point
// by the rope's stretched length.
constexpr char kHangingRod[] = R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
rope       0.05    20         1.0e9      -0.5        0          1.2    1.0    0.0     0.0
---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
weight        0.3      150       1.0    1.0     0.5      0.5
---------------------- RODS ----------------------------------------
ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs
(#)  (name)    (#/key)    (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
1    weight    Free       0     0     -56   0     0     -50  3         -
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       0       -20     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     rope       1        R1B       30        10      -
----------------------- OUTPUTS -----------------------------------------
FairTen1
)";

TEST(MoorDynBodiesTest, RodHangingFromALineAtRestCarriesItsWeightLessBuoyancy) {
  const v1::Scene s = Read(Deck(kHangingRod));
  ASSERT_EQ(s.bodies_size(), 1);
  // The rope's end B is pinned to the rod's end B, (L / 2, 0, 0) in its axes.
  bool joined = false;
  for (const v1::Joint& j : s.joints()) {
    if (j.b().body() != "rod1") continue;
    joined = true;
    EXPECT_EQ(j.a().cable(), "line1");
    EXPECT_DOUBLE_EQ(j.a().s(), 30);
    EXPECT_DOUBLE_EQ(j.b().point().x(), 3);
  }
  EXPECT_TRUE(joined);
  CollectingSink sink;
  const Frame last = Statics(s, "rod1", &sink);
  ASSERT_EQ(last.probe_tensions.size(), 1u);
  const double volume = kPi * 0.3 * 0.3 / 4 * 6;
  const double net = kG * (150 * 6 - kRho * volume);
  std::printf("tension at the rod %.9g N, by hand %.9g N\n", last.probe_tensions[0], net);
  // The end tension is the element's axial force at its end: rounding of
  // the strain of a 1e9 N rope (1e-16 x 1e9 / 1e4 N ~ 1e-11 relative),
  // Newton's tolerance, and the engineering law's exactness; 1e-6.
  EXPECT_NEAR(last.probe_tensions[0], net, 1e-6 * net);
  // The rope hangs straight: its tension grows by its own weight in water
  // per metre, so it stretches by (T_bottom L + w' L^2 / 2) / EA.
  const double rope_wet = kG * (20 - kRho * kPi * 0.05 * 0.05 / 4);
  const double stretch = (net * 30 + rope_wet * 30 * 30 / 2) / 1e9;
  const double centre = -20 - 30 - stretch - 3;
  std::printf("rod centre %.12g m, by hand %.12g m\n", last.probes[0].position_m.z(), centre);
  EXPECT_NEAR(last.probes[0].position_m.z(), centre, 1e-6);
  EXPECT_NEAR(last.probes[0].position_m.x(), 0, 1e-6);
}

// A body with a vertical rod rigidly on it (Body1), two 50 kg points on it
// holding lines, turned by yaw 90 degrees: one scene body of the sum of
// the masses at their common centre, inertia by the parallel-axis theorem,
// the points where the rotation puts them.
constexpr char kBodyWithRod[] = R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1     100        1.0e9      -0.5        0          1.2    1.0    0.4     0.0
---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
can           2        500       0.6    1.0     1.2      1.0
---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)
1       free      0     0      -40   0       0      90     1e4   0    5e4     0        0      0
---------------------- RODS ----------------------------------------
ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs
(#)  (name)    (#/key)    (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
1    can       Body1      0     0     -5    0     0     5    4         -
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Body1     2       0       0       50     0       0      0
2     Body1     -2      0       0       50     0       0      0
3     Fixed     0       300     -200    0      0       0      0
4     Fixed     0       -300    -200    0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      3        1         340       20      -
2     chain      4        2         340       20      -
----------------------- OUTPUTS -----------------------------------------
Point1Pz
)";

TEST(MoorDynBodiesTest, BodyWithRodAndPointsIsOneRigidBody) {
  const v1::Scene s = Read(Deck(kBodyWithRod));
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& b = BodyNamed(s, "body1");
  const double rod = 500 * 10, total = 1e4 + rod + 100;
  EXPECT_DOUBLE_EQ(b.mass(), total);
  EXPECT_NEAR(b.position().z(), -40, 1e-12);
  EXPECT_NEAR(b.position().x(), 0, 1e-12);
  // About z (the rod's axis): the body's 5e4, the rod's m r^2 / 2, the
  // points' 2 x 50 x 2^2; about x: the rod's m (3 r^2 + L^2) / 12, and the
  // points (on the world's y axis after the yaw) 2 x 50 x 2^2; about y: no
  // point term.
  const double rod_axial = rod * 1.0 / 2, rod_across = rod * (3 * 1.0 + 100) / 12;
  EXPECT_NEAR(b.inertia().z(), 5e4 + rod_axial + 400, 1e-8);
  EXPECT_NEAR(b.inertia().x(), 5e4 + rod_across + 400, 1e-8);
  EXPECT_NEAR(b.inertia().y(), 5e4 + rod_across, 1e-8);
  // The rod's cylinder, centred at the centre of mass.
  EXPECT_DOUBLE_EQ(b.hydrodynamics().diameter(), 2);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().height(), 10);
  // Both ends under water: twice CdEnd.
  EXPECT_DOUBLE_EQ(b.hydrodynamics().heave_drag_coefficient(), 2.4);
  // Point 1 at (2, 0, 0) in the body frame is at (0, 2, -40) after the yaw.
  int pinned = 0;
  for (const v1::Joint& j : s.joints()) {
    if (j.b().body() != "body1") continue;
    ++pinned;
    EXPECT_NEAR(std::abs(j.b().point().y()), 2, 1e-12);
    EXPECT_NEAR(j.b().point().x(), 0, 1e-12);
  }
  EXPECT_EQ(pinned, 2);
  ASSERT_EQ(s.cables_size(), 2);
  EXPECT_NEAR(s.cables(0).points(s.cables(0).points_size() - 1).y(), 2, 1e-12);
  // The output channel Point1Pz: a probe on the body's point.
  ASSERT_EQ(s.probes_size(), 1);
  EXPECT_EQ(s.probes(0).body(), "body1");
}

// A body with its own volume (3 m^3) and a horizontal rod on it (along
// the body's x, the world's y after the yaw of 90 degrees), both centred at
// its centre of mass (MoorDyn's riser decks clamp such a rod to a buoy):
// two parts, the volume's vertical cylinder in `hydrodynamics` and the rod
// in hydrodynamics_parts, its loads split along its own axis (the world's
// y in the scene body's frame, the world's at the start), the ends' CdEnd
// and CaEnd on its axis. Before, a second part with volume was refused.
TEST(MoorDynBodiesTest, BodyVolumeAndHorizontalRodAreTwoParts) {
  const std::string deck = absl::StrReplaceAll(
      Deck(kBodyWithRod), {{"5e4     0        0", "5e4     3        0"},
                           {"1    can       Body1      0     0     -5    0     0     5    4",
                            "1    can       Body1      -5    0     0     5     0     0    4"}});
  const v1::Scene s = Read(deck);
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& b = BodyNamed(s, "body1");
  EXPECT_NEAR(b.position().z(), -40, 1e-12);
  // The body's volume: a vertical cylinder as tall as wide.
  const double d = std::cbrt(4 * 3 / kPi);
  EXPECT_NEAR(b.hydrodynamics().diameter(), d, 1e-14);
  EXPECT_NEAR(b.hydrodynamics().height(), d, 1e-14);
  EXPECT_FALSE(b.hydrodynamics().along_axis());
  // The rod: d 2 m, 10 m, Cd 0.6 and Ca 1 across, both ends' CdEnd 1.2
  // along, and CaEnd 1 on the ends' (2/3) pi r^3 each over the rod's
  // volume pi r^2 L: 2 (2/3) / 10.
  ASSERT_EQ(b.hydrodynamics_parts_size(), 1);
  const v1::BodyHydrodynamics& rod = b.hydrodynamics_parts(0);
  EXPECT_TRUE(rod.along_axis());
  EXPECT_NEAR(rod.axis().x(), 0, 1e-12);
  EXPECT_NEAR(rod.axis().y(), 1, 1e-12);
  EXPECT_NEAR(rod.axis().z(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(rod.diameter(), 2);
  EXPECT_DOUBLE_EQ(rod.height(), 10);
  EXPECT_DOUBLE_EQ(rod.drag_coefficient(), 0.6);
  EXPECT_DOUBLE_EQ(rod.added_mass(), 1.0);
  EXPECT_DOUBLE_EQ(rod.heave_drag_coefficient(), 2 * 1.2);
  EXPECT_NEAR(rod.heave_added_mass(), 2 * (2.0 / 3) / 10, 1e-15);
  // The scene builds a model with one fluid load per part.
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<MultibodyModel> model = MultibodyModel::Build(*scene);
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->body_fluid_loads().size(), 2u);
  // Its statics: the body hangs between its two lines, buoyed by both
  // parts.
  CollectingSink sink;
  const Frame last = Statics(s, "body1", &sink);
  EXPECT_TRUE(std::isfinite(last.probes[0].position_m.z()));
}

// Fixed, coupled and coupled-pinned bodies; pinned, fixed and coupled
// rods.
TEST(MoorDynBodiesTest, MountsBecomeSupportsCoupledBodiesAndPins) {
  const v1::Scene s = Read(Deck(R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1     100        1.0e9      -0.5        0          1.2    1.0    0.4     0.0
---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
bar           0.2      50        0      0       0        0
---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)
1       Fixed     0     0      -200  0       0      90     0     0    0       0        0      0
2       Coupled   100   0      -10   0       0      0      0     0    0       0        0      0
3       CoupledPinned 0 100    -20   0       0      0      1e3   0    1e3     0        0      0
---------------------- RODS ----------------------------------------
ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs
(#)  (name)    (#/key)    (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
1    bar       Pinned     50    50    -100  52    50    -100 1         -
2    bar       Fixed      -50   0     -150  -50   0     -140 1         -
3    bar       Body3Pinned 0    0     -1    0     0     -3   1         -
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Body1     10      0       0       0      0       0      0
2     Body2     0       0       -1      0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         250       20      -
2     chain      R2B      R1B       130       20      -
)"));
  // Body 1 is fixed: no body; line 1's end A is a ground pin where the yaw
  // puts (10, 0, 0): the line starts at (0, 10, -200).
  EXPECT_NEAR(s.cables(0).points(0).x(), 0, 1e-12);
  EXPECT_NEAR(s.cables(0).points(0).y(), 10, 1e-12);
  EXPECT_EQ(BodyNamed(s, "body2").coupled(), true);
  EXPECT_FALSE(BodyNamed(s, "body3").coupled());
  // Rod 2 is fixed: line 2 starts on the ground at its end B (a joint
  // named by the rod's end).
  EXPECT_DOUBLE_EQ(s.cables(1).points(0).z(), -140);
  bool rod_end = false;
  for (const v1::Joint& j : s.joints()) rod_end = rod_end || j.name() == "rod2B";
  EXPECT_TRUE(rod_end);
  int coupled_pins = 0, ground_pins = 0;
  for (const v1::Joint& j : s.joints()) {
    if (j.name() == "body3") {
      EXPECT_TRUE(j.coupled());
      EXPECT_EQ(j.a().body(), "body3");
      ++coupled_pins;
    }
    if (j.name() == "rod1A") {
      EXPECT_FALSE(j.has_b());
      EXPECT_DOUBLE_EQ(j.a().point().x(), -1);  // end A of a 2 m rod
      ++ground_pins;
    }
    if (j.name() == "rod3A") {
      // End A of rod 3 on body 3's point (0, 0, -1) from its reference.
      EXPECT_EQ(j.b().body(), "body3");
      EXPECT_NEAR(j.b().point().z(), -1, 1e-12);
    }
  }
  EXPECT_EQ(coupled_pins, 1);
  EXPECT_EQ(ground_pins, 1);
  // The scene is valid.
  EXPECT_TRUE(SceneFromProto(s).ok()) << SceneFromProto(s).status();
}

TEST(MoorDynBodiesTest, RefusalsNameTheLineAndField) {
  const std::string rod = Deck(kHangingRod);
  // Deck(...) puts the deck's first row on line 3: the rod type on line
  // 10, the rod on 14, the line on 22.
  auto edited = [&](const std::string& from, const std::string& to) {
    EXPECT_NE(rod.find(from), std::string::npos) << from;
    return absl::StrReplaceAll(rod, {{from, to}});
  };
  EXPECT_EQ(Refusal(edited("1    weight    Free", "1    heavy     Free")),
            "bad.dat:14: RODS RodType: unknown rod type \"heavy\" (define it in ROD TYPES before "
            "RODS)");
  EXPECT_EQ(Refusal(edited("1    weight    Free", "1    weight    Body2")),
            "bad.dat:14: RODS Attachment: body 2 does not exist (define it in BODIES before RODS)");
  EXPECT_EQ(Refusal(edited("R1B", "R2B")),
            "bad.dat:22: LINES Attach: rod 2 does not exist (define it in RODS)");
  EXPECT_EQ(Refusal(edited("1    weight    Free", "2    weight    Free")).substr(0, 18),
            "bad.dat:14: RODS I");
  // A horizontal rod with drag is read (its loads split along its axis);
  // one within half its length of the surface is refused (its buoyancy
  // would be the vertical cylinder's).
  {
    const v1::Scene horizontal = Read(edited("0     0     -50  3", "6     0     -56  3"));
    ASSERT_EQ(horizontal.bodies_size(), 1);
    EXPECT_TRUE(horizontal.bodies(0).hydrodynamics().along_axis());
    EXPECT_DOUBLE_EQ(horizontal.bodies(0).axis().x(), 1);
    EXPECT_DOUBLE_EQ(horizontal.bodies(0).hydrodynamics().heave_drag_coefficient(), 2 * 0.5);
  }
  EXPECT_NE(Refusal(edited("0     0     -56   0     0     -50  3", "0     0     -2    6     0     -2   3"))
                .find("bad.dat:14: RODS Zb: a rod that is not vertical within half its length of "
                      "the water surface"),
            std::string::npos);
  // A point on a body that does not exist.
  const std::string body = Deck(kBodyWithRod);
  EXPECT_EQ(Refusal(absl::StrReplaceAll(body, {{"1     Body1     2", "1     Body4     2"}})),
            "bad.dat:22: POINTS Type: body 4 does not exist (define it in BODIES)");
  // A second part with volume on one body is read (BodyVolumeAndHorizontalRodAreTwoParts);
  // a tilted rod on a body within half its length of the surface is refused.
  EXPECT_NE(Refusal(absl::StrReplaceAll(
                        body, {{"-40   0       0      90", "-2    0       0      90"},
                               {"1    can       Body1      0     0     -5    0     0     5    4",
                                "1    can       Body1      -5    0     0     5     0     0    4"}}))
                .find("bad.dat:18: RODS Zb: a rod that is not vertical within half its length"),
            std::string::npos);
  // The rod's cylinder off the centre of mass (one point's mass removed):
  // read since 28 November 2026, the rod's cylinder centred where it is,
  // `center` from the centre of mass in the body's frame (the world's at
  // the start): point 1's 50 kg at world y = 2 m move the centre of mass
  // 2 x 50 / 15,050 m along y, so the rod sits that far on the other side.
  {
    const v1::Scene off = Read(absl::StrReplaceAll(
        body, {{"2     Body1     -2      0       0       50",
                "2     Body1     -2      0       0       0"}}));
    ASSERT_EQ(off.bodies_size(), 1);
    const v1::BodyHydrodynamics& h = off.bodies(0).hydrodynamics();
    ASSERT_TRUE(h.has_center());
    EXPECT_NEAR(h.center().y(), -2 * 50 / (1e4 + 500 * 10 + 50), 1e-12);
    EXPECT_NEAR(h.center().x(), 0, 1e-12);
    EXPECT_NEAR(h.center().z(), 0, 1e-12);
    EXPECT_NEAR(off.bodies(0).position().y(), 2 * 50 / (1e4 + 500 * 10 + 50), 1e-12);
  }
  EXPECT_NE(Refusal(absl::StrReplaceAll(body, {{"-5    0     0     5    4",
                                               "-5    0     0     5    0"}}))
                .find("bad.dat:18: RODS NumSegs"),
            std::string::npos);
  // Drag areas per axis on a body turned off the world's axes (yaw 30).
  EXPECT_NE(Refusal(Deck(absl::StrReplaceAll(
                    kFloater, {{"0      5000  -0.5  2000    8        0 ",
                                "30     5000  0     2000    8        1|2|3 "}})))
                .find("bad.dat:6: BODIES CdA: drag areas that differ between the axes"),
            std::string::npos);
  EXPECT_NE(Refusal(absl::StrReplaceAll(body, {{"5e4     0        0      0",
                                               "5e4     0        1|2|3|4  0"}}))
                .find("bad.dat:14: BODIES CdA: \"1|2|3|4\": 1, 2, 3 or 6 numbers"),
            std::string::npos);
  EXPECT_NE(Refusal(absl::StrReplaceAll(body, {{"5e4     0        0      0",
                                               "5e4     0        -1     0"}}))
                .find("bad.dat:14: BODIES CdA: must be >= 0"),
            std::string::npos);
  // Drag on a body whose CG is off its reference point (MoorDyn's drag
  // acts there, cablesim's at the centre of mass).
  EXPECT_NE(Refusal(Deck(absl::StrReplaceAll(kFloater, {{"8        0      0.8", "8        1.5    0.8"}})))
                .find("bad.dat:6: BODIES CG: drag (CdA) on a body whose centre of mass lies 0.5 m"),
            std::string::npos);
}

// MoorDyn's body drag areas (BODIES CdA): one number for all six degrees
// of freedom, two for translation and rotation, three per axis for both,
// six per axis then about each axis; in the body's axes, which MoorDyn's
// yaw of 90 degrees turns (its x along the world's y): the scene's are
// the world's, so x and y swap. A body without volume keeps its drag (no
// cylinder, no buoyancy).
TEST(MoorDynBodiesTest, DragAreasPerBodyAxis) {
  const std::string body = Deck(kBodyWithRod);
  const std::string row = "0      90     1e4   0    5e4     0        0      0";
  ASSERT_NE(body.find(row), std::string::npos);
  auto areas = [&](const std::string& cda) {
    const v1::Scene s = Read(absl::StrReplaceAll(
        body, {{row, absl::StrCat("0      90     1e4   0    5e4     0        ", cda, " 0")}}));
    const v1::BodyHydrodynamics& h = BodyNamed(s, "body1").hydrodynamics();
    return std::pair{Eigen::Vector3d(h.drag_area().x(), h.drag_area().y(), h.drag_area().z()),
                     Eigen::Vector3d(h.rotational_drag_area().x(), h.rotational_drag_area().y(),
                                     h.rotational_drag_area().z())};
  };
  for (const auto& [cda, along, about] :
       {std::tuple{"0.5", Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(0.5, 0.5, 0.5)},
        std::tuple{"0.5|7", Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(7, 7, 7)},
        std::tuple{"1|2|3", Eigen::Vector3d(2, 1, 3), Eigen::Vector3d(2, 1, 3)},
        std::tuple{"1|2|3|4|5|6", Eigen::Vector3d(2, 1, 3), Eigen::Vector3d(5, 4, 6)}}) {
    SCOPED_TRACE(cda);
    const auto [a, w] = areas(cda);
    EXPECT_LT((a - along).norm(), 1e-12);
    EXPECT_LT((w - about).norm(), 1e-12);
  }
  // The scene is valid.
  const v1::Scene s = Read(absl::StrReplaceAll(
      body, {{row, "0      90     1e4   0    5e4     0        1|2|3 0"}}));
  EXPECT_TRUE(SceneFromProto(s).ok()) << SceneFromProto(s).status();
}

// MoorDyn's 3D seafloor file: nx ny, the ticks, then x y z per node.
std::string SeafloorFile(const std::string& nodes) {
  return absl::StrCat("3 2\n-100 0 100\n-50 50\n", nodes);
}
const char kFlatNodes[] =
    "-100 -50 -60\n0 -50 -60\n100 -50 -60\n-100 50 -60\n0 50 -60\n100 50 -60\n";

// A chain from (-80, 0) to (80, 0) at the bed, 200 m long, two ends on a
// flat grid bed at 60 m below a 200 m deep water: it lies on the grid bed,
// sunk by its weight in water per length over the stiffness per length.
std::string SeafloorDeck() {
  return Deck(R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1     100        1.0e9      -0.5        0          1.2    1.0    0.4     0.0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     -80     0       -60     0      0       0      0
2     Fixed     80      0       -60     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         160       16      -
---------------------- OPTIONS -----------------------------------------
bed.txt       SeafloorFile  the bed
3.0e6         kBot          bottom stiffness (Pa/m)
)");
}

MoorDynFileReader Files(const std::string& bed) {
  return [bed](std::string_view name) -> absl::StatusOr<std::string> {
    if (name == "bed.txt") return bed;
    return absl::NotFoundError(absl::StrCat("no file ", std::string(name)));
  };
}

TEST(MoorDynBodiesTest, SeafloorFileBecomesTheBathymetryGrid) {
  const v1::Scene s = Read(SeafloorDeck(), Files(SeafloorFile(
      "-100 -50 -60\n0 -50 -61\n100 -50 -62\n-100 50 -63\n0 50 -64\n100 50 -65\n")));
  const v1::Bathymetry& g = s.seabed().bathymetry();
  EXPECT_EQ(g.nx(), 3);
  EXPECT_EQ(g.ny(), 2);
  EXPECT_DOUBLE_EQ(g.origin_x(), -100);
  EXPECT_DOUBLE_EQ(g.origin_y(), -50);
  EXPECT_DOUBLE_EQ(g.dx(), 100);
  EXPECT_DOUBLE_EQ(g.dy(), 100);
  ASSERT_EQ(g.depths_size(), 6);
  for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(g.depths(k), 60 + k);  // row-major, -z
  EXPECT_DOUBLE_EQ(s.seabed().depth(), 0);
  EXPECT_DOUBLE_EQ(s.fluid().water_depth(), 200);

  // Refusals name the deck's line (17: the option) and the file's row.
  const std::string deck = SeafloorDeck();
  EXPECT_NE(Refusal(deck, Files(absl::StrCat("3 2\n-100 0 150\n-50 50\n", kFlatNodes)))
                .find("bad.dat:17: OPTIONS SeafloorFile: bed.txt:2: tick 0 is off the even "
                      "spacing: a non-rectangular"),
            std::string::npos);
  EXPECT_NE(Refusal(deck, Files(SeafloorFile("-100 -50 -60\n0 -50 -60\n100 -50 -60\n")))
                .find("the node (-100, 50) is missing"),
            std::string::npos);
  EXPECT_NE(Refusal(deck, Files(SeafloorFile("-100 -50 -60\n-100 -50 -60\n")))
                .find("bed.txt:5: a node given twice"),
            std::string::npos);
  EXPECT_NE(Refusal(deck, Files(SeafloorFile("-100 -20 -60\n"))).find("bed.txt:4: the node is "
                                                                      "not on the grid"),
            std::string::npos);
  EXPECT_NE(Refusal(deck).find("bad.dat:17: OPTIONS SeafloorFile: \"bed.txt\": a seafloor file "
                               "cannot be read here"),
            std::string::npos);
}

TEST(MoorDynBodiesTest, ChainLiesOnTheSeafloorFilesBed) {
  v1::Scene s = Read(SeafloorDeck(), Files(SeafloorFile(kFlatNodes)));
  v1::Probe* p = s.add_probes();
  p->set_name("mid");
  p->set_cable("line1");
  p->set_s(80);
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  const double z = sink.frames().back().probes[0].position_m.z();
  // Penetration = weight in water per length / (kBot d).
  const double wet = kG * (100 - kRho * kPi * 0.01 / 4);
  const double expected = -60 - wet / (3.0e6 * 0.1);
  std::printf("chain's middle at %.9g m, on the grid bed %.9g m\n", z, expected);
  // The element's cubic follows the uniform sinking exactly; Newton's
  // tolerance; 1e-6 m.
  EXPECT_NEAR(z, expected, 1e-6);
}

// Two lines of different diameters on a flat bed (kBot 3e6 Pa/m, cBot
// 3e5 Pa s/m): MoorDyn's bed pressure acts on each line's diameter, so each
// sinks by its own weight in water per length over kBot d.
std::string TwoDiameterDeck() {
  return Deck(R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1     100        1.0e9      -0.5        0          1.2    1.0    0.4     0.0
rope       0.2     60         1.0e8      -0.5        0          1.2    1.0    0.4     0.0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     -100    0       -200    0      0       0      0
2     Fixed     0       0       -200    0      0       0      0
3     Fixed     100     0       -200    0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         100       10      -
2     rope       2        3         100       10      -
---------------------- OPTIONS -----------------------------------------
3.0e6         kBot          bottom stiffness (Pa/m)
3.0e5         cBot          bottom damping (Pa-s/m)
)");
}

TEST(MoorDynBodiesTest, LinesOfDifferentDiametersPressOnTheBedByTheirOwnDiameter) {
  v1::Scene s = Read(TwoDiameterDeck());
  ASSERT_EQ(s.cables_size(), 2);
  // The scene's bed from the first type's diameter; the rope its own.
  EXPECT_DOUBLE_EQ(s.seabed().stiffness(), 3.0e6 * 0.1);
  EXPECT_DOUBLE_EQ(s.seabed().damping(), 3.0e5 * 0.1);
  EXPECT_FALSE(s.cables(0).has_seabed_stiffness());
  EXPECT_DOUBLE_EQ(s.cables(1).seabed_stiffness(), 3.0e6 * 0.2);
  EXPECT_DOUBLE_EQ(s.cables(1).seabed_damping(), 3.0e5 * 0.2);
  for (const auto& [name, cable] : {std::pair{"chain", "line1"}, std::pair{"rope", "line2"}}) {
    v1::Probe* p = s.add_probes();
    p->set_name(name);
    p->set_cable(cable);
    p->set_s(50);
  }
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Frame& last = sink.frames().back();
  const double chain = -200 - kG * (100 - kRho * kPi * 0.01 / 4) / (3.0e6 * 0.1);
  const double rope = -200 - kG * (60 - kRho * kPi * 0.04 / 4) / (3.0e6 * 0.2);
  std::printf("chain's middle %.9g m (by hand %.9g), rope's %.9g m (by hand %.9g)\n",
              last.probes[0].position_m.z(), chain, last.probes[1].position_m.z(), rope);
  // 50 m from the ends (held at the bed's undisturbed level, which lifts
  // the line near them) the bed carries the line's weight alone: measured
  // within 0.1 % of each penetration (2.8e-6 m of the chain's 3.0e-3 m);
  // tolerance 1 % of it. With the scene's stiffness for both, the rope's
  // penetration would be twice as deep (9.1e-4 m, 100 % off).
  EXPECT_NEAR(last.probes[0].position_m.z(), chain, 0.01 * (-200 - chain));
  EXPECT_NEAR(last.probes[1].position_m.z(), rope, 0.01 * (-200 - rope));
  // A cable's own bed needs a seabed.
  v1::Scene dry = s;
  dry.clear_seabed();
  EXPECT_EQ(SceneFromProto(dry).status().message(), "cables[1].seabed_stiffness: needs a seabed");
  v1::Scene soft = s;
  soft.mutable_cables(1)->set_seabed_stiffness(0);
  EXPECT_EQ(SceneFromProto(soft).status().message().substr(0, 35),
            "cables[1].seabed_stiffness: must be");
}

std::string WriteTemp(const std::string& dir, const std::string& name, const std::string& text) {
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

using testing::Cli;

// Each deck of this file through the CLI: import writes a scene, run
// solves it; a bad deck exits 2 naming the line.
TEST(MoorDynBodiesTest, CliImportsAndRunsTheDecks) {
  const std::string dir =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/moordyn_bodies_", ::getpid()));
  WriteTemp(dir, "bed.txt", SeafloorFile(kFlatNodes));
  const std::vector<std::pair<std::string, std::string>> decks = {
      {"floating_rod.txt", Deck(kFloatingRod)},
      {"hanging_rod.dat", Deck(kHangingRod)},
      {"body_with_rod.dat", Deck(kBodyWithRod)},
      {"seafloor.dat", SeafloorDeck()},
      {"two_diameters.dat", TwoDiameterDeck()}};
  for (const auto& [name, text] : decks) {
    SCOPED_TRACE(name);
    const std::string deck = WriteTemp(dir, name, text);
    std::string out, err;
    EXPECT_EQ(Cli({"import", deck, "--out", deck + ".json"}, &out, &err), 0) << err;
    EXPECT_TRUE(ReadSceneFile(deck + ".json").ok());
    EXPECT_EQ(Cli({"run", deck, "--out", deck + ".csv"}, &out, &err), 0) << err;
    EXPECT_NE(out.find("\"status\":\"ok\""), std::string::npos) << out;
  }
  const std::string bad =
      WriteTemp(dir, "bad.dat", absl::StrReplaceAll(Deck(kHangingRod), {{"R1B", "R7B"}}));
  std::string out, err;
  EXPECT_EQ(Cli({"run", bad}, &out, &err), 2);
  EXPECT_NE(err.find("bad.dat:22: LINES Attach: rod 7 does not exist"), std::string::npos) << err;
}

}  // namespace
}  // namespace cablesim

namespace cablesim {
namespace {

// WtrDnsty 0: MoorDyn's dry deck (its body_tests/pinnedBody.txt). No
// fluid loads anywhere: the rod of kHangingRod hangs on its rope with its
// whole weight g (150 kg/m x 6 m) at the rope's end (1e-6, as in water).
TEST(MoorDynBodiesTest, DryDeckCarriesTheWholeWeight) {
  const std::string wet = Deck(kHangingRod);
  const std::string option = "1025          WtrDnsty";
  ASSERT_NE(wet.find(option), std::string::npos);
  const v1::Scene s = Read(absl::StrReplaceAll(wet, {{option, "0             WtrDnsty"}}));
  EXPECT_EQ(s.fluid().density(), 0);
  EXPECT_FALSE(s.fluid().free_surface());
  ASSERT_EQ(s.cables_size(), 1);
  EXPECT_FALSE(s.cables(0).has_hydrodynamics());
  ASSERT_EQ(s.bodies_size(), 1);
  EXPECT_FALSE(s.bodies(0).has_hydrodynamics());
  CollectingSink sink;
  const Frame last = Statics(s, "rod1", &sink);
  ASSERT_EQ(last.probe_tensions.size(), 1u);
  const double weight = kG * 150 * 6;
  std::printf("dry: tension at the rod %.9g N, by hand %.9g N\n", last.probe_tensions[0], weight);
  EXPECT_NEAR(last.probe_tensions[0], weight, 1e-6 * weight);
  // Negative stays refused.
  EXPECT_NE(Refusal(absl::StrReplaceAll(wet, {{option, "-1            WtrDnsty"}}))
                .find("OPTIONS WtrDnsty: must be >= 0"),
            std::string::npos);
}

// g 0: MoorDyn's weightless deck (its body_tests/orbitalBody.txt checks
// the same motion). A dumbbell of two 20 kg points 4 m apart on a body of
// no mass, its CG 10 m from its reference point, turning at 0.2 rad/s
// about its centre: the reference point orbits the centre at 10 m, its
// angle 0.2 t. MoorDyn's test's tolerances, 1e-6 of the radius and of the
// angular speed (measured: 1.3e-12 and 6.9e-9 of them at h = 1e-3 s over 10 s). The
// dumbbell has no inertia about its own axis: the converter gives it the
// 0.1 m sphere a free point gets (nothing turns it there).
TEST(MoorDynBodiesTest, WeightlessDumbbellOrbitsItsCentre) {
  const std::string deck = absl::StrReplaceAll(Deck(R"(---------------------------- BODIES -----------------------------------------------------
ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*       I*      Volume   CdA*   Ca
(#)     (-)      (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)       (kg-m^2)  (m^3)   (m^2)  (-)
1       free      0     10    -20    0       0      0      0     0|-10|0   0       0        0      0
----------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Body1     0       -10     -2      20     0       0      0
2     Body1     0       -10     2       20     0       0      0
)"),
                                               {{"9.81          g", "0             g"}});
  v1::Scene s = Read(deck);
  EXPECT_EQ(s.gravity().z(), 0);
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& b = s.bodies(0);
  EXPECT_DOUBLE_EQ(b.mass(), 40);
  EXPECT_NEAR(b.position().y(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(b.inertia().x(), 2 * 20 * 4);
  EXPECT_DOUBLE_EQ(b.inertia().z(), 0.4 * 40 * 0.1 * 0.1);
  s.mutable_solver()->set_analysis(v1::DYNAMIC);
  s.mutable_solver()->set_integrator(v1::HHT);
  s.mutable_solver()->set_duration(10);
  s.mutable_solver()->set_step(1e-3);
  s.mutable_solver()->set_output_interval(0.5);
  s.mutable_initial_velocity()->mutable_angular()->set_x(0.2);
  s.mutable_initial_velocity()->mutable_origin()->set_z(-20);
  v1::Probe* p = s.add_probes();
  p->set_name("reference");
  p->set_body("body1");
  p->mutable_point()->set_y(10);
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  RunOk(*scene, &sink);
  ASSERT_GE(sink.frames().size(), 20u);
  const int k = testing::ProbeIndex(sink.info(), "reference");
  ASSERT_GE(k, 0);
  double worst_r = 0, worst_w = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t == 0) continue;
    const Eigen::Vector3d r = f.probes[k].position_m - Eigen::Vector3d(0, 0, -20);
    worst_r = std::max(worst_r, std::abs(r.norm() - 10));
    worst_w = std::max(worst_w, std::abs(std::atan2(r.z(), r.y()) / f.t - 0.2));
  }
  std::printf("orbit: radius off by %.3g m, angular speed by %.3g rad/s\n", worst_r, worst_w);
  EXPECT_LT(worst_r, 1e-6 * 10);
  EXPECT_LT(worst_w, 1e-6 * 0.2);
  EXPECT_NE(Refusal(absl::StrReplaceAll(deck, {{"0             g", "-9.81         g"}}))
                .find("OPTIONS g: must be >= 0"),
            std::string::npos);
}

// A body's channels (OUTPUTS Body<n>...: MoorDyn's body_tests/pinnedBody.txt):
// the reference point's position, velocity and acceleration become a probe
// "Body<n>" on the body at that point, a rotation's output.orientation
// (refused for a body MoorDyn turns at the start: its scene body's axes
// are the world's); a channel of no translation is refused by name.
TEST(MoorDynBodiesTest, BodyChannelsBecomeAProbeAndTheOrientation) {
  const std::string body = Deck(kBodyWithRod);
  const std::string turned = "0      90     1e4", upright = "0      0      1e4";
  ASSERT_NE(body.find(turned), std::string::npos);
  const v1::Scene s = Read(absl::StrReplaceAll(
      body, {{"Point1Pz", "Body1Px\nBODY1AY\nBody1RX"}, {turned, upright}}));
  EXPECT_TRUE(s.output().orientation());
  int probes = 0;
  for (const v1::Probe& p : s.probes()) {
    if (p.name() != "Body1") continue;
    ++probes;
    EXPECT_EQ(p.body(), "body1");
    const v1::Body& b = BodyNamed(s, "body1");
    // The reference point (0, 0, -40) from the centre of mass.
    EXPECT_NEAR(b.position().z() + p.point().z(), -40, 1e-12);
  }
  EXPECT_EQ(probes, 1);
  EXPECT_TRUE(SceneFromProto(s).ok()) << SceneFromProto(s).status();
  EXPECT_NE(Refusal(absl::StrReplaceAll(body, {{"Point1Pz", "Body1RX"}}))
                .find("bad.dat:32: OUTPUTS Body1RX: a rotation channel of a body with r0, p0 or "
                      "y0"),
            std::string::npos);
  EXPECT_NE(Refusal(absl::StrReplaceAll(body, {{"Point1Pz", "Body1FX"}}))
                .find("bad.dat:32: OUTPUTS Body1FX: only point positions"),
            std::string::npos);
}

// A body with drag but no volume (MoorDyn's body_tests/bodyDrag.txt): its
// drag areas alone, no cylinder (no buoyancy), and a valid scene.
TEST(MoorDynBodiesTest, BodyDragWithoutVolume) {
  const v1::Scene s = Read(Deck(absl::StrReplaceAll(
      kFloater, {{"5000  -0.5  2000    8        0      0.8", "5000  0     2000    0        0.7    0.8"}})));
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::BodyHydrodynamics& h = s.bodies(0).hydrodynamics();
  EXPECT_FALSE(h.has_diameter());
  EXPECT_FALSE(h.has_height());
  EXPECT_DOUBLE_EQ(h.added_mass(), 0);  // MoorDyn's Ca rho V with V = 0
  EXPECT_DOUBLE_EQ(h.drag_area().x(), 0.7);
  EXPECT_DOUBLE_EQ(h.drag_area().z(), 0.7);
  EXPECT_DOUBLE_EQ(h.rotational_drag_area().y(), 0.7);
  auto model = MultibodyModel::Build(*SceneFromProto(s));
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->body_fluid_loads().size(), 1u);
  EXPECT_EQ(model->body_fluid_loads()[0].waterplane_area(), 0);
}

// ---- Rods of zero length (RODS NumSegs 0; convert/moordyn_deck.cc
// JoinAtPointRods, docs/moordyn-files.md "Bodies and rods"): the joints and
// tip loads a deck's rod becomes, a taut line split in two at such a rod
// against the unsplit line and the closed form of a hanging bar, and the
// refusals naming the deck's line.

constexpr char kPointRodTypes[] = R"(----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
cable      0.1     20         1.0e8      -0.5        1.0e5      1.2    1.0    0.0     0.0
rope       0.1     20         1.0e8      -0.5        0          1.2    1.0    0.0     0.0
soft       0.1     20         5.0e7      -0.5        1.0e3      1.2    1.0    0.0     0.0
---------------------- ROD TYPES ------------------------------------
TypeName      Diam     Mass/m    Cd     Ca      CdEnd    CaEnd
(name)        (m)      (kg/m)    (-)    (-)     (-)      (-)
conn          0.116    25        1.1    1.0     1.1      0.9
)";

// A taut vertical line from an anchor at -100 m to a fixed point at -10 m,
// 89 m long, split at a rod of zero length (placed off the line: a free
// rod's place is only where it starts) into 44.5 m and 44.5 m.
std::string SplitDeck(const std::string& rods, const std::string& lines) {
  return Deck(absl::StrCat(kPointRodTypes, R"(---------------------- RODS ----------------------------------------
ID   RodType  Attachment  Xa    Ya    Za    Xb    Yb    Zb   NumSegs  RodOutputs
(#)  (name)    (#/key)    (m)   (m)   (m)   (m)   (m)   (m)  (-)       (-)
)",
                           rods, R"(---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       0       -100    0      0       0      0
2     Fixed     0       0       -10     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
)",
                           lines, R"(----------------------- OUTPUTS -----------------------------------------
AnchTen1
FairTen2
)"));
}

constexpr char kFreeRod[] = "1    conn       Free   1  0  -50   1  0  -50    0   -\n";

TEST(MoorDynPointRodsTest, RodOfZeroLengthJoinsItsLinesAndCarriesItsEndLoads) {
  // Lines 1 (ending at R1A) and 2 (starting at R1B) have EI > 0: a FIXED
  // joint; line 3 (EI 0) is pinned to line 1's end.
  const std::string deck = absl::StrReplaceAll(
      SplitDeck(kFreeRod, "1 cable 1 R1A 44.5 10 -\n2 cable R1B 2 44.5 10 -\n"
                          "3 rope R1A 3 20 10 -\n"),
      {{"2     Fixed     0       0       -10     0      0       0      0\n",
        "2     Fixed     0       0       -10     0      0       0      0\n"
        "3     Fixed     15      0       -55     0      0       0      0\n"}});
  const absl::StatusOr<v1::Scene> s = SceneFromMoorDyn(deck, "test.dat");
  ASSERT_TRUE(s.ok()) << s.status();
  ASSERT_EQ(s->cables_size(), 3);
  EXPECT_EQ(s->bodies_size(), 0) << "a rod of zero length has no mass: no body";
  int fixed = 0, pinned = 0;
  for (const v1::Joint& j : s->joints()) {
    if (!j.b().cable().empty()) {
      EXPECT_EQ(j.b().cable(), "line1");
      EXPECT_DOUBLE_EQ(j.b().s(), 44.5);
      if (j.type() == v1::FIXED) {
        ++fixed;
        EXPECT_EQ(j.a().cable(), "line2");
        EXPECT_DOUBLE_EQ(j.a().s(), 0);
      } else {
        ++pinned;
        EXPECT_EQ(j.type(), v1::PIN);
        EXPECT_EQ(j.a().cable(), "line3");
        EXPECT_DOUBLE_EQ(j.a().s(), 0);
      }
    }
  }
  EXPECT_EQ(fixed, 1);
  EXPECT_EQ(pinned, 1);
  // Both ends' loads on line 1's end B (the first line with EI > 0):
  // 2 CdEnd pi d^2 / 4 and 2 rho CaEnd pi d^3 / 12.
  const double d = 0.116;
  const v1::Hydrodynamics& h = s->cables(0).hydrodynamics();
  EXPECT_DOUBLE_EQ(h.end_tip().drag_area(), 2 * 1.1 * kPi * d * d / 4);
  EXPECT_DOUBLE_EQ(h.end_tip().added_mass(), 2 * kRho * 0.9 * kPi * d * d * d / 12);
  EXPECT_FALSE(h.has_start_tip());
  for (int c = 1; c < 3; ++c) {
    EXPECT_FALSE(s->cables(c).hydrodynamics().has_start_tip()) << c;
    EXPECT_FALSE(s->cables(c).hydrodynamics().has_end_tip()) << c;
  }
  // Laid as one chain: line 1 ends where line 2 starts, on the straight
  // line between the points (the rod moved there from x = 1), and line 3
  // starts there too.
  const v1::Vec3& end1 = s->cables(0).points(s->cables(0).points_size() - 1);
  const v1::Vec3& start2 = s->cables(1).points(0);
  const v1::Vec3& start3 = s->cables(2).points(0);
  EXPECT_DOUBLE_EQ(end1.x(), 0);
  EXPECT_NEAR(end1.z(), -55, 1e-12);
  EXPECT_DOUBLE_EQ(start2.z(), end1.z());
  EXPECT_DOUBLE_EQ(start3.z(), end1.z());
  EXPECT_TRUE(SceneFromProto(*s).ok());
}

TEST(MoorDynPointRodsTest, RodWithoutALineOfBendingStiffnessCarriesNoEndLoads) {
  // MoorDyn's direction is then the zero vector: no end loads; the lines
  // are pinned.
  const absl::StatusOr<v1::Scene> s = SceneFromMoorDyn(
      SplitDeck(kFreeRod, "1 rope 1 R1A 44.5 10 -\n2 rope R1B 2 44.5 10 -\n"), "test.dat");
  ASSERT_TRUE(s.ok()) << s.status();
  for (const v1::Cable& c : s->cables()) {
    EXPECT_FALSE(c.hydrodynamics().has_start_tip());
    EXPECT_FALSE(c.hydrodynamics().has_end_tip());
  }
  ASSERT_EQ(s->joints_size(), 3);
  EXPECT_EQ(s->joints(1).type(), v1::PIN);
  EXPECT_EQ(s->joints(1).b().cable(), "line1");
}

// The top and bottom tensions of the taut line (deck's probes AnchTen1
// and FairTen2 or FairTen1).
std::pair<double, double> Tensions(const std::string& deck) {
  const absl::StatusOr<v1::Scene> proto = SceneFromMoorDyn(deck, "test.dat");
  EXPECT_TRUE(proto.ok()) << proto.status();
  if (!proto.ok()) return {0, 0};
  const absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  if (!scene.ok()) return {0, 0};
  CollectingSink sink;
  RunOk(*scene, &sink);
  const Frame& last = sink.frames().back();
  EXPECT_EQ(last.probe_tensions.size(), 2u);
  return {last.probe_tensions[0], last.probe_tensions[1]};
}

TEST(MoorDynPointRodsTest, TautLineSplitAtARodOfZeroLengthCarriesTheUnsplitTension) {
  const auto [bottom_split, top_split] =
      Tensions(SplitDeck(kFreeRod, "1 cable 1 R1A 44.5 10 -\n2 cable R1B 2 44.5 10 -\n"));
  std::string whole = SplitDeck("", "1 cable 1 2 89 20 -\n");
  whole = absl::StrReplaceAll(whole, {{"FairTen2", "FairTen1"}});
  const auto [bottom, top] = Tensions(whole);
  // The closed form: a bar of wet weight w per unit length between points
  // 90 m apart, unstretched 89 m, stretches by (T0 L + w L^2 / 2) / EA
  // (T0 at the bottom, engineering strain).
  const double length = 89, ea = 1e8;
  const double w = kG * (20 - kRho * kPi * 0.1 * 0.1 / 4);
  const double t0 = ((90 - length) * ea - w * length * length / 2) / length;
  std::printf("split: %.9g %.9g N, whole: %.9g %.9g N, closed form: %.9g %.9g N\n",
              bottom_split, top_split, bottom, top, t0, t0 + w * length);
  // Newton's tolerance and the elements' end forces (as the hanging rod's
  // test in moordyn_bodies_test.cc): 1e-6 relative.
  EXPECT_NEAR(bottom, t0, 1e-6 * t0);
  EXPECT_NEAR(top, t0 + w * length, 1e-6 * t0);
  EXPECT_NEAR(bottom_split, t0, 1e-6 * t0);
  EXPECT_NEAR(top_split, t0 + w * length, 1e-6 * t0);
}

// A sagging line with bending stiffness (EI 1e5 N m^2: a bending length
// sqrt(EI / T) of some 8 m at its 1.7 kN) between points 60 m apart at
// the same depth, split at its middle: the FIXED weld keeps it one smooth
// line (a PIN there would let it kink), so the statics are the unsplit
// line's, node for node (the split's nodes are the unsplit's); 1e-6 of
// the tension (Newton's tolerance).
TEST(MoorDynPointRodsTest, SaggingLineSplitAtARodOfZeroLengthStaysOneSmoothLine) {
  const std::pair<std::string, std::string> beside = {
      "2     Fixed     0       0       -10 ", "2     Fixed     60      0       -100"};
  const auto [bottom_split, top_split] = Tensions(absl::StrReplaceAll(
      SplitDeck(kFreeRod, "1 cable 1 R1A 44.5 10 -\n2 cable R1B 2 44.5 10 -\n"), {beside}));
  const auto [bottom, top] = Tensions(absl::StrReplaceAll(
      SplitDeck("", "1 cable 1 2 89 20 -\n"), {beside, {"FairTen2", "FairTen1"}}));
  std::printf("sagging, split: %.9g %.9g N, whole: %.9g %.9g N\n", bottom_split, top_split,
              bottom, top);
  EXPECT_NEAR(bottom_split, bottom, 1e-6 * bottom);
  EXPECT_NEAR(top_split, top, 1e-6 * top);
}

TEST(MoorDynPointRodsTest, RefusalsNameTheLineAndField) {
  const std::string two = "1 cable 1 R1A 44.5 10 -\n2 cable R1B 2 44.5 10 -\n";
  // On a body, pinned, fixed: not a free rod.
  std::string m = Refusal(SplitDeck("1 conn Pinned 1 0 -50 1 0 -50 0 -\n", two));
  EXPECT_NE(m.find("bad.dat:16: RODS Attachment: a pinned rod of zero length"), std::string::npos)
      << m;
  m = Refusal(SplitDeck("1 conn Fixed 1 0 -50 1 0 -50 0 -\n", two));
  EXPECT_NE(m.find("bad.dat:16: RODS Attachment: a rod of zero length that is not Free"),
            std::string::npos)
      << m;
  // NumSegs 0 with end B elsewhere; zero length with NumSegs 1.
  m = Refusal(SplitDeck("1 conn Free 1 0 -50 1 0 -49 0 -\n", two));
  EXPECT_NE(m.find("bad.dat:16: RODS NumSegs: 0 makes a rod of zero length at end A"),
            std::string::npos)
      << m;
  m = Refusal(SplitDeck("1 conn Free 1 0 -50 1 0 -50 1 -\n", two));
  EXPECT_NE(m.find("bad.dat:16: RODS NumSegs: a rod of zero length has no direction"),
            std::string::npos)
      << m;
  // Head to head (both lines end at the rod, at its two ends).
  m = Refusal(SplitDeck(kFreeRod, "1 cable 1 R1A 44.5 10 -\n2 cable 2 R1B 44.5 10 -\n"));
  EXPECT_NE(m.find("bad.dat:26: LINES AttachB: lines 1 and 2 meet at rod 1"), std::string::npos)
      << m;
  // Different EA.
  m = Refusal(SplitDeck(kFreeRod, "1 cable 1 R1A 44.5 10 -\n2 soft R1B 2 44.5 10 -\n"));
  EXPECT_NE(m.find("bad.dat:26: LINES LineType: lines 1 and 2 meet at rod 1 (of zero length) "
                   "with different EA"),
            std::string::npos)
      << m;
  // A rod of zero length with no line.
  m = Refusal(SplitDeck(kFreeRod, "1 cable 1 2 89 20 -\n"));
  EXPECT_NE(m.find("bad.dat:16: RODS ID: a rod of zero length with no line"), std::string::npos)
      << m;
}

}  // namespace
}  // namespace cablesim
