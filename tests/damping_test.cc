// Damping (MultibodyModel::DampingForce): Kelvin-Voigt and Rayleigh damping
// of a cable against the logarithmic decrement of a damped oscillator, body
// damping against the exponential decay of a free body, and the energy
// report's balance energy.total + energy.damped (+ the stepper's own
// dissipation) = the initial energy.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/elements/ancf_cable_element.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/linear/skyline_ldlt.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

constexpr double kPi = std::numbers::pi;

// The sample scene: a 1 m steel rod (d = 10 mm) clamped at x = 0, released
// straight under gravity, so it oscillates about its static sag (7.7 mm at
// the tip) almost purely in its first mode: the static deflection under a
// uniform load projects onto the second mode with an amplitude of about
// 1.4 % of the first's, which Kelvin-Voigt damping (ratio proportional to
// omega, 6.3 times the first mode's) removes within the first period.
Scene DampedCantilever(const std::string& damping, const std::string& analysis,
                       const std::string& integrator = "GENERALIZED_ALPHA") {
  auto proto = ReadSceneFile(absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/damped-cantilever.json"));
  EXPECT_TRUE(proto.ok()) << proto.status();
  v1::Scene p = *proto;
  auto* d = p.mutable_cables(0)->mutable_damping();
  d->Clear();
  auto parsed = ParseSceneJson(absl::StrCat("{\"cables\": [{\"damping\": ", damping, "}]}"));
  EXPECT_TRUE(parsed.ok()) << parsed.status();
  *d = parsed->cables(0).damping();
  v1::Analysis a = v1::DYNAMIC;
  EXPECT_TRUE(v1::Analysis_Parse(analysis, &a));
  p.mutable_solver()->set_analysis(a);
  v1::Integrator i = v1::GENERALIZED_ALPHA;
  EXPECT_TRUE(v1::Integrator_Parse(integrator, &i));
  p.mutable_solver()->set_integrator(i);
  if (integrator == "IMPLICIT_EULER") p.mutable_solver()->clear_rho_infinity();
  auto scene = SceneFromProto(p);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : Scene{};
}

// The first circular frequency about the static sag [rad/s], and the tip's
// static height [m].
double FirstOmega() {
  CollectingSink sink;
  const RunSummary s = RunOk(DampedCantilever("{}", "MODAL"), &sink);
  EXPECT_FALSE(s.frequencies_hz.empty());
  return s.frequencies_hz.empty() ? 0 : 2 * kPi * s.frequencies_hz[0];
}
double StaticTipY() {
  CollectingSink sink;
  RunOk(DampedCantilever("{}", "STATIC"), &sink);
  return sink.frames().back().probes[0].position_m.y();
}

// Positive peaks of y - y0 over the frames, each refined by the parabola
// through the frame at the peak and its two neighbours.
std::vector<double> Peaks(const std::vector<Frame>& frames, double y0) {
  std::vector<double> peaks;
  for (size_t i = 1; i + 1 < frames.size(); ++i) {
    const double a = frames[i - 1].probes[0].position_m.y() - y0;
    const double b = frames[i].probes[0].position_m.y() - y0;
    const double c = frames[i + 1].probes[0].position_m.y() - y0;
    if (b > 0 && b > a && b >= c) peaks.push_back(b - (c - a) * (c - a) / (8 * (c - 2 * b + a)));
  }
  return peaks;
}

// Logarithmic decrement from the peaks, skipping the first two (where the
// second mode may still be present): ln(p_2 / p_n) / (n - 2).
double Decrement(const std::vector<double>& peaks) {
  EXPECT_GE(peaks.size(), 5u);
  if (peaks.size() < 5) return 0;
  const size_t n = peaks.size() - 1;
  return std::log(peaks[2] / peaks[n]) / static_cast<double>(n - 2);
}

// delta = 2 pi zeta / sqrt(1 - zeta^2): the ratio of successive peaks of
// exp(-zeta omega t) cos(omega_d t), omega_d = omega sqrt(1 - zeta^2).
double TheoryDecrement(double zeta) { return 2 * kPi * zeta / std::sqrt(1 - zeta * zeta); }

// Tolerance of the decrement: 0.5 % relative (measured 1.3e-4 with
// Kelvin-Voigt or beta, 9e-5 with alpha). The budget: the step
// (283 per period, omega h = 0.022) changes the trapezoidal rule's
// (generalized-alpha with rho_infinity = 1) period by (omega h)^2 / 12 =
// 4e-5 and its damping ratio by the same order; the sag (0.8 % of the
// length) shifts the frequency by its square, 6e-5; the parabolic peaks
// are exact to (pi / 283)^4. The damping matrix at the sagged (slightly
// curved) state differs from eta K by the curvature squared, 1e-4. All
// together below 1e-3: a factor 2 or a missing term in C is far outside.
constexpr double kDecrementTolerance = 5e-3;

struct DecrementCase {
  const char* damping;
  const char* integrator;  // GENERALIZED_ALPHA or HHT, both at rho_infinity = 1
  // zeta = eta omega / 2 + alpha / (2 omega) for the first (bending) mode,
  // eta the bending retardation time, alpha Rayleigh's mass coefficient.
  double eta_s;
  double alpha_1_s;
};

class DampingDecrementTest : public ::testing::TestWithParam<DecrementCase> {};

TEST_P(DampingDecrementTest, FirstModeDecrementMatchesTheory) {
  const DecrementCase& c = GetParam();
  const double omega = FirstOmega();
  const double y0 = StaticTipY();
  CollectingSink sink;
  const RunSummary s = RunOk(DampedCantilever(c.damping, "DYNAMIC", c.integrator), &sink);
  const double zeta = c.eta_s * omega / 2 + c.alpha_1_s / (2 * omega);
  const double expected = TheoryDecrement(zeta);
  const double measured = Decrement(Peaks(sink.frames(), y0));
  EXPECT_NEAR(measured, expected, kDecrementTolerance * expected)
      << "omega = " << omega << " rad/s, zeta = " << zeta;
  // The energy balance: generalized-alpha with rho_infinity = 1 adds no
  // dissipation of its own on a linear problem, so what the damping did
  // is all the energy lost: E0 = total + damped to the quadrature of the
  // power (trapezoidal, O((omega h)^2) = 5e-4 of the damped work; 2e-3;
  // measured 2e-4).
  ASSERT_GT(s.energy_damped, 0);
  EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 2e-3 * s.energy_damped);
  EXPECT_NEAR(s.energy_dissipated, 0, 2e-3 * s.energy_damped);
  // energy.damped never decreases, frame by frame.
  for (size_t i = 1; i < sink.frames().size(); ++i)
    ASSERT_GE(sink.frames()[i].energy.damped, sink.frames()[i - 1].energy.damped) << i;
}

