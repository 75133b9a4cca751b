// MoorDyn v2 input files read into scenes (convert/moordyn_deck.h): each
// section, each convention of docs/moordyn-files.md against its formula,
// each refusal naming the file's line and field, and the CLI's import and
// run and the service's scene_moordyn. The decks are written here.

#include "convert/moordyn_deck.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "client/cli.h"
#include "tests/cli_test_util.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "server/request_checks.h"
#include "tests/scratch_dir.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

// A deck of four lines: a chain from an anchor to a fairlead (point 2);
// a rope from a second anchor to a buoyant clump (point 4, free with mass
// and volume), then on to a massless connection (point 5) joining lines 3
// and 4, line 4 ending at the fairlead. Its line numbers matter to the
// refusal tests: line 6 is the chain's type, 19 to 22 the lines.
constexpr char kDeck[] = R"(--------------------- MoorDyn Input File ------------------------------------
A deck written for cablesim's tests
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1     100        1.0e9      -0.5        0          1.2    1.0    0.4     0.0
rope       0.1     10         2.0e8      3.0e6       50         1.5    0.8    0.1     0.8
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     400     0       -100    0      0       0      0
2     Vessel    0       0       -5      0      0       0      0
3     Fixed     -300    0       -100    0      0       0      0
4     Free      -200    0       -40     2000   1.5     0.6    0.9
5     Free      -100    0       -30     0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     chain      1        2         450       30      -
2     rope       3        4         150       10      -
3     rope       4        5         110       8       -
4     rope       5        2         110       8       p
---------------------- OPTIONS -----------------------------------------
0.001         dtM           time step (s)
3.0e6         kBot          bottom stiffness (Pa/m)
2.0e5         cBot          bottom damping (Pa-s/m)
1020          WtrDnsty      water density (kg/m^3)
100           WtrDpth       water depth (m)
9.81          g             gravity
0.4           FrictionCoefficient  friction
100.0         TmaxIC        max time for ic gen (s)
----------------------- OUTPUTS -----------------------------------------
Point4Pz
Point2Px Point2Pz
------------------------- need this line --------------------------------------
)";

v1::Scene Read(const std::string& text, const std::string& name = "test.dat") {
  absl::StatusOr<v1::Scene> scene = SceneFromMoorDyn(text, name);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : v1::Scene{};
}

// The refusal of `text` (InvalidArgument), its message.
std::string Refusal(const std::string& text) {
  absl::StatusOr<v1::Scene> scene = SceneFromMoorDyn(text, "bad.dat");
  EXPECT_FALSE(scene.ok());
  if (scene.ok()) return "";
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(scene.status().message());
}

// kDeck with `from` replaced by `to` (which must occur).
std::string Edited(const std::string& from, const std::string& to) {
  std::string text = kDeck;
  EXPECT_NE(text.find(from), std::string::npos) << from;
  return absl::StrReplaceAll(text, {{from, to}});
}

const v1::Cable& CableNamed(const v1::Scene& s, const std::string& name) {
  for (const v1::Cable& c : s.cables())
    if (c.name() == name) return c;
  ADD_FAILURE() << "no cable " << name;
  return s.cables(0);
}

TEST(MoorDynDeckTest, LineTypesTranslateEveryConvention) {
  const v1::Scene s = Read(kDeck);
  ASSERT_EQ(s.cables_size(), 4);
  const double area = kPi * 0.1 * 0.1 / 4;
  const v1::Cable& chain = CableNamed(s, "line1");
  EXPECT_DOUBLE_EQ(chain.area(), area);
  EXPECT_DOUBLE_EQ(chain.density(), 100 / area);           // mass per length in air / area
  EXPECT_DOUBLE_EQ(chain.youngs_modulus(), 1.0e9 / area);  // EA / area
  EXPECT_EQ(chain.bending(), v1::NONE);                    // EI = 0
  EXPECT_EQ(chain.axial_law(), v1::ENGINEERING);           // T = EA e
  EXPECT_DOUBLE_EQ(chain.length(), 450);
  EXPECT_EQ(chain.elements(), 30);
  // BA = -0.5: the damping ratio zeta = 0.5 of MoorDyn's BA = zeta (L/N)
  // sqrt(EA m) [N s]; the Kelvin-Voigt time is BA / EA.
  EXPECT_DOUBLE_EQ(chain.damping().axial_time(),
                   0.5 * (450.0 / 30) * std::sqrt(1.0e9 * 100) / 1.0e9);
  EXPECT_DOUBLE_EQ(chain.hydrodynamics().normal_drag(), 1.2);
  EXPECT_DOUBLE_EQ(chain.hydrodynamics().tangential_drag(), 0.4);
  EXPECT_DOUBLE_EQ(chain.hydrodynamics().added_mass(), 1.0);
  EXPECT_DOUBLE_EQ(chain.hydrodynamics().diameter(), 0.1);
  const v1::Cable& rope = CableNamed(s, "line2");
  EXPECT_EQ(rope.bending(), v1::EXACT);
  EXPECT_DOUBLE_EQ(rope.second_moment() * rope.youngs_modulus(), 50);  // EI kept
  EXPECT_DOUBLE_EQ(rope.damping().axial_time(), 3.0e6 / 2.0e8);     // BA >= 0: N s
}

