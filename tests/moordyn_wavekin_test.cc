// MoorDyn's wave and current kinematics options (WaveKin, Currents) read
// from MoorDyn's own test decks (tests/data/moordyn_wavekin, unchanged)
// into the scene's fluid fields, each deck's scene run (its STATIC
// analysis as imported, then a short DYNAMIC run that feels the waves and
// currents); the scene's new fields refused naming the field; bad
// kinematics files refused naming the deck's line and the file's row.

#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "convert/moordyn_deck.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/forces/waves.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

std::string DataPath(const std::string& deck) {
  return absl::StrCat(CABLESIM_SOURCE_DIR, "/tests/data/moordyn_wavekin/", deck);
}

v1::Scene Import(const std::string& deck) {
  absl::StatusOr<v1::Scene> proto = ReadSceneFile(DataPath(deck));
  EXPECT_TRUE(proto.ok()) << deck << ": " << proto.status();
  return proto.ok() ? *proto : v1::Scene();
}

// The deck's own analysis (STATIC), then `seconds` of DYNAMIC from rest in
// the waves and currents: both finish.
void RunsBothWays(const std::string& deck, double seconds) {
  v1::Scene proto = Import(deck);
  absl::StatusOr<Scene> scene = SceneFromProto(proto);
  ASSERT_TRUE(scene.ok()) << deck << ": " << scene.status();
  testing::CollectingSink statics;
  testing::RunOk(*scene, &statics);
  EXPECT_FALSE(statics.frames().empty()) << deck;
  if (!(seconds > 0)) return;
  proto.mutable_solver()->set_analysis(v1::DYNAMIC);
  proto.mutable_solver()->set_duration(seconds);
  absl::StatusOr<Scene> dynamic = SceneFromProto(proto);
  ASSERT_TRUE(dynamic.ok()) << deck << ": " << dynamic.status();
  testing::CollectingSink sink;
  testing::RunOk(*dynamic, &sink);
  ASSERT_FALSE(sink.frames().empty()) << deck;
  EXPECT_NEAR(sink.frames().back().t, seconds, 1e-9) << deck;
}

// WaveKin 2: wave_frequencies.txt's rows (omega, Re A, Im A) summed as
// MoorDyn's inverse FFT does, |A| cos(omega t - k x + arg A): the four
// non-zero rows become components of amplitude |A| and phase -arg A
// (the elevation at the origin at t = 0 is |A| cos(arg A)).
TEST(MoorDynWaveKinTest, WaveKin2ReadsTheFrequencies) {
  const v1::Scene s = Import("wavekin_2/wavekin_2.txt");
  const v1::Waves& w = s.fluid().waves();
  ASSERT_EQ(w.components_size(), 4);
  const double omega[] = {0.2, 0.25, 0.4, 0.45}, amplitude[] = {0.5, 0.2, 1.0, 0.5},
               phase[] = {0, 0, -kPi / 2, -kPi / 2};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(w.components(i).angular_frequency(), omega[i], 1e-12) << i;
    EXPECT_NEAR(w.components(i).amplitude(), amplitude[i], 1e-12) << i;
    EXPECT_NEAR(w.components(i).phase(), phase[i], 1e-12) << i;
    EXPECT_EQ(w.components(i).direction().x(), 1) << i;
  }
  // Currents 1: current_profile.txt, z from -51 to 5 m: depth = -z.
  ASSERT_EQ(s.fluid().current_profile_size(), 57);
  EXPECT_EQ(s.fluid().current_profile(0).depth(), -5);
  EXPECT_EQ(s.fluid().current_profile(56).depth(), 51);
  // z = -49 m: 0.03125 m/s.
  EXPECT_NEAR(s.fluid().current_profile(54).velocity().x(), 0.03125, 1e-12);
}