INSTANTIATE_TEST_SUITE_P(
    KelvinVoigtAndRayleigh, DampingDecrementTest,
    ::testing::Values(
        // Kelvin-Voigt bending alone; zeta = 0.02.
        DecrementCase{"{\"bending_time\": 9e-4}", "GENERALIZED_ALPHA", 9e-4, 0},
        // Rayleigh's beta (the material stiffness: also damps the axial
        // modes, which the first mode does not involve to first order).
        // HHT at rho_infinity = 1 (alpha = 0) is the same trapezoidal rule.
        DecrementCase{"{\"rayleigh_beta\": 9e-4}", "HHT", 9e-4, 0},
        // Rayleigh's alpha (zeta 0.017) with half the Kelvin-Voigt bending
        // (zeta 0.01; it removes the second mode, which alpha alone would
        // damp 6.3 times less than the first) and axial Kelvin-Voigt
        // (which the bending mode does not see).
        DecrementCase{
            "{\"rayleigh_alpha\": 1.5, \"bending_time\": 4.5e-4, \"axial_time\": 1e-3}",
            "GENERALIZED_ALPHA", 4.5e-4, 1.5}));

// Backward Euler's own damping stays apart: its energy_dissipated is
// positive (the stepper removes energy of its own, about omega h / 2 in
// damping ratio), and the three parts add up to the initial energy by
// construction of the summary; energy.damped is then the work of the
// damping along the computed (more strongly decaying) motion, so less
// than with the second-order stepper.
TEST(DampingTest, BackwardEulerDissipationStaysApart) {
  CollectingSink be_sink, ga_sink;
  const RunSummary be =
      RunOk(DampedCantilever("{\"bending_time\": 9e-4}", "DYNAMIC", "IMPLICIT_EULER"), &be_sink);
  const RunSummary ga = RunOk(DampedCantilever("{\"bending_time\": 9e-4}", "DYNAMIC"), &ga_sink);
  EXPECT_GT(be.energy_dissipated, 0.1 * be.energy_damped);
  EXPECT_LT(be.energy_damped, ga.energy_damped);
  EXPECT_NEAR(be.energy_final + be.energy_damped + be.energy_dissipated, be.energy_initial,
              1e-12 * be.energy_initial + 1e-15);
}

// Without damping the column is there and zero.
TEST(DampingTest, UndampedSceneReportsZeroDampedWork) {
  CollectingSink sink;
  const RunSummary s = RunOk(DampedCantilever("{}", "DYNAMIC"), &sink);
  EXPECT_EQ(s.energy_damped, 0);
  for (const Frame& f : sink.frames()) ASSERT_EQ(f.energy.damped, 0);
}