// MoorDyn's viscoelastic types: EA "EA|EA_D" (a constant dynamic
// stiffness) or "EA|alphaMBL|beta" (the mean-load law), BA "BA|BA_D".
TEST(MoorDynDeckTest, ViscoelasticTypesBecomeTheViscoelasticLaw) {
  const v1::Scene constant = Read(Edited("2.0e8      3.0e6", "2.0e8|3.0e8  3.0e6|1.0e5"));
  const v1::Cable& rope = CableNamed(constant, "line2");
  EXPECT_EQ(rope.axial_law(), v1::VISCOELASTIC);
  EXPECT_DOUBLE_EQ(rope.youngs_modulus() * rope.area(), 2.0e8);  // the static EA
  EXPECT_DOUBLE_EQ(rope.viscoelastic().dynamic_ea(), 3.0e8);
  EXPECT_FALSE(rope.viscoelastic().has_dynamic_ea_base());
  EXPECT_DOUBLE_EQ(rope.viscoelastic().static_damping(), 3.0e6);
  EXPECT_DOUBLE_EQ(rope.viscoelastic().dynamic_damping(), 1.0e5);
  EXPECT_EQ(rope.damping().axial_time(), 0);  // BA is the law's dashpot, not Kelvin-Voigt's
  const v1::Scene mean = Read(Edited("2.0e8      3.0e6", "2.0e8|2.2e8|0.4  3.0e6"));
  const v1::Cable& m = CableNamed(mean, "line2");
  EXPECT_EQ(m.axial_law(), v1::VISCOELASTIC);
  EXPECT_FALSE(m.viscoelastic().has_dynamic_ea());
  EXPECT_DOUBLE_EQ(m.viscoelastic().dynamic_ea_base(), 2.2e8);
  EXPECT_DOUBLE_EQ(m.viscoelastic().dynamic_ea_slope(), 0.4);
  EXPECT_DOUBLE_EQ(m.viscoelastic().dynamic_damping(), 0);  // no BA_D: MoorDyn's 0
  // The scenes convert (the law's own checks pass).
  EXPECT_TRUE(SceneFromProto(constant).ok()) << SceneFromProto(constant).status();
  EXPECT_TRUE(SceneFromProto(mean).ok()) << SceneFromProto(mean).status();
}

TEST(MoorDynDeckTest, OptionsBecomeEnvironmentAndSeabed) {
  const v1::Scene s = Read(kDeck, "some/dir/test.dat");
  EXPECT_EQ(s.name(), "test");
  EXPECT_DOUBLE_EQ(s.gravity().z(), -9.81);
  EXPECT_DOUBLE_EQ(s.fluid().density(), 1020);
  EXPECT_DOUBLE_EQ(s.fluid().water_depth(), 100);
  EXPECT_DOUBLE_EQ(s.seabed().depth(), 100);
  EXPECT_DOUBLE_EQ(s.seabed().stiffness(), 3.0e6 * 0.1);  // kBot [Pa/m] x diameter
  EXPECT_DOUBLE_EQ(s.seabed().damping(), 2.0e5 * 0.1);    // cBot [Pa s/m] x diameter
  EXPECT_DOUBLE_EQ(s.seabed().friction_axial(), 0.4);
  EXPECT_DOUBLE_EQ(s.seabed().friction_transverse(), 0.4);
  EXPECT_EQ(s.solver().analysis(), v1::STATIC);
  // MoorDyn's defaults when omitted: g 9.80665, rho 1025, kBot 3e6, cBot 3e5.
  std::string text = kDeck;
  for (const char* option : {"3.0e6         kBot", "2.0e5         cBot", "1020          WtrDnsty",
                             "9.81          g "}) {
    const size_t at = text.find(option);
    ASSERT_NE(at, std::string::npos);
    text.erase(at, text.find('\n', at) - at + 1);
  }
  const v1::Scene d = Read(text);
  EXPECT_DOUBLE_EQ(d.gravity().z(), -9.80665);
  EXPECT_DOUBLE_EQ(d.fluid().density(), 1025);
  EXPECT_DOUBLE_EQ(d.seabed().stiffness(), 3.0e6 * 0.1);
  EXPECT_DOUBLE_EQ(d.seabed().damping(), 3.0e5 * 0.1);
}

