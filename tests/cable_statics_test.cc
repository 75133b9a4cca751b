// STATIC analysis of pure cables (bending NONE or a negligible EI) against
// the elastic catenary, computed here by quadrature from the same axial law
// as the element: Green-Lagrange strain eps = (lam^2 - 1) / 2 with energy
// EA eps^2 / 2 per unit unstretched length, so the tension at stretch lam
// is T = d(EA eps^2 / 2)/d lam = EA lam (lam^2 - 1) / 2 (Irvine, Cable
// Structures, 1981, ch. 2, with this constitutive law in place of Hooke's).
//
// With unstretched arc length s from the left support, weight w per unit
// unstretched length and point weights W_k at s_k, the horizontal tension H
// is constant, the vertical one is V(s) = V0 - w s - sum_{s_k < s} W_k, and
//   dx/ds = lam(T) H / T,   dy/ds = lam(T) V / T,   T = sqrt(H^2 + V^2).
// H and V0 are found by Newton so that the cable ends at the right support.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/elements/ancf_cable_element.h"
#include "engine/scene/scene.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

struct Catenary {
  double length, ea, w;          // m, N, N/m
  std::vector<double> load_s;    // point weights [N] at arc lengths [m]
  std::vector<double> load_w;

  // Stretch at tension T: solves EA lam (lam^2 - 1) / 2 = T (increasing).
  double Stretch(double t) const {
    double lam = 1 + t / ea;
    for (int i = 0; i < 50; ++i) {
      const double g = ea * lam * (lam * lam - 1) / 2 - t;
      const double dg = ea * (3 * lam * lam - 1) / 2;
      lam -= g / dg;
      if (std::abs(g) <= 1e-15 * (ea + t)) break;
    }
    return lam;
  }

  // Position at arc length s for (H, V0), by composite Gauss-Legendre
  // quadrature (4 points, `panels` panels between point loads).
  void At(double h, double v0, double s_end, double* x, double* y, int panels = 400) const {
    static const double xi[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                 0.8611363115940526};
    static const double wt[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                 0.3478548451374538};
    // Breakpoints: 0, the point loads before s_end, s_end.
    std::vector<double> br{0};
    for (double s : load_s)
      if (s > 0 && s < s_end) br.push_back(s);
    br.push_back(s_end);
    *x = *y = 0;
    for (size_t b = 0; b + 1 < br.size(); ++b) {
      const double a = br[b], len = (br[b + 1] - a) / panels;
      for (int p = 0; p < panels; ++p) {
        const double mid = a + (p + 0.5) * len;
        for (int g = 0; g < 4; ++g) {
          const double s = mid + 0.5 * len * xi[g];
          double v = v0 - w * s;
          for (size_t k = 0; k < load_s.size(); ++k)
            if (load_s[k] < s) v -= load_w[k];
          const double t = std::hypot(h, v);
          const double lam = Stretch(t);
          *x += 0.5 * len * wt[g] * lam * h / t;
          *y -= 0.5 * len * wt[g] * lam * v / t;
        }
      }
    }
  }

  // H and V0 so that the end is at (span, dh).
  void Solve(double span, double dh, double* h, double* v0) const {
    double total = w * length;
    for (double wk : load_w) total += wk;
    *h = total;
    *v0 = total / 2;
    for (int it = 0; it < 100; ++it) {
      double x, y;
      At(*h, *v0, length, &x, &y);
      const double fx = x - span, fy = y - dh;
      if (std::hypot(fx, fy) < 1e-13 * span) return;
      const double dh_ = 1e-7 * *h, dv = 1e-7 * std::max(std::abs(*v0), *h);
      double xh, yh, xv, yv;
      At(*h + dh_, *v0, length, &xh, &yh);
      At(*h, *v0 + dv, length, &xv, &yv);
      const double a = (xh - x) / dh_, b = (xv - x) / dv, c = (yh - y) / dh_, d = (yv - y) / dv;
      const double det = a * d - b * c;
      double sh = (d * fx - b * fy) / det, sv = (-c * fx + a * fy) / det;
      // Keep H positive.
      while (*h - sh <= 0) sh /= 2;
      *h -= sh;
      *v0 -= sv;
    }
    ADD_FAILURE() << "the catenary reference did not converge";
  }
};

// A 1.2 m steel cable of 1 cm diameter between pins at (0, 0) and
// (1, dh), its midpoint probed.
std::string CableScene(int elements, const std::string& bending, const std::string& points,
                       double length, const std::string& extra_cable = "",
                       const std::string& extra_scene = "") {
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": %.17g, "elements": %d, "density": 7850,
                "youngs_modulus": 2e11, "area": 7.853981633974483e-05,
                "second_moment": 1e-14, "bending": "%s", "points": %s %s}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
               {"type": "PIN", "a": {"cable": "c", "s": %.17g}} %s],
    "probes": [{"name": "mid", "cable": "c", "s": %.17g}],
    "solver": {"analysis": "STATIC"}})",
                         length, elements, bending, points, extra_cable, length, extra_scene,
                         length / 2);
}