// A free body with linear and angular damping, moving along x at v0 and
// spinning about its principal z axis at w0: v = v0 exp(-c t / m),
// w = w0 exp(-c_r t / I_z), in the planar and the spatial model.
class BodyDampingTest : public ::testing::TestWithParam<const char*> {};

TEST_P(BodyDampingTest, VelocitiesDecayExponentially) {
  const double m = 2, iz = 0.25, c = 1, cr = 0.05, v0 = 1, w0 = 2, duration = 1;
  const Scene scene = SceneFromJson(absl::StrCat(R"({
    "model": ")", GetParam(), R"(",
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 0.1, "y": 0.2, "z": 0.25},
                "damping": {"linear": 1, "angular": 0.05}}],
    "probes": [{"name": "c", "body": "b"}, {"name": "p", "body": "b", "point": {"x": 0.5}}],
    "initial_velocity": {"linear": {"x": 1}, "angular": {"z": 2}},
    "solver": {"duration": 1, "step": 1e-3, "integrator": "GENERALIZED_ALPHA",
               "rho_infinity": 1}})"));
  CollectingSink sink;
  const RunSummary s = RunOk(scene, &sink);
  const Frame& last = sink.frames().back();
  const double v = last.probes[0].velocity_m_s.x();
  const double w = (last.probes[1].velocity_m_s - last.probes[0].velocity_m_s).norm() / 0.5;
  // Tolerance 1e-5 relative: the decay itself is integrated far better
  // (the second-order steppers' error on exp(-t / tau), tau = m / c = 2 s
  // and I_z / c_r = 5 s, is below 1e-10 at h = 1 ms), but the spin moves the
  // body's axes along their unit-length constraints, which the steppers
  // follow to second order: (w0 h)^2 = 4e-6 (measured 9e-7 on w, 1e-8 on
  // v). A missing factor 2 in the spatial c / 2 per axis is 10 % at t = 1 s.
  EXPECT_NEAR(v, v0 * std::exp(-c * duration / m), 1e-5 * v0);
  EXPECT_NEAR(w, w0 * std::exp(-cr * duration / iz), 1e-5 * w0);
  // The damped work is the kinetic energy lost (to the same (w0 h)^2;
  // measured 5e-7).
  const double e0 = 0.5 * m * v0 * v0 + 0.5 * iz * w0 * w0;
  EXPECT_NEAR(s.energy_initial, e0, 1e-12 * e0);
  EXPECT_NEAR(s.energy_final + s.energy_damped, e0, 1e-5 * e0);
}

INSTANTIATE_TEST_SUITE_P(PlanarAndSpatial, BodyDampingTest,
                         ::testing::Values("PLANAR", "SPATIAL"));

// At a straight unstressed configuration the material stiffness is the
// whole tangent, so Kelvin-Voigt damping with both times eta is eta K_T
// there (what Rayleigh's beta means), in the plane and in space.
template <int D>
void ExpectStraightDampingIsEtaTangent(const Eigen::Matrix<double, D, 1>& direction) {
  const double l = 0.3, eta = 2e-3;
  AncfCableElement<D> element(l, 1e6, 50, BendingModel::kExact);
  typename AncfCableElement<D>::Coords e, f;
  const Eigen::Matrix<double, D, 1> d = direction.normalized();
  Eigen::Matrix<double, D, 1> origin;
  origin.setConstant(0.7);
  e << origin, d, origin + l * d, d;
  typename AncfCableElement<D>::Matrix c = AncfCableElement<D>::Matrix::Zero(),
                                       k = AncfCableElement<D>::Matrix::Zero();
  f.setZero();
  element.ElasticForce(e, &f, &k);
  element.AddDampingMatrix(e, eta, eta, &c);
  // Relative to |K|: the two are assembled from the same Gauss points, so
  // only rounding separates them.
  EXPECT_LE((c - eta * k).cwiseAbs().maxCoeff(), 1e-12 * eta * k.cwiseAbs().maxCoeff());
  EXPECT_LE((c - c.transpose()).cwiseAbs().maxCoeff(), 1e-14 * c.cwiseAbs().maxCoeff());
}

TEST(DampingMatrixTest, StraightElementDampingIsEtaTimesTangent) {
  ExpectStraightDampingIsEtaTangent<2>(Eigen::Vector2d(1, 2));
  ExpectStraightDampingIsEtaTangent<3>(Eigen::Vector3d(1, 2, 3));
}