TEST(MoorDynDeckTest, PointsBecomeSupportsBodiesAndPins) {
  const v1::Scene s = Read(kDeck);
  // Point 4 (mass and volume) is a body; point 5 (nothing) a pin between
  // the ends of lines 3 and 4; points 1, 2, 3 supports.
  ASSERT_EQ(s.bodies_size(), 1);
  const v1::Body& b = s.bodies(0);
  EXPECT_EQ(b.name(), "point4");
  EXPECT_DOUBLE_EQ(b.mass(), 2000);
  EXPECT_DOUBLE_EQ(b.position().x(), -200);
  EXPECT_DOUBLE_EQ(b.position().z(), -40);
  const double d = std::cbrt(4 * 1.5 / kPi);  // a cylinder as tall as wide, 1.5 m^3
  EXPECT_NEAR(kPi * d * d / 4 * d, 1.5, 1e-12);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().diameter(), d);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().height(), d);
  EXPECT_NEAR(b.hydrodynamics().drag_coefficient() * d * d, 0.6, 1e-12);  // CdA
  EXPECT_NEAR(b.hydrodynamics().heave_drag_coefficient() * kPi * d * d / 4, 0.6, 1e-12);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().added_mass(), 0.9);
  EXPECT_DOUBLE_EQ(b.hydrodynamics().heave_added_mass(), 0.9);
  int ground = 0, to_body = 0, cable_cable = 0;
  for (const v1::Joint& j : s.joints()) {
    EXPECT_EQ(j.type(), v1::PIN);
    if (!j.b().body().empty()) {
      ++to_body;
      EXPECT_EQ(j.b().body(), "point4");
    } else if (!j.b().cable().empty()) {
      ++cable_cable;
      EXPECT_EQ(j.a().cable(), "line4");
      EXPECT_DOUBLE_EQ(j.a().s(), 0);
      EXPECT_EQ(j.b().cable(), "line3");
      EXPECT_DOUBLE_EQ(j.b().s(), 110);
    } else {
      ++ground;
    }
  }
  EXPECT_EQ(ground, 4);  // line 1 at both ends, line 2 at A, line 4 at B
  EXPECT_EQ(to_body, 2);
  EXPECT_EQ(cable_cable, 1);
  // Outputs: point positions become probes, once per point.
  ASSERT_EQ(s.probes_size(), 2);
  EXPECT_EQ(s.probes(0).name(), "Point4");
  EXPECT_EQ(s.probes(0).body(), "point4");
  EXPECT_EQ(s.probes(1).name(), "Point2");
  EXPECT_EQ(s.probes(1).cable(), "line1");
  EXPECT_DOUBLE_EQ(s.probes(1).s(), 450);
  // And the scene converts.
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  EXPECT_TRUE(scene.ok()) << scene.status();
}

// MoorDyn's line-end tension channels become probes at the line's end
// with output.tension: FairTen<n> and Line<n>TenB at end B (s = length),
// AnchTen<n> and Line<n>TenA at end A, named as the deck spells them
// (columns FAIRTEN1.tension ...).
TEST(MoorDynDeckTest, LineEndTensionChannelsBecomeTensionProbes) {
  const v1::Scene s = Read(Edited("Point2Px Point2Pz", "FAIRTEN1 anchten1\nLine4TenB Line2TenA"));
  EXPECT_TRUE(s.output().tension());
  ASSERT_EQ(s.probes_size(), 5);
  const std::vector<std::tuple<std::string, std::string, double>> expected = {
      {"FAIRTEN1", "line1", 450}, {"anchten1", "line1", 0}, {"Line4TenB", "line4", 110},
      {"Line2TenA", "line2", 0}};
  for (size_t k = 0; k < expected.size(); ++k) {
    const v1::Probe& p = s.probes(static_cast<int>(k) + 1);
    EXPECT_EQ(p.name(), std::get<0>(expected[k]));
    EXPECT_EQ(p.cable(), std::get<1>(expected[k]));
    EXPECT_DOUBLE_EQ(p.s(), std::get<2>(expected[k]));
  }
  const absl::StatusOr<Scene> scene = SceneFromProto(s);
  EXPECT_TRUE(scene.ok()) << scene.status();
}

// MoorDyn's version 1 format (OpenFAST's decks before MoorDyn v2): count
// lines and other column orders. A chain from an anchor to a connection
// (free, with a clump's mass) and a rope on to a vessel point.
constexpr char kVersion1Head[] = R"(--------------------- MoorDyn Input File ------------------------------------
Two lines and a clump
FALSE    Echo      - echo the input file data (flag)
----------------------- LINE TYPES ------------------------------------------
2        NTypes    - number of LineTypes
Name     Diam      MassDen   EA        BA/-zeta  Can   Cat   Cdn   Cdt
(-)      (m)       (kg/m)    (N)       (N-s/-)   (-)   (-)   (-)   (-)
chain    0.1       100       1.0e9     -0.5      1.0   0.5   1.2   0.05
rope     0.1       10        2.0e8     -0.8      0.9   0.2   1.6   0.01
---------------------- CONNECTION PROPERTIES --------------------------------
3        NConnects - number of connections including anchors and fairleads
Node     Type      X        Y         Z        M        V        FX       FY      FZ     CdA   CA
(-)      (-)       (m)      (m)       (m)      (kg)     (m^3)    (kN)     (kN)    (kN)   (m^2) (-)
1        Fixed     -300     0         -100     0        0        0        0       0      0     0
2        Connect   -100     0         -60      2000     0.5      0        0       0      0.8   1.0
3        Vessel     -10     0         -5       0        0        0        0       0      0     0
---------------------- LINE PROPERTIES --------------------------------------
2        NLines    - number of line objects
Line     LineType  UnstrLen  NumSegs   NodeAnch  NodeFair  Flags/Outputs
(-)      (-)       (m)       (-)       (-)       (-)       (-)
1        chain     250       12        1         2         -
2        rope      110       6         2         3         p
)";