// WaveKin 7: the same rows summed as |A| sin(omega t - k x + arg A):
// wave_surface's one row (0.4 rad/s, A = 5i) is 5 cos(0.4 t - k x), the
// component of amplitude 5 and phase pi/2 - pi/2 = 0.
TEST(MoorDynWaveKinTest, WaveKin7ReadsTheFrequencies) {
  const v1::Scene s = Import("wave_surface/wave_surface.txt");
  ASSERT_EQ(s.fluid().waves().components_size(), 1);
  const v1::Waves::Component& c = s.fluid().waves().components(0);
  EXPECT_NEAR(c.amplitude(), 5, 1e-12);
  EXPECT_NEAR(c.angular_frequency(), 0.4, 1e-12);
  EXPECT_NEAR(c.phase(), 0, 1e-12);
}

// WaveKin 3: wave_elevation.txt as the elevation series, resampled every
// dtWave (0.15 s), harmonics above 0.5 Hz dropped (MoorDyn's cutoff).
TEST(MoorDynWaveKinTest, WaveKin3ReadsTheElevationSeries) {
  const v1::Scene s = Import("wavekin_2/wavekin_3.txt");
  const v1::Waves::ElevationSeries& e = s.fluid().waves().elevation_series();
  EXPECT_EQ(e.times_size(), 101);
  EXPECT_EQ(e.elevations_size(), 101);
  EXPECT_EQ(e.interval(), 0.15);
  EXPECT_NEAR(e.cutoff_frequency(), kPi, 1e-15);
  // The file is one period (15 s) of 1 m at 2 pi / 15 rad/s, starting at
  // 0 and rising: one component, sin(omega t) = cos(omega t - pi/2).
  absl::StatusOr<Scene> scene = SceneFromProto(s);
  ASSERT_TRUE(scene.ok()) << scene.status();
  WaveField field(Eigen::Vector3d::UnitZ(), 0, scene->fluid.water_depth_m, 9.80665, 0);
  const ElevationSeriesSpec& spec = scene->fluid.waves.elevation_series.at(0);
  EXPECT_EQ(field.AddElevationSeries(spec.times_s, spec.elevations_m, spec.interval_s,
                                     spec.cutoff_rad_s, spec.direction),
            1);
  EXPECT_NEAR(field.components()[0].omega_rad_s, 2 * kPi / 15, 1e-12);
  EXPECT_NEAR(field.components()[0].amplitude_m, 1, 1e-9);
  EXPECT_NEAR(field.components()[0].phase_rad, kPi / 2, 1e-9);
}

// Currents 2: current_profile_dynamic.txt (42 depths, 60 times, ux and uy
// columns) as a current grid with one x and one y; Currents 5:
// current_profile_4d.txt's 11 x 2 x 36 x 2 nodes, every row read (MoorDyn
// starts at the file's seventh line and so leaves its first node, -5 m/s,
// at 0).
TEST(MoorDynWaveKinTest, DynamicAnd4dCurrentsBecomeGrids) {
  for (const char* deck : {"wavekin_2/wavekin_2_curr2.txt", "wavekin_3/test_dynamic_currents.txt"}) {
    const v1::Fluid::CurrentGrid g = Import(deck).fluid().current_grid();
    EXPECT_EQ(g.x_size(), 1) << deck;
    EXPECT_EQ(g.z_size(), 42) << deck;
    EXPECT_EQ(g.times_size(), 60) << deck;
    ASSERT_EQ(g.velocities_size(), 42 * 60) << deck;
    // z = -41 m at t = 1 s: 0.10452846326765346 m/s.
    EXPECT_NEAR(g.velocities(1).x(), 0.10452846326765346, 1e-15) << deck;
  }
  const v1::Fluid::CurrentGrid g = Import("wavekin_4/hanging_lines.txt").fluid().current_grid();
  EXPECT_EQ(g.x_size(), 11);
  EXPECT_EQ(g.y_size(), 2);
  EXPECT_EQ(g.z_size(), 36);
  EXPECT_EQ(g.times_size(), 2);
  ASSERT_EQ(g.velocities_size(), 1584);
  EXPECT_EQ(g.velocities(0).x(), -5);
  EXPECT_EQ(g.velocities(1).x(), -3.5);
}