constexpr double kEa = 2e11 * 7.853981633974483e-05;
constexpr double kW = 7850 * 7.853981633974483e-05 * 9.81;

// The probe's equilibrium against the catenary at s = L/2: the sag (depth
// below the chord there) within 0.2 % (the issue's bound; a 24-element
// cubic mesh is far closer, so this also catches a wrong axial law).
void ExpectCatenary(const std::string& json, double length, double dh,
                    const std::vector<double>& load_s = {},
                    const std::vector<double>& load_w = {}, Eigen::Vector3d* mid_out = nullptr) {
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Eigen::Vector3d mid = sink.frames().back().probes[0].position_m;
  if (mid_out != nullptr) *mid_out = mid;
  Catenary cat{length, kEa, kW, load_s, load_w};
  double h, v0, x, y;
  cat.Solve(1.0, dh, &h, &v0);
  cat.At(h, v0, length / 2, &x, &y);
  const double chord_y = dh * x;  // chord from (0, 0) to (1, dh)
  const double sag = chord_y - y;
  const double got = chord_y - mid.y();
  std::printf("catenary sag %.9g m, cablesim %.9g m (relative %.2e), x %.9g vs %.9g, %lld "
              "Newton iterations\n",
              sag, got, std::abs(got - sag) / sag, x, mid.x(),
              static_cast<long long>(s.newton_iterations));
  EXPECT_NEAR(got, sag, 2e-3 * sag);
  EXPECT_NEAR(mid.x(), x, 2e-3 * sag);
}

const char kVPolyline[] = R"([{"x": 0, "y": 0}, {"x": 0.5, "y": -0.33166247903554}, {"x": 1, "y": 0}])";

// From a slack V (its vertex a kink holding 1.7 kJ of spurious strain at
// the first load increment) to the catenary: the pseudo-transient Newton
// of StaticSolver, about 380 iterations for the 10 increments.
TEST(CableStaticsTest, SlackPolylineWithNegligibleBendingHangsAsTheCatenary) {
  ExpectCatenary(CableScene(24, "EXACT", kVPolyline, 1.2), 1.2, 0);
}

TEST(CableStaticsTest, SlackPolylineWithLinearBendingHangsAsTheCatenary) {
  ExpectCatenary(CableScene(24, "LINEAR", kVPolyline, 1.2), 1.2, 0);
}

TEST(CableStaticsTest, SlackPolylineWithoutBendingStiffness) {
  ExpectCatenary(CableScene(24, "NONE", kVPolyline, 1.2), 1.2, 0);
}

// cables[].gauss_points: the strain energy integrated with 3 points per
// element (reduced; the default 5 integrate the Green-Lagrange energy
// exactly) hangs as the same catenary within the same bound, and
// differently from 5 points (so the field reaches the elements); 6 too.
// (4 points, refused by the scene's validation, hung this V 1.9 % too
// deep and asymmetric: a spurious equilibrium.)
TEST(CableStaticsTest, FewerGaussPointsStillHangAsTheCatenary) {
  EXPECT_EQ(CableSpec().gauss_points, AncfCableElement<3>::kDefaultGaussPoints);
  Eigen::Vector3d five, three, six;
  ExpectCatenary(CableScene(24, "NONE", kVPolyline, 1.2), 1.2, 0, {}, {}, &five);
  ExpectCatenary(CableScene(24, "NONE", kVPolyline, 1.2, R"(, "gauss_points": 3)"), 1.2, 0, {},
                 {}, &three);
  ExpectCatenary(CableScene(24, "NONE", kVPolyline, 1.2, R"(, "gauss_points": 6)"), 1.2, 0, {},
                 {}, &six);
  EXPECT_NE(three, five);
  EXPECT_NE(six, five);
}

TEST(CableStaticsTest, SupportsAtDifferentHeights) {
  const char pts[] = R"([{"x": 0, "y": 0}, {"x": 0.4, "y": -0.3}, {"x": 1, "y": 0.3}])";
  ExpectCatenary(CableScene(24, "EXACT", pts, 1.2), 1.2, 0.3);
}

TEST(CableStaticsTest, TautStraightStartWithoutBendingStiffness) {
  // Laid straight and stretched (0.999 m between pins 1 m apart).
  const char pts[] = R"([{"x": 0, "y": 0}, {"x": 1, "y": 0}])";
  ExpectCatenary(CableScene(24, "NONE", pts, 0.999), 0.999, 0);
  ExpectCatenary(CableScene(24, "EXACT", pts, 0.999), 0.999, 0);
}