// The same tables in version 2's columns, written by hand.
constexpr char kVersion2Head[] = R"(--------------------- MoorDyn Input File ------------------------------------
Two lines and a clump
----------------------- LINE TYPES ------------------------------------------
TypeName Diam      Mass/m    EA        BA/-zeta  EI  Cd    Ca    CdAx  CaAx
(-)      (m)       (kg/m)    (N)       (N-s/-)   (-) (-)   (-)   (-)   (-)
chain    0.1       100       1.0e9     -0.5      0   1.2   1.0   0.05  0.5
rope     0.1       10        2.0e8     -0.8      0   1.6   0.9   0.01  0.2
---------------------- POINTS --------------------------------
ID       Attachment X        Y         Z        M        V        CdA   CA
(-)      (-)       (m)      (m)       (m)      (kg)     (m^3)    (m^2) (-)
1        Fixed     -300     0         -100     0        0        0     0
2        Free      -100     0         -60      2000     0.5      0.8   1.0
3        Vessel     -10     0         -5       0        0        0     0
---------------------- LINES --------------------------------------
ID       LineType  AttachA  AttachB  UnstrLen  NumSegs  Outputs
(-)      (-)       (-)      (-)      (m)       (-)      (-)
1        chain     1        2        250       12       -
2        rope      2        3        110       6        p
)";

// Both decks' options and outputs (version 1 closes its outputs with END,
// which version 2 also reads).
constexpr char kVersionsTail[] = R"(---------------------- SOLVER OPTIONS ---------------------------------------
0.001    dtM       - time step to use in mooring integration (s)
3.0e6    kbot      - bottom stiffness (Pa/m)
3.0e5    cbot      - bottom damping (Pa-s/m)
100      WtrDpth   - water depth (m)
60.0     TmaxIC    - max time for ic gen (s)
------------------------ OUTPUTS --------------------------------------------
FairTen2
AnchTen1
END
------------------------- need this line --------------------------------------
)";

TEST(MoorDynDeckTest, Version1DeckReadsAsItsVersion2Equivalent) {
  const std::string version1 = absl::StrCat(kVersion1Head, kVersionsTail);
  const v1::Scene old_format = Read(version1, "v1.dat");
  const v1::Scene new_format = Read(absl::StrCat(kVersion2Head, kVersionsTail), "v1.dat");
  ASSERT_EQ(old_format.cables_size(), 2);
  EXPECT_EQ(old_format.SerializeAsString(), new_format.SerializeAsString())
      << old_format.DebugString() << "\n---\n" << new_format.DebugString();
  // A wrong row names the file's line; a version 1 deck with a table that
  // has no count line is refused.
  std::string text = absl::StrReplaceAll(version1, {{"2        rope      110       6         2         3         p",
                                     "2        rope      110       6         2         3"}});
  const absl::StatusOr<v1::Scene> bad = SceneFromMoorDyn(text, "v1.dat");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("v1.dat:22: version 1 row: expected the 7 columns"),
            std::string::npos)
      << bad.status();
  text = absl::StrReplaceAll(version1, {{"2        NLines    - number of line objects\n", ""}});
  EXPECT_FALSE(SceneFromMoorDyn(text, "v1.dat").ok());
}

// OpenFAST's decks close OUTPUTS with a line END: the list ends there, the
// channels before it are read (end was refused as a channel name before).
TEST(MoorDynDeckTest, OutputsMayEndWithEnd) {
  const v1::Scene s = Read(Edited("Point2Px Point2Pz", "FairTen1\nEND"));
  ASSERT_EQ(s.probes_size(), 2);
  EXPECT_EQ(s.probes(1).name(), "FairTen1");
  EXPECT_EQ(Read(Edited("Point2Px Point2Pz", "Point2Px Point2Pz\nend")).probes_size(),
            Read(kDeck).probes_size());
}