// WaveKin 1 (the calling program sets the kinematics): still water.
TEST(MoorDynWaveKinTest, WaveKin1IsStillWater) {
  for (const char* deck :
       {"wavekin_wave_1.txt", "wavekin_current_1.txt", "lowe_and_langley_2006/line.txt"}) {
    const v1::Scene s = Import(deck);
    EXPECT_FALSE(s.fluid().has_waves()) << deck;
    EXPECT_FALSE(s.fluid().has_current_grid()) << deck;
    EXPECT_EQ(s.fluid().current_profile_size(), 0) << deck;
  }
}

// Every deck imports and runs its STATIC analysis; those with waves or
// currents also run 0.1 s of DYNAMIC in them (wave_surface's lines lie in
// the still level, and its DYNAMIC start fails with or without its waves:
// its STATIC only).
TEST(MoorDynWaveKinTest, EveryDeckRuns) {
  for (const char* deck : {"wavekin_2/wavekin_2.txt", "wavekin_2/wavekin_2_curr2.txt",
                           "wavekin_2/wavekin_2_curr5.txt", "wavekin_2/wavekin_3.txt",
                           "wavekin_2/wavekin_3_curr2.txt", "wavekin_2/wavekin_3_curr5.txt",
                           "wavekin_3/test_dynamic_currents.txt", "wavekin_4/hanging_lines.txt"})
    RunsBothWays(deck, 0.1);
  for (const char* deck : {"wave_surface/wave_surface.txt", "wavekin_wave_1.txt",
                           "wavekin_current_1.txt", "lowe_and_langley_2006/line.txt"})
    RunsBothWays(deck, 0);
}

// A deck of one line whose kinematics files come from `files`.
constexpr char kDeck[] = R"(MoorDyn v2 input file
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
chain      0.1      20.0       5.0e8      -0.5        0          1.0    1.0    0.0     0.0
---------------------- POINT PROPERTIES --------------------------------
ID    Type      X       Y       Z       Mass    Volume      CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)    (m^3)       (m^2)  (-)
1     Fixed     -100    0       -50     0       0           0      0
2     Coupled   0       0       -5      0       0           0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1      chain     1        2         120       20      -
---------------------- OPTIONS -----------------------------------------
50            WtrDpth       water depth (m)
WAVES         WaveKin
CURRENTS      Currents
------------------------- need this line --------------------------------------
)";

std::string Refusal(const std::string& waves, const std::string& currents,
                    const std::string& file) {
  const std::string deck =
      absl::StrReplaceAll(kDeck, {{"WAVES     ", waves}, {"CURRENTS  ", currents}});
  absl::StatusOr<v1::Scene> s =
      SceneFromMoorDyn(deck, "bad.dat", [&](std::string_view) -> absl::StatusOr<std::string> {
        return file;
      });
  return s.ok() ? "accepted" : std::string(s.status().message());
}