// Kelvin-Voigt damping does not see rigid motion in the plane, however
// stretched and bent the element: C v = 0 for v a translation or a
// rotation (rdot = omega perp(r), r'dot = omega perp(r')).
TEST(DampingMatrixTest, PlanarRigidMotionIsNotDamped) {
  const double l = 0.3, radius = 0.5, stretch = 1.05;
  AncfCableElement<2> element(l, 1e6, 50, BendingModel::kExact);
  // An arc of radius 0.5 m through l / radius rad, its slopes of length 1.05.
  AncfCableElement<2>::Coords e, translation, rotation;
  const double a = l / radius;
  const Eigen::Vector2d r0(radius, 0), r1(radius * std::cos(a), radius * std::sin(a));
  const Eigen::Vector2d t0(0, stretch), t1(-stretch * std::sin(a), stretch * std::cos(a));
  e << r0, t0, r1, t1;
  auto perp = [](const Eigen::Vector2d& v) { return Eigen::Vector2d(-v.y(), v.x()); };
  translation << 1, 2, 0, 0, 1, 2, 0, 0;
  rotation << perp(r0), perp(t0), perp(r1), perp(t1);
  AncfCableElement<2>::Matrix c = AncfCableElement<2>::Matrix::Zero();
  element.AddDampingMatrix(e, 1e-3, 1e-3, &c);
  const double scale = c.cwiseAbs().maxCoeff();
  EXPECT_LE((c * translation).cwiseAbs().maxCoeff(), 1e-13 * scale * 2);
  EXPECT_LE((c * rotation).cwiseAbs().maxCoeff(), 1e-13 * scale * 2);
  // And it does damp a stretching rate (the check can fail).
  AncfCableElement<2>::Coords stretching;
  stretching << 0, 0, t0, 0, 0, t1;
  EXPECT_GT(stretching.dot(c * stretching), 1e-3 * scale * stretching.squaredNorm());
}

// The model's damping tangent is d(-f)/d(zdot) on the unknowns (f is
// linear in the rates, so a difference quotient is exact to rounding), and
// the dissipated power is -zdot . f, on a spatial cable carrying a damped
// cylinder.
TEST(DampingMatrixTest, ModelTangentIsMinusForceDerivativeInRates) {
  Scene scene = SceneFromJson(R"({
    "model": "SPATIAL", "gravity": {"y": -9.81},
    "cables": [{"name": "cable", "points": [{"x": 0}, {"x": 0.3, "y": 0.1}, {"x": 0.5, "z": 0.1}],
                "elements": 6, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01,
                "damping": {"axial_time": 1e-3, "bending_time": 2e-3, "rayleigh_alpha": 0.5,
                            "rayleigh_beta": 1e-4}}],
    "bodies": [{"name": "cyl", "cylinder": {"diameter": 0.04, "height": 0.1}, "density": 1000,
                "position": {"x": 0.55, "z": 0.1}, "damping": {"linear": 0.3, "angular": 0.02}}],
    "joints": [{"type": "PIN", "a": {"cable": "cable", "s": 0}},
               {"type": "PIN", "a": {"cable": "cable", "s": 0.5611767402951557},
                "b": {"body": "cyl", "point": {"x": -0.05}}}],
    "solver": {"duration": 1}})");
  auto built = MultibodyModel::Build(scene);
  ASSERT_TRUE(built.ok()) << built.status();
  MultibodyModel& model = *built;
  ASSERT_TRUE(model.has_damping());
  const int n = model.dofs(), nq = model.coordinates();
  Eigen::VectorXd q(nq), qd(nq), zdot = Eigen::VectorXd::LinSpaced(n, -1, 1.3);
  for (int i = 0; i < n; ++i) zdot(i) += 0.5 * std::sin(3.0 * i);
  model.ToFull(model.initial_z(), &q);
  model.RateToFull(zdot, &qd);
  EXPECT_GT(model.DampingPower(q, qd), 0);
  // The force is linear in the rates: a difference quotient of step 1 is
  // exact but for rounding.
  double size = 0;
  const double worst = testing::DampingTangentError(model, zdot, 1.0, &size);
  EXPECT_GT(size, 0);
  EXPECT_LE(worst, 1e-12 * size);
}

// Bad input names the field.
TEST(DampingTest, NegativeDampingIsRejectedByName) {
  auto cable = ParseSceneJson(R"({"cables": [{"name": "c", "length": 1, "density": 1000,
      "youngs_modulus": 1e9, "diameter": 0.01, "damping": {"bending_time": -1}}]})");
  ASSERT_TRUE(cable.ok());
  auto s = SceneFromProto(*cable);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("cables[0].damping.bending_time"), std::string::npos)
      << s.status();
  auto body = ParseSceneJson(R"({"bodies": [{"name": "b", "mass": 1,
      "inertia": {"x": 1, "y": 1, "z": 1}, "damping": {"angular": -2}}]})");
  ASSERT_TRUE(body.ok());
  s = SceneFromProto(*body);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("bodies[0].damping.angular"), std::string::npos)
      << s.status();
}

}  // namespace
}  // namespace cablesim