TEST(MoorDynDeckTest, SlackLinesAreLaidAlongTheirLengthAboveTheBed) {
  const v1::Scene s = Read(kDeck);
  for (const v1::Cable& c : s.cables()) {
    double length = 0;
    for (int k = 1; k < c.points_size(); ++k) {
      const double dx = c.points(k).x() - c.points(k - 1).x();
      const double dy = c.points(k).y() - c.points(k - 1).y();
      const double dz = c.points(k).z() - c.points(k - 1).z();
      length += std::sqrt(dx * dx + dy * dy + dz * dz);
      EXPECT_GE(c.points(k).z(), -100 - 1e-9) << c.name();
    }
    // Every line of the deck is longer than its span: laid with a corner
    // so that the polyline's length is the unstretched length (1e-9:
    // bisection to rounding) on the bed (lines 1 and 2, from anchors), and
    // 0.1 % more for a free sag (lines 3 and 4: a little tension to start).
    EXPECT_GT(c.points_size(), 2) << c.name();
    const bool on_bed = c.name() == "line1" || c.name() == "line2";
    EXPECT_NEAR(length, c.length() * (on_bed ? 1 : 1.001), 1e-9 * c.length()) << c.name();
  }
  // The chain (450 m over a 395 m span from the anchor on the bed) has its
  // corner on the bed.
  EXPECT_DOUBLE_EQ(CableNamed(s, "line1").points(1).z(), -100);
}

TEST(MoorDynDeckTest, RefusalsNameTheLineAndField) {
  struct Case {
    std::string from, to, expected;
  };
  const Case cases[] = {
      {"1     chain      1        2", "1     cable      1        2",
       "bad.dat:19: LINES LineType: unknown line type \"cable\""},
      {"3     rope       4        5", "3     rope       4        9",
       "bad.dat:21: LINES AttachB: point 9 does not exist"},
      {"1.0e9      -0.5", "chain.txt  -0.5", "bad.dat:6: LINE TYPES EA: \"chain.txt\""},
      {"1.0e9      -0.5", "1.0e9      -0.5|0.1", "bad.dat:6: LINE TYPES BA/-zeta"},
      {"1.0e9      -0.5", "1.0e9|0.9e9  -0.5", "bad.dat:6: LINE TYPES EA (dynamic): EA_D 9e+08 N must exceed the static EA 1e+09 N"},
      {"1.0e9      -0.5", "1.0e9|2e9  1e6|-0.1", "bad.dat:6: LINE TYPES BA/-zeta (dynamic; a ratio cannot be expressed): must be >= 0"},
      {"1.0e9      -0.5", "1.0e9|2e9  0", "bad.dat:6: LINE TYPES BA/-zeta: a viscoelastic line needs a dashpot"},
      {"1.0e9      -0.5", "SYROPE:s.dat|1e9|0.2  0", "bad.dat:6: LINE TYPES EA: \"SYROPE:s.dat|1e9|0.2\": the Syrope law"},
      {"100        1.0e9", "-100       1.0e9", "bad.dat:6: LINE TYPES Mass/m: must be > 0"},
      {"0.001         dtM", "0.001         dtM\n7             NotAnOption",
       "bad.dat:25: OPTIONS NotAnOption"},
      {"Point4Pz", "Line1N3T", "bad.dat:33: OUTPUTS Line1N3T: only point positions (Point<n>Px, Py, Pz), line-end tensions"},
      {"Point4Pz", "Body1Px", "bad.dat:33: OUTPUTS Body1Px: body 1 does not exist (define it in BODIES)"},
      {"Point4Pz", "FairTen7", "bad.dat:33: OUTPUTS FairTen7: line 7 does not exist"},
      {"Point2Px Point2Pz", "END\nPoint2Px", "bad.dat:35: OUTPUTS Point2Px: a channel after END (line 34)"},
      {"TypeName   Diam", "1   NTypes  - number of LineTypes\nTypeName   Diam",
       "bad.dat:7: version 1 row: expected the 9 columns Name Diam MassDen EA BA/-zeta Can Cat "
       "Cdn Cdt, got 10"},
      {"100           WtrDpth       water depth (m)\n", "", "OPTIONS WtrDpth: required"},
      {"4     Free      -200", "4     Body1     -200", "bad.dat:14: POINTS Volume: a point on a body with volume"},
      {"5     Free      -100    0       -30     0      0       0      0",
       "5     Free      -100    0       -30     0      0",
       "bad.dat:15: POINTS: expected the 9 columns"},
      {"4     Free      -200    0       -40     2000",
       "4     Free      -200    0       -40     0   ",
       "bad.dat:14: POINTS Mass: a free point with volume"},
      {"0.4           FrictionCoefficient", "4             WaveKin\n0.4  FrictionCoefficient",
       "bad.dat:30: OPTIONS WaveKin: WaveKin 4 is not read"},
      {"0.4           FrictionCoefficient", "50            FricDamp\n0.4  FrictionCoefficient",
       "bad.dat:30: OPTIONS FricDamp: lines 1 and 3 differ in segment length"},
      {"0.4           FrictionCoefficient", "0  StatDynFricScale\n0.4  FrictionCoefficient",
       "bad.dat:30: OPTIONS StatDynFricScale: must be > 0"},
      {"---------------------- OPTIONS",
       "---------------------- RODS ----\nID RodType\n(#) (-)\n1 r\n---------------------- OPTIONS",
       "bad.dat:26: RODS: expected the 11 columns"},
      {"---------------------- OPTIONS",
       "---------------------- WHATEVER ----\n---------------------- OPTIONS",
       "bad.dat:23: section"},
      {"0.4     0.0\n", "0.4     0.0     0.7   0.08  0.18\n", "bad.dat:6: LINE TYPES Cl: \"0.7\""},
      // Units that cannot be right: a diameter in millimetres, a mass per
      // length or an EA no material has on the type's diameter.
      {"chain      0.1     100 ", "chain      76      100 ",
       "bad.dat:6: LINE TYPES Diam: 76 m: diameters are in metres"},
      {"rope       0.1     10 ", "rope       0.1     0.001 ",
       "bad.dat:7: LINE TYPES Mass/m: 0.001 kg/m on a diameter of 0.1 m is a density of 0.127 "
       "kg/m^3, outside 1 to 100000"},
      {"2.0e8      3.0e6", "2.0       3.0e6",
       "bad.dat:7: LINE TYPES EA: 2 N over the area of a 0.1 m diameter is a Young's modulus "
       "of 255 Pa, outside 1000 to 1e+13 Pa"},
      // Values the deck's syntax allows but the scene's ranges refuse: the
      // scene's message, led by the deck's line.
      {"450       30 ", "450       3000000 ",
       "bad.dat:19 (its line type on line 6): cables[0].elements: must be in"},
      {"2000   1.5 ", "1e12   1.5 ", "bad.dat:14: bodies[0].mass"},
  };
  for (const Case& c : cases) {
    const std::string message = Refusal(Edited(c.from, c.to));
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected \"" << c.expected << "\" in: " << message;
  }
}