TEST(MoorDynWaveKinTest, BadKinematicsRefusedNamingTheLineAndRow) {
  struct Case {
    std::string waves, currents, file, expected;
  };
  const Case cases[] = {
      {"4", "0", "", "bad.dat:17: OPTIONS WaveKin: WaveKin 4 is not read"},
      {"6", "0", "", "WaveKin 6 is not read"},
      {"0", "7", "", "bad.dat:18: OPTIONS Currents: Currents 7 is not one of"},
      {"7", "0", "0.1 0 0\n0.4 1 0\n", "wave_frequencies.txt:1: the first frequency must be 0"},
      {"7", "0", "0 0 0\n0.4 1 0\n0.3 1 0\n", "wave_frequencies.txt:3: frequencies must increase"},
      {"7", "0", "0 0.5 0\n0.4 1 0\n", "wave_frequencies.txt:1: a non-zero amplitude at 0 rad/s"},
      {"7", "0", "0 0 0\n0.4 1 x\n", "wave_frequencies.txt:2: \"x\" is not a number"},
      {"7", "0", "0 0 0\n0.4 1 0 9\n", "the direction (4th column) must be in"},
      {"2", "0", "0 0 0\n0.2 0 0\n0.4 1 0\n", "a non-zero amplitude at the last frequency"},
      {"3", "0", "0 0\n1 0.5\n1 0.7\n", "fluid.waves.elevation_series.times: must increase"},
      {"3", "0", "-1 0\n1 0.5\n", "wave_elevation.txt:1: the series must start at t >= 0"},
      {"0", "1", "h\nh\nh\n-10 0.5\n-10 0.7\n", "current_profile.txt:5: a depth given twice"},
      {"0", "2", "h\nh\nh\nh\n-10 -5\n\n0 1\n", "current_profile_dynamic.txt:7: expected at least 3"},
      {"0", "2", "h\nh\nh\nh\n-5 -10\n\n0 1 1\n", "fluid.current_grid.z: must increase"},
      {"0", "5", "2 1 1 1\n0 1\n0\n0\n0\n0 0 0 0 1 0 0\n",
       "current_profile_4d.txt: 1 of the grid's 2 nodes have no row"},
      {"0", "5", "1 1 1 1\n0\n0\n0\n0\n0 0 0 0 1 0 0\n0 0 0 0 1 0 0\n",
       "current_profile_4d.txt:7: a node given twice"},
      {"0", "5", "1 1 1 1\n0\n0\n0\n0\n3 0 0 0 1 0 0\n", "x = 3 is not on the grid's axis"},
  };
  for (const Case& c : cases) {
    const std::string message = Refusal(c.waves, c.currents, c.file);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "expected \"" << c.expected << "\" in: " << message;
  }
  // Without a directory (the service's scene_moordyn) the files cannot be
  // read: refused naming the option.
  absl::StatusOr<v1::Scene> text_only =
      SceneFromMoorDyn(absl::StrReplaceAll(kDeck, {{"WAVES     ", "7"}, {"CURRENTS  ", "0"}}),
                       "deck.dat");
  ASSERT_FALSE(text_only.ok());
  EXPECT_NE(text_only.status().message().find("deck.dat:17: OPTIONS WaveKin: "
                                              "wave_frequencies.txt cannot be read here"),
            std::string::npos)
      << text_only.status();
}

// FricDamp and StatDynFricScale select MoorDyn's friction law: FricDamp
// per node over the segment length (120 m / 20 = 6 m) per unit length;
// without them the regularised law stays.
TEST(MoorDynWaveKinTest, FricDampSelectsMoorDynsFrictionLaw) {
  const std::string plain = absl::StrReplaceAll(
      kDeck, {{"WAVES     ", "0"}, {"CURRENTS      Currents", "0 Currents\n0.5  FrictionCoefficient"}});
  absl::StatusOr<v1::Scene> regular = SceneFromMoorDyn(plain, "a.dat");
  ASSERT_TRUE(regular.ok()) << regular.status();
  EXPECT_EQ(regular->seabed().friction_law(), v1::Seabed::FRICTION_LAW_UNSPECIFIED);
  absl::StatusOr<v1::Scene> moordyn = SceneFromMoorDyn(
      absl::StrReplaceAll(plain, {{"FrictionCoefficient", "FrictionCoefficient\n20000 FricDamp\n"
                                                          "1.5 StatDynFricScale"}}),
      "b.dat");
  ASSERT_TRUE(moordyn.ok()) << moordyn.status();
  EXPECT_EQ(moordyn->seabed().friction_law(), v1::Seabed::MOORDYN);
  EXPECT_NEAR(moordyn->seabed().friction_damping(), 20000.0 / 6, 1e-9);
  EXPECT_EQ(moordyn->seabed().static_friction_scale(), 1.5);
  EXPECT_EQ(moordyn->seabed().friction_axial(), 0.5);
  // MoorDyn's default FricDamp (200) when only the scale is given.
  absl::StatusOr<v1::Scene> scaled = SceneFromMoorDyn(
      absl::StrReplaceAll(plain, {{"FrictionCoefficient", "FrictionCoefficient\n2 mc"}}), "c.dat");
  ASSERT_TRUE(scaled.ok()) << scaled.status();
  EXPECT_NEAR(scaled->seabed().friction_damping(), 200.0 / 6, 1e-12);
  EXPECT_TRUE(SceneFromProto(*moordyn).ok());
}