// Laid straight and compressed (1.2 m of cable on the 1 m chord, 220 kJ of
// strain): an unstable equilibrium at load factor 0 whose stiffness is
// negative. StaticSolver leaves it by the flipped-pivot step and reaches the
// catenary by lengthened Newton steps (about 400 and 510 iterations; before,
// it failed after 500 iterations at each of 12 bisections of the first
// increment).
TEST(CableStaticsTest, CompressedStraightStartHangsAsTheCatenary) {
  const char pts[] = R"([{"x": 0, "y": 0}, {"x": 1, "y": 0}])";
  ExpectCatenary(CableScene(24, "NONE", pts, 1.2), 1.2, 0);
  ExpectCatenary(CableScene(24, "EXACT", pts, 1.2), 1.2, 0);
}

// A 2 kg point-like body pinned at the midpoint of a cable without bending
// stiffness: the catenary with a point weight there, kinked under the body.
// The node under the body is split (multibody_model.cc, Build): with slopes
// continuous there the kink was rounded off over one element and the sag
// came out 1.5 % short at 24 elements (0.3258 m against 0.3307 m),
// converging only at first order in the element length.
TEST(CableStaticsTest, BodyHangingAtTheMiddleKinksTheCable) {
  const std::string body = R"(, "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 1e-4,
      "y": 1e-4, "z": 1e-4}, "position": {"x": 0.5, "y": -0.33166247903554}}])";
  const std::string pin =
      R"(, {"type": "PIN", "a": {"cable": "c", "s": 0.6}, "b": {"body": "b"}})";
  std::string json = CableScene(24, "NONE", kVPolyline, 1.2, "", pin);
  json.insert(json.rfind('}'), body);
  ExpectCatenary(json, 1.2, 0, {0.6}, {2 * 9.81});
}

// The same with a point load instead of a body, and a cable laid straight
// and stretched: the load kinks it too.
TEST(CableStaticsTest, PointLoadKinksATautCable) {
  const char pts[] = R"([{"x": 0, "y": 0}, {"x": 1, "y": 0}])";
  const std::string load = R"(, "loads": [{"at": {"cable": "c", "s": 0.4995}, "force": {"y": -19.62}}])";
  std::string json = CableScene(24, "NONE", pts, 0.999);
  json.insert(json.rfind('}'), load);
  ExpectCatenary(json, 0.999, 0, {0.4995}, {19.62});
}

// A split node counts once, and its two halves meet at an angle: the
// cable's slope just left and right of the body differ in sign.
TEST(CableStaticsTest, SplitNodeCountsOnceAndCarriesTwoSlopes) {
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1.2, "elements": 24, "density": 7850,
                "youngs_modulus": 2e11, "area": 7.853981633974483e-05, "bending": "NONE",
                "points": %s}],
    "bodies": [{"name": "b", "mass": 2, "inertia": {"x": 1e-4, "y": 1e-4, "z": 1e-4},
                "position": {"x": 0.5, "y": -0.33166247903554}}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}},
               {"type": "PIN", "a": {"cable": "c", "s": 1.2}},
               {"type": "PIN", "a": {"cable": "c", "s": 0.6}, "b": {"body": "b"}}],
    "probes": [{"name": "l", "cable": "c", "s": 0.59}, {"name": "r", "cable": "c", "s": 0.61}],
    "solver": {"analysis": "STATIC"}})",
                                           kVPolyline);
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  EXPECT_EQ(s.info.nodes, 25 + 2);  // 24 elements, plus a node at each probe
  ASSERT_FALSE(sink.frames().empty());
  const auto& p = sink.frames().back().probes;
  // 1 cm either side of the body (at x = 0.5, sag 0.3307 m), each probe is
  // on its own leg rising away from it: the legs meet at an angle, which
  // continuous slopes at the body's node would round off.
  const double sag = 0.330727;
  const Eigen::Vector2d left = p[0].position_m.head<2>() - Eigen::Vector2d(0.5, -sag);
  const Eigen::Vector2d right = p[1].position_m.head<2>() - Eigen::Vector2d(0.5, -sag);
  EXPECT_LT(left.x(), 0);
  EXPECT_GT(right.x(), 0);
  // Both rise at the leg's slope, about 35 degrees, right from the body.
  EXPECT_GT(left.y() / -left.x(), 0.5);
  EXPECT_GT(right.y() / right.x(), 0.5);
}