// A line type whose EA names a file (MoorDyn's nonlinear line type): the
// file's knots after its three header lines become the TABLE law's, the
// nominal EA is MoorDyn's (the last tension over the last strain), which
// the negative BA's damping ratio scales as for a constant EA.
constexpr char kPolyTable[] = R"(Strain Tension
(-)    (N)
-----------
0.0    0.0
0.01   1.0e6
0.02   3.0e6
)";

absl::StatusOr<std::string> PolyFile(std::string_view name) {
  if (name == "poly.txt") return std::string(kPolyTable);
  return absl::NotFoundError(absl::StrCat("no file ", std::string(name)));
}

TEST(MoorDynDeckTest, TensionStrainTableFileBecomesTheTableLaw) {
  const std::string deck = Edited("1.0e9      -0.5", "poly.txt   -0.5");
  absl::StatusOr<v1::Scene> scene = SceneFromMoorDyn(deck, "t.dat", PolyFile);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const v1::Cable& chain = CableNamed(*scene, "line1");
  EXPECT_EQ(chain.axial_law(), v1::TABLE);
  EXPECT_EQ(std::vector<double>(chain.tension_table().strains().begin(),
                                chain.tension_table().strains().end()),
            (std::vector<double>{0, 0.01, 0.02}));
  EXPECT_EQ(std::vector<double>(chain.tension_table().tensions().begin(),
                                chain.tension_table().tensions().end()),
            (std::vector<double>{0, 1e6, 3e6}));
  const double area = kPi * 0.1 * 0.1 / 4, ea = 3e6 / 0.02;
  EXPECT_NEAR(chain.youngs_modulus() * area, ea, 1e-6 * ea);
  // BA = zeta (L / N) sqrt(EA m), axial_time = BA / EA.
  const double ba = 0.5 * (450.0 / 30) * std::sqrt(ea * 100);
  EXPECT_NEAR(chain.damping().axial_time(), ba / ea, 1e-9 * ba / ea);
  // The rope keeps its constant EA.
  EXPECT_EQ(CableNamed(*scene, "line2").axial_law(), v1::ENGINEERING);

  // Bad tables are refused naming the deck's line and the file's row.
  struct Case {
    std::string table, expected;
  };
  const Case cases[] = {
      {"a\nb\nc\n0 0\n0.02 1e6\n0.01 2e6\n", "bad.dat:6: LINE TYPES EA: poly.txt:6: strain 0.01"},
      {"a\nb\nc\n0 0\n0.01 2e6\n0.02 1e6\n", "bad.dat:6: LINE TYPES EA: poly.txt:6: tension 1e6"},
      {"a\nb\nc\n0 5\n0.01 2e6\n", "poly.txt:4: tension 5 at zero strain"},
      {"a\nb\nc\n-0.01 0\n0.01 2e6\n", "poly.txt:4: strain -0.01 < 0"},
      {"a\nb\nc\n0 0\n0.01 x\n", "poly.txt:5: expected a strain and a tension"},
      {"a\nb\nc\n0.01 2e6\n", "at least two knots"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<v1::Scene> bad =
        SceneFromMoorDyn(deck, "bad.dat", [&](std::string_view) -> absl::StatusOr<std::string> {
          return c.table;
        });
    ASSERT_FALSE(bad.ok()) << c.table;
    EXPECT_NE(bad.status().message().find(c.expected), std::string::npos)
        << "expected \"" << c.expected << "\" in: " << bad.status().message();
  }
  absl::StatusOr<v1::Scene> missing = SceneFromMoorDyn(
      Edited("1.0e9      -0.5", "other.txt  -0.5"), "bad.dat", PolyFile);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("bad.dat:6: LINE TYPES EA: \"other.txt\": cannot "
                                            "read"),
            std::string::npos)
      << missing.status();
  // Viscoelastic and Syrope laws stay refused.
  EXPECT_NE(Refusal(Edited("1.0e9      -0.5", "poly.txt|2e9 -0.5")).find("viscoelastic"),
            std::string::npos);
}