// The scene's new fields, each bad value refused naming the field.
TEST(MoorDynWaveKinTest, SceneFieldsRefusedNamingTheField) {
  auto base = [] {
    v1::Scene s = Import("wavekin_wave_1.txt");
    s.mutable_fluid()->clear_waves();
    return s;
  };
  struct Case {
    std::function<void(v1::Scene*)> edit;
    std::string expected;
  };
  const Case cases[] = {
      {[](v1::Scene* s) { s->mutable_fluid()->mutable_waves()->add_components()->set_amplitude(1); },
       "fluid.waves.components[0].angular_frequency: must be > 0"},
      {[](v1::Scene* s) {
         auto* c = s->mutable_fluid()->mutable_waves()->add_components();
         c->set_amplitude(-1);
         c->set_angular_frequency(1);
       },
       "fluid.waves.components[0].amplitude: must be >= 0"},
      {[](v1::Scene* s) {
         auto* e = s->mutable_fluid()->mutable_waves()->mutable_elevation_series();
         e->add_times(0);
         e->add_elevations(0);
       },
       "fluid.waves.elevation_series.times: at least 2"},
      {[](v1::Scene* s) {
         auto* e = s->mutable_fluid()->mutable_waves()->mutable_elevation_series();
         e->add_times(0);
         e->add_times(1);
         e->add_elevations(0);
       },
       "fluid.waves.elevation_series.elevations: one per time"},
      {[](v1::Scene* s) {
         auto* e = s->mutable_fluid()->mutable_waves()->mutable_elevation_series();
         for (double t : {0.0, 2.0, 1.0}) {
           e->add_times(t);
           e->add_elevations(0);
         }
       },
       "fluid.waves.elevation_series.times: must increase"},
      {[](v1::Scene* s) {
         auto* e = s->mutable_fluid()->mutable_waves()->mutable_elevation_series();
         for (double t : {0.0, 100.0}) {
           e->add_times(t);
           e->add_elevations(0);
         }
         e->set_interval(0.001);
       },
       "fluid.waves.elevation_series.interval: cuts the series into"},
      {[](v1::Scene* s) {
         auto* g = s->mutable_fluid()->mutable_current_grid();
         g->add_x(0);
         g->add_y(0);
         g->add_z(0);
       },
       "fluid.current_grid.times: at least one value"},
      {[](v1::Scene* s) {
         auto* g = s->mutable_fluid()->mutable_current_grid();
         g->add_x(0);
         g->add_x(1);
         g->add_y(0);
         g->add_z(0);
         g->add_times(0);
         g->add_velocities();
       },
       "fluid.current_grid.velocities: expected x * y * z * times = 2 velocities, got 1"},
      {[](v1::Scene* s) {
         auto* g = s->mutable_fluid()->mutable_current_grid();
         g->add_x(0);
         g->add_y(0);
         g->add_z(0);
         g->add_times(0);
         g->add_velocities();
         s->mutable_fluid()->add_current_profile()->set_depth(1);
       },
       "fluid.current_grid: give fluid.current_profile or fluid.current_grid, not both"},
      {[](v1::Scene* s) { s->mutable_seabed()->set_friction_law(v1::Seabed::MOORDYN); },
       "seabed.friction_damping: must be > 0"},
      {[](v1::Scene* s) { s->mutable_seabed()->set_friction_damping(5); },
       "seabed.friction_damping: only with seabed.friction_law MOORDYN"},
      {[](v1::Scene* s) {
         s->mutable_seabed()->set_friction_law(v1::Seabed::MOORDYN);
         s->mutable_seabed()->set_friction_damping(5);
         s->mutable_seabed()->set_static_friction_scale(-1);
       },
       "seabed.static_friction_scale: must be > 0"},
  };
  for (const Case& c : cases) {
    v1::Scene s = base();
    c.edit(&s);
    absl::StatusOr<Scene> scene = SceneFromProto(s);
    ASSERT_FALSE(scene.ok()) << c.expected;
    EXPECT_NE(scene.status().message().find(c.expected), std::string::npos)
        << "expected \"" << c.expected << "\" in: " << scene.status().message();
  }
}

}  // namespace
}  // namespace cablesim