TEST(CableStaticsTest, TwoThousandElementChainStretchesUnderItsWeight) {
  // Hanging 10 m steel chain: the tip drops by rho g L^2 / (2 E) to first
  // order in the strain (1.9e-5 m); the Green-Lagrange law adds a relative
  // 3/2 eps ~ 3e-6 of that, below the 1e-3 tolerance.
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 10, "elements": 2000, "direction": {"y": -1},
                "density": 7850, "youngs_modulus": 2e11, "diameter": 0.01}],
    "joints": [{"type": "PIN", "a": {"cable": "c", "s": 0}}],
    "probes": [{"name": "tip", "cable": "c", "s": 10}],
    "solver": {"analysis": "STATIC"}})"),
                             &sink);
  ASSERT_FALSE(sink.frames().empty());
  const double drop = -10 - sink.frames().back().probes[0].position_m.y();
  const double expected = 7850 * 9.81 * 100 / (2 * 2e11);
  EXPECT_NEAR(drop, expected, 1e-3 * expected);
  EXPECT_EQ(s.rejected_steps, 0);
}

// What a mooring engineer reads: the forces at the anchor and at the
// fairlead (output.reactions) and the line tension (output.tension),
// against the same elastic catenary between supports at different heights.
// The support at s = 0 holds the cable with (-H, V0), the one at s = L with
// (H, w L - V0); the tension at s is T(s) = sqrt(H^2 + (V0 - w s)^2).
// Tolerance 2e-3 of the largest tension, the bound the sag is held to above:
// H and V0 follow the shape, so a shape within it gives forces within it
// (a reaction read at the wrong end, or a tension with its sign or stretch
// factor wrong, is off by tens of percent). The vertical reactions balance
// the weight exactly (statics), to 1e-9 of it.
TEST(CableStaticsTest, SupportsCarryTheCatenaryEndForcesAndTheLineItsTension) {
  // Bending NONE: with the scenes' EI of 2e-3 N m^2 the bending length
  // sqrt(EI / T) is 2.6 cm, half an element, and the supports' boundary
  // layers move H by 0.5 %: physics the catenary leaves out, not an error.
  {
    const char pts[] = R"([{"x": 0, "y": 0}, {"x": 0.4, "y": -0.3}, {"x": 1, "y": 0.3}])";
    std::string json = CableScene(24, "NONE", pts, 1.2);
    const std::string solver = R"("solver": {"analysis": "STATIC"})";
    json.replace(json.find(solver), solver.size(),
                 R"("output": {"reactions": true, "tension": true, "shape": true}, )" + solver);
    CollectingSink sink;
    RunOk(SceneFromJson(json), &sink);
    ASSERT_FALSE(sink.frames().empty());
    const Frame& f = sink.frames().back();
    Catenary cat{1.2, kEa, kW, {}, {}};
    double h, v0;
    cat.Solve(1.0, 0.3, &h, &v0);
    const double w_total = kW * 1.2;
    const double t_max = std::max(std::hypot(h, v0), std::hypot(h, w_total - v0));
    const double tol = 2e-3 * t_max;
    ASSERT_EQ(f.reactions.size(), 2u);
    const Eigen::Vector3d anchor = f.reactions[0].force, fairlead = f.reactions[1].force;
    std::printf("H %.9g N, V0 %.9g N; anchor (%.9g, %.9g), fairlead (%.9g, %.9g)\n", h, v0,
                anchor.x(), anchor.y(), fairlead.x(), fairlead.y());
    EXPECT_NEAR(anchor.x(), -h, tol);
    EXPECT_NEAR(anchor.y(), v0, tol);
    EXPECT_NEAR(fairlead.x(), h, tol);
    EXPECT_NEAR(fairlead.y(), w_total - v0, tol);
    EXPECT_NEAR(anchor.y() + fairlead.y(), w_total, 1e-9 * w_total);
    // The probe at mid-length.
    ASSERT_EQ(f.probe_tensions.size(), 1u);
    EXPECT_NEAR(f.probe_tensions[0], std::hypot(h, v0 - kW * 0.6), tol);
    // Along the line, node by node (the shape's tension).
    const std::vector<double>& node_s = sink.info().node_s;
    ASSERT_EQ(f.node_tensions.size(), node_s.size());
    for (size_t k = 0; k < node_s.size(); ++k) {
      EXPECT_NEAR(f.node_tensions[k], std::hypot(h, v0 - kW * node_s[k]), tol) << node_s[k];
    }
  }
}

TEST(CableStaticsTest, AFreeCableHasNoEquilibriumAndSaysSo) {
  CollectingSink sink;
  auto summary = RunScene(SceneFromJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "c", "length": 1, "elements": 4, "density": 1000,
                "youngs_modulus": 1e9, "diameter": 0.01}],
    "solver": {"analysis": "STATIC", "load_steps": 1, "max_step_halvings": 1}})"),
                          &sink);
  ASSERT_TRUE(summary.ok()) << summary.status();
  EXPECT_EQ(summary->status, "failed");
  EXPECT_NE(summary->error.find("no static equilibrium"), std::string::npos) << summary->error;
}

}  // namespace
}  // namespace cablesim