// MoorDyn's optional 11th to 13th line-type columns (vortex-induced
// vibration) read when their lift coefficient is 0, '#' comments, and a
// SOLVER OPTIONS header.
TEST(MoorDynDeckTest, ReadsOptionalColumnsCommentsAndSolverOptions) {
  std::string text = Edited("0.4     0.0\n", "0.4     0.0     0.0   0.08  0.18  # no VIV\n");
  text = absl::StrReplaceAll(text, {{"----- OPTIONS", "----- SOLVER OPTIONS"}});
  const v1::Scene s = Read(text);
  EXPECT_EQ(s.cables_size(), 4);
  EXPECT_DOUBLE_EQ(s.fluid().water_depth(), 100);
}

// Degenerate placements are laid without a search that never ends, a
// division by zero or a fold: a slack line from an anchor straight below
// its fairlead, and one whose two ends coincide.
TEST(MoorDynDeckTest, LaysDegeneratePlacements) {
  std::string text =
      Edited("1     Fixed     400     0       -100", "1     Fixed     0       0       -100");
  text = absl::StrReplaceAll(
      text, {{"2     Vessel    0       0       -5", "2     Vessel    0       0       0"}});
  // (Read also converts the scene: no corner folds back by more than
  // scenes allow, 135 degrees; a V here would turn by 154.)
  const v1::Scene s = Read(text);
  const v1::Cable& chain = CableNamed(s, "line1");
  ASSERT_EQ(chain.points_size(), 4);  // a U: 450 m between ends 100 m apart
  for (const v1::Vec3& p : chain.points())
    EXPECT_TRUE(std::isfinite(p.x()) && std::isfinite(p.z()));
  const v1::Scene t =
      Read(Edited("3     Fixed     -300    0       -100", "3     Fixed     -200    0       -40"));
  const v1::Cable& rope = CableNamed(t, "line2");
  ASSERT_EQ(rope.points_size(), 5);  // a square loop of side 150 m / 4, 0.1 % long
  EXPECT_DOUBLE_EQ(rope.points(1).z(), -40 - 150 * 1.001 / 4);
}

// A slack line from an anchor on the bed to a free point 60 m up and 100 m
// away, 175 m long: the corner on the bed where the two legs add up to the
// length lies 13.5 m beyond the free point (100 u + sqrt(100^2 u^2 + 60^2)
// = 75, u = 0.135), so the rising leg folds back by 103 degrees, which a
// scene allows. Until 28 November 2026 such a line was laid as a V whose
// corner lay 26 m inside the bed (MoorDyn's BodiesAndRods.dat: 46 m).
TEST(MoorDynDeckTest, LaysALineFoldingBackOverItsBedRunOnTheBed) {
  const v1::Scene s = Read(
      Edited("2     rope       3        4         150", "2     rope       3        4         175"));
  const v1::Cable& rope = CableNamed(s, "line2");
  ASSERT_EQ(rope.points_size(), 3);
  const v1::Vec3& c = rope.points(1);
  std::printf("corner (%.9g, %.9g) m\n", c.x(), c.z());
  EXPECT_NEAR(c.z(), -100, 1e-12);
  EXPECT_NEAR(c.x(), -300 + 100 * 1.135, 1e-9);
  const double legs =
      std::hypot(c.x() + 300, c.z() + 100) + std::hypot(-200 - c.x(), -40 - c.z());
  EXPECT_NEAR(legs, 175, 1e-9);
}

TEST(MoorDynDeckTest, RecognisesDecksByNameOrContents) {
  EXPECT_TRUE(IsMoorDynDeck("a/b/mooring.dat", ""));
  EXPECT_TRUE(IsMoorDynDeck("lines.txt", kDeck));
  EXPECT_FALSE(IsMoorDynDeck("scene.json", kDeck));
  EXPECT_FALSE(IsMoorDynDeck("scene.txt", "{\"name\": \"x\"}"));
  EXPECT_FALSE(IsMoorDynDeck("scene.txtpb", kDeck));
  // A deck of rods alone has no LINE TYPES section; it is still a deck, and is read (and its
  // rods refused by name) rather than parsed as a text-format scene.
  EXPECT_TRUE(IsMoorDynDeck("rods.txt", "--- MoorDyn Input File ---\nrods\n--- ROD TYPES ---\n"));
  EXPECT_TRUE(IsMoorDynDeck("rods.txt", "title\n------ ROD TYPES ------\n"));
  EXPECT_FALSE(IsMoorDynDeck("scene.txt", "name: \"x\"\ncables { length: 1 }\n"));
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/moordyn_", ::getpid(), "_", name));
  std::ofstream(path) << text;
  return path;
}

using testing::Cli;

TEST(MoorDynDeckTest, CliImportWritesTheSceneAndRefusesABadDeckWithExit2) {
  const std::string deck = WriteTemp("deck.dat", kDeck);
  const std::string json =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/moordyn_", ::getpid(), ".json"));
  std::string out, err;
  ASSERT_EQ(Cli({"import", deck, "--out", json}, &out, &err), 0) << err;
  const absl::StatusOr<v1::Scene> back = ReadSceneFile(json);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->cables_size(), 4);
  EXPECT_EQ(back->cables(0).axial_law(), v1::ENGINEERING);
  const std::string bad = WriteTemp("bad.dat", Edited("1     chain      1", "1     cable      1"));
  EXPECT_EQ(Cli({"import", bad, "--out", json}, &out, &err), 2);
  EXPECT_NE(err.find(":19: LINES LineType"), std::string::npos) << err;
  EXPECT_EQ(Cli({"run", bad}, &out, &err), 2);
  EXPECT_NE(err.find(":19: LINES LineType"), std::string::npos) << err;
  EXPECT_EQ(Cli({"import", deck}, &out, &err), 2);  // --out is required
}

// A taut single line, statics by `cablesim run` on a .txt deck (MoorDyn's
// own inputs are .txt): the run succeeds.
// A taut wire (CliRunsATxtDeck, CliReadsATableFileBesideTheDeck).
constexpr char kTautDeck[] = R"(--------------------- MoorDyn Input File ------------------------------------
A taut wire
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
wire       0.05    20         5.0e8      -0.8        0          1.2    1.0    0.0     0.0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       0       -50     0      0       0      0
2     Vessel    30      0       -5      0      0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     wire       1        2         53.9      10      -
---------------------- OPTIONS -----------------------------------------
50            WtrDpth       water depth (m)
------------------------- need this line --------------------------------------
)";

TEST(MoorDynDeckTest, CliRunsATxtDeck) {
  const std::string deck = WriteTemp("taut.txt", kTautDeck);
  std::string out, err;
  EXPECT_EQ(Cli({"run", deck}, &out, &err), 0) << err;
  EXPECT_NE(out.find("\"status\":\"ok\""), std::string::npos) << out;
}

// The CLI reads a table file beside the deck (MoorDyn's base path).
TEST(MoorDynDeckTest, CliReadsATableFileBesideTheDeck) {
  const std::string dir =
      testing::Scratch(absl::StrCat(::testing::TempDir(), "/moordyn_table_", ::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir + "/wire_ea.txt") << "Strain Tension\n(-) (N)\n---\n0 0\n0.002 1e6\n"
                                         "0.01 6e6\n";
  const std::string deck_text =
      absl::StrReplaceAll(kTautDeck, {{"5.0e8      -0.8", "wire_ea.txt -0.8"}});
  ASSERT_NE(deck_text, kTautDeck);
  std::ofstream(dir + "/taut.dat") << deck_text;
  std::string out, err;
  EXPECT_EQ(Cli({"run", dir + "/taut.dat"}, &out, &err), 0) << err;
  EXPECT_NE(out.find("\"status\":\"ok\""), std::string::npos) << out;
  EXPECT_EQ(Cli({"import", dir + "/taut.dat", "--out", dir + "/taut.json"}, &out, &err), 0)
      << err;
  std::ifstream json(dir + "/taut.json");
  const std::string imported((std::istreambuf_iterator<char>(json)),
                             std::istreambuf_iterator<char>());
  EXPECT_NE(imported.find("\"TABLE\""), std::string::npos) << imported;
}

TEST(MoorDynDeckTest, ServiceReadsSceneMoorDynAndRefusesTwoScenes) {
  const absl::StatusOr<v1::Scene> s = SceneOrDeckOfRequest(false, v1::Scene{}, "", kDeck);
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ(s->cables_size(), 4);
  const absl::StatusOr<v1::Scene> both = SceneOrDeckOfRequest(false, v1::Scene{}, "{}", kDeck);
  ASSERT_FALSE(both.ok());
  EXPECT_NE(both.status().message().find("scene_moordyn"), std::string::npos);
  const absl::StatusOr<v1::Scene> bad =
      SceneOrDeckOfRequest(false, v1::Scene{}, "", Edited("1     chain      1", "1     cable      1"));
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("scene_moordyn:19: LINES LineType"), std::string::npos)
      << bad.status();
}

}  // namespace
}  // namespace cablesim
