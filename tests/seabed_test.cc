// The seabed (engine/forces/seabed.h) against closed forms:
//  - a mooring line pinned at an anchor on a frictionless bed and at a
//    fairlead, in statics, against the elastic catenary with seabed contact
//    (Irvine, Cable Structures, 1981, sec. 2.3; the form MAP and MoorPy
//    solve): with H the horizontal tension, V the fairlead's vertical
//    tension, w the weight per length and L_B = L - V / w on the bed,
//      x_F = L_B + (H / w) asinh(V / H) + H L / EA,
//      z_F = (H / w) (sqrt(1 + (V / H)^2) - 1) + V^2 / (2 EA w);
//    the touchdown point lies at x = L_B (1 + H / EA);
//  - a chain dropped flat comes to rest at penetration w / k with
//    energy.total + energy.damped at its initial value;
//  - a line whose fairlead oscillates steps as a free cable does.

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/forces/contact_point.h"
#include "engine/forces/seabed.h"
#include "engine/output/frame_columns.h"
#include "engine/model/multibody_model.h"
#include "engine/analysis/static_solver.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using testing::CollectingSink;
using testing::RunOk;
using testing::SceneFromJson;

// A chain-like line: 100 m, w = 7850 * 0.01 * 9.81 = 770 N/m, EA = 5e7 N.
constexpr double kLength = 100, kArea = 0.01, kDensity = 7850, kG = 9.81;
constexpr double kEa = 5e7;
constexpr double kW = kDensity * kArea * kG;
constexpr double kStiffness = 1e8;  // [N/m^2]: sinks w / k = 7.7 um
constexpr double kXf = 85, kZf = 30;

// The closed form: H and V from (x_F, z_F) by Newton on the two equations
// (analytic Jacobian), to 1e-12 relative.
// With seabed friction C_B (MAP's and MoorPy's CB; Masciola, Jonkman and
// Robertson, "Implementation of a multisegmented, quasi-static cable
// model", ISOPE 2013): the tension on the grounded line falls by C_B w per
// metre from the touchdown point toward the anchor, T(s) = max(H - C_B w
// (L_B - s), 0), so the grounded part stretches by int T / EA ds less than
// H L_B / EA, and x_F gains
//   (C_B w / (2 EA)) (-L_B^2 + (L_B - H / (C_B w)) max(L_B - H / (C_B w), 0)).
struct SeabedCatenary {
  double h = 0, v = 0;
  double cb = 0;
  double Lb() const { return kLength - v / kW; }
  // The grounded line's tension at arc length s from the anchor.
  double GroundTension(double s) const { return std::max(h - cb * kW * (Lb() - s), 0.0); }
  void Residual(double hh, double vv, double* fx, double* fz, double xf, double zf) const {
    *fx = kLength - vv / kW + hh / kW * std::asinh(vv / hh) + hh * kLength / kEa - xf;
    if (cb > 0) {
      const double lb = kLength - vv / kW, slack = lb - hh / (cb * kW);
      *fx += cb * kW / (2 * kEa) * (-lb * lb + slack * std::max(slack, 0.0));
    }
    *fz = hh / kW * (std::sqrt(1 + vv * vv / (hh * hh)) - 1) + vv * vv / (2 * kEa * kW) - zf;
  }
  bool Solve(double xf, double zf) {
    h = kW * 20;
    v = kW * 50;
    for (int it = 0; it < 100; ++it) {
      double fx, fz;
      Residual(h, v, &fx, &fz, xf, zf);
      if (std::hypot(fx, fz) < 1e-12 * xf) return true;
      const double dh = 1e-7 * h, dv = 1e-7 * v;
      double fxh, fzh, fxv, fzv;
      Residual(h + dh, v, &fxh, &fzh, xf, zf);
      Residual(h, v + dv, &fxv, &fzv, xf, zf);
      const double a = (fxh - fx) / dh, b = (fxv - fx) / dv, c = (fzh - fz) / dh,
                   d = (fzv - fz) / dv;
      const double det = a * d - b * c;
      double sh = (d * fx - b * fz) / det, sv = (-c * fx + a * fz) / det;
      while (h - sh <= 0 || v - sv <= 0) {
        sh /= 2;
        sv /= 2;
      }
      h -= sh;
      v -= sv;
    }
    return false;
  }
};

// The line from the anchor at (0, -w/k) (the grounded line's own level)
// along the bed, then straight to the fairlead; the polyline is as long as
// the line. `extra` is appended to the scene object.
std::string MooringScene(int elements, const std::string& analysis, const std::string& seabed,
                         const std::string& fairlead_motion = "", const std::string& extra = "",
                         double stiffness = kStiffness) {
  const double y0 = -kW / stiffness;
  // x1 + sqrt((xf - x1)^2 + (zf - y0)^2) = L.
  const double dz = kZf - y0;
  const double x1 = (kLength * kLength - kXf * kXf - dz * dz) / (2 * (kLength - kXf));
  return absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "line", "length": %.17g, "elements": %d, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "second_moment": 1e-14,
                "bending": "NONE",
                "points": [{"x": 0, "y": %.17g}, {"x": %.17g, "y": %.17g},
                           {"x": %.17g, "y": %.17g}]}],
    "joints": [{"type": "PIN", "a": {"cable": "line", "s": 0}},
               {"type": "PIN", "a": {"cable": "line", "s": %.17g} %s}],
    "probes": [{"name": "fairlead", "cable": "line", "s": %.17g}],
    %s
    "solver": {"analysis": "%s" %s}})",
                         kLength, elements, kDensity, kEa / kArea, kArea, y0, x1, y0, kXf, kZf,
                         kLength, fairlead_motion, kLength, seabed, analysis, extra);
}

std::string Bed(double damping = 0, double stiffness = kStiffness) {
  return absl::StrFormat(R"("seabed": {"depth": 0, "stiffness": %.17g, "damping": %.17g},)",
                         stiffness, damping);
}

struct MooringStatics {
  double tension = 0, horizontal = 0, touchdown_x = 0, touchdown_s = 0, vertical_lb = 0;
  double anchor_tension = 0;
  std::vector<double> tension_at;  // at the arc lengths asked for
};

// The tension T = EA lam (lam^2 - 1) / 2 at arc length s.
double TensionAt(const MultibodyModel& model, const Eigen::VectorXd& q, double s) {
  Eigen::Vector3d slope;
  model.CablePosition(q, 0, s, &slope);
  const double lam = slope.norm();
  return kEa * lam * (lam * lam - 1) / 2;
}

// Statics by StaticSolver on the model itself (the fairlead's tension is
// read from the cable's stretch there: T = EA lam (lam^2 - 1) / 2, the
// element's Green-Lagrange law), the touchdown point by bisection on the
// height of the cable's cubic above the bed.
MooringStatics SolveMooring(int elements, const std::string& bed = Bed(),
                            const std::vector<double>& at = {}) {
  MooringStatics out;
  const Scene scene = SceneFromJson(MooringScene(elements, "STATIC", bed));
  auto model = MultibodyModel::Build(scene);
  EXPECT_TRUE(model.ok()) << model.status();
  if (!model.ok()) return out;
  EXPECT_NE(model->seabed(), nullptr);
  StaticSolver solver(&*model, scene.solver);
  for (int k = 1; k <= 10; ++k) {
    const auto stats = solver.Solve(k / 10.0);
    EXPECT_TRUE(stats.converged) << k << ": " << stats.reason;
    if (!stats.converged) return out;
  }
  Eigen::VectorXd q(model->coordinates());
  model->ToFull(solver.z(), &q);
  Eigen::Vector3d slope;
  model->CablePosition(q, 0, kLength, &slope);
  const double lam = slope.norm();
  out.tension = kEa * lam * (lam * lam - 1) / 2;
  out.horizontal = out.tension * slope.x() / lam;
  out.vertical_lb = kLength - out.tension * slope.y() / lam / kW;
  out.anchor_tension = TensionAt(*model, q, 0);
  for (double s : at) out.tension_at.push_back(TensionAt(*model, q, s));
  // Touchdown: the last point in the bed (height < 0) before the line
  // rises; the grounded part lies at -w/k, the suspended part above 0.
  const Seabed& bed = *model->seabed();
  double a = 0, b = kLength;
  EXPECT_LT(bed.Height(model->CablePosition(q, 0, 1.0)), 0);
  for (int i = 0; i < 200 && b - a > 1e-12; ++i) {
    const double m = 0.5 * (a + b);
    (bed.Height(model->CablePosition(q, 0, m)) < 0 ? a : b) = m;
  }
  out.touchdown_s = a;
  out.touchdown_x = model->CablePosition(q, 0, a).x();
  return out;
}

// The fairlead tension, the horizontal tension and the touchdown point of
// the statics against the closed form with the bed at the grounded line's
// level -w/k (z_F measured from there), at 160 elements (0.625 m).
// Measured errors: H 7e-6, T 1e-5 relative (the mesh; they fall by 4 or
// more per halving of the element, TouchdownPointConvergesWithTheMesh),
// so 1e-4 (the axial laws differ, Green-Lagrange in the element and Hooke
// in the closed form, by (3/2) (T/EA)^2 L = 4e-5 m of stretch: far below).
// The length on the bed from the vertical force balance, L - V / w, to
// 0.01 m (measured 6e-4 m). The geometric touchdown point (the last point
// of the cubic in the bed) is ill-conditioned: the line leaves the bed
// tangentially, so a height error d moves it by sqrt(2 H d / w), and a
// cubic cannot follow the jump of curvature (0 to w / H) there, which
// leaves d of order (w / H) h^2 / 16: a shift of order h / 3. So within one
// element length (measured 0.56 m at 160 elements; 0.005 m at 640).
TEST(SeabedTest, MooringStaticsMatchesTheCatenaryWithSeabedContact) {
  SeabedCatenary ref;
  ASSERT_TRUE(ref.Solve(kXf, kZf + kW / kStiffness));
  const double t_ref = std::hypot(ref.h, ref.v);
  const double td_ref = ref.Lb() * (1 + ref.h / kEa);
  const MooringStatics fe = SolveMooring(160);
  std::printf("closed form: H %.3f N, T %.3f N, touchdown x %.4f m (L_B %.4f m)\n", ref.h, t_ref,
              td_ref, ref.Lb());
  std::printf("statics 160 el: H %.3f N, T %.3f N, touchdown x %.4f m, L - V/w %.4f m\n",
              fe.horizontal, fe.tension, fe.touchdown_x, fe.vertical_lb);
  EXPECT_NEAR(fe.tension, t_ref, 1e-4 * t_ref);
  EXPECT_NEAR(fe.horizontal, ref.h, 1e-4 * ref.h);
  EXPECT_NEAR(fe.vertical_lb, ref.Lb(), 0.01);
  EXPECT_NEAR(fe.touchdown_x, td_ref, kLength / 160);
}

// Convergence with the mesh, 10 to 640 elements. The length on the bed
// from the force balance, L - V / w, converges at second order or better
// (each halving of the element at least halves its error; measured 2.0,
// 0.64, 0.10, 0.0097, 5.7e-4, 1.5e-4, 4e-5 m). The geometric touchdown
// point (see above) stays within one element length from 40 elements on
// and reaches 0.02 m at 640 elements (measured 0.005 m); the
// integration splits each element at the roots of its height cubic, so
// the contact is never smeared over an element.
TEST(SeabedTest, TouchdownPointConvergesWithTheMesh) {
  SeabedCatenary ref;
  ASSERT_TRUE(ref.Solve(kXf, kZf + kW / kStiffness));
  const double td_ref = ref.Lb() * (1 + ref.h / kEa);
  const std::vector<int> meshes = {10, 20, 40, 80, 160, 320, 640};
  std::vector<double> err, lb_err;
  for (int n : meshes) {
    const MooringStatics fe = SolveMooring(n);
    err.push_back(std::abs(fe.touchdown_x - td_ref));
    lb_err.push_back(std::abs(fe.vertical_lb - ref.Lb()));
    std::printf("%d elements: touchdown x %.5f m (error %.2e m), L - V/w error %.2e m, H %.4f N, "
                "T %.4f N\n",
                n, fe.touchdown_x, err.back(), lb_err.back(), fe.horizontal, fe.tension);
  }
  for (size_t i = 1; i < meshes.size(); ++i) EXPECT_LE(lb_err[i], 0.5 * lb_err[i - 1]) << i;
  for (size_t i = 2; i < meshes.size(); ++i) EXPECT_LE(err[i], kLength / meshes[i]) << i;
  EXPECT_LT(err.back(), 0.02);
}

// Static friction (seabed.h, default friction_length 1e-5 m): the same
// line, laid straight on the bed from the anchor to x = 62.5 m and then to
// the fairlead, pulled into its catenary by the statics; every grounded
// point moves toward the fairlead
// (by the stretch), so friction is mobilised toward the anchor as the C_B
// closed form assumes. Two coefficients: C_B = 0.1 (the tension falls by
// C_B w L_B = 4.3 kN of 13.8 kN and reaches the anchor) and C_B = 0.5 (it
// reaches zero 19.5 m from the anchor). The fairlead tension, H and the
// tension along the grounded line (anchor, and 10 and 25 m before the
// touchdown) against the closed form, at 160 elements.
// Tolerance: 1e-4 of H (the mesh: 1e-5 measured without friction, above).
// The regularisation mobilises friction only where the displacement from
// the laid line u >> u_s (1e-5 m). Along the sliding line u is the stretch
// (centimetres), so the tension's slope there is C_B w to 1e-6. Where the
// tension reaches zero (C_B = 0.5) u grows as C_B w t^2 / (2 EA) with the
// distance t, so friction is short over about sqrt(2 EA u_s / (C_B w)) =
// 1.6 m, where the tension is about zero anyway: it moves the zero point,
// not the profile. At a pinned anchor still under tension (C_B = 0.1) u
// grows as T_a t / EA, so friction is short over EA u_s / T_a = 0.05 m:
// the anchor's tension is higher by up to C_B w EA u_s / T_a (4 N), which
// its tolerance adds twice. Measured (160 elements): H 0.05 and 0.12 N,
// fairlead 0.43 and 0.65 N, anchor 3.0 and 0.0 N, along the line 0.5-0.75 N.
TEST(SeabedTest, MooringStaticsWithFrictionMatchesTheCatenaryWithCB) {
  for (double cb : {0.1, 0.5}) {
    SeabedCatenary ref;
    ref.cb = cb;
    ASSERT_TRUE(ref.Solve(kXf, kZf + kW / kStiffness));
    const std::vector<double> at = {ref.Lb() - 10, ref.Lb() - 25};
    const MooringStatics fe = SolveMooring(
        160,
        absl::StrFormat(R"("seabed": {"depth": 0, "stiffness": %.17g, "friction_axial": %.17g,
                           "friction_transverse": %.17g},)",
                        kStiffness, cb, cb),
        at);
    const double t_ref = std::hypot(ref.h, ref.v);
    std::printf("C_B %.1f closed form: H %.3f N, T %.3f N, anchor %.3f N, at L_B-10 %.3f N, "
                "at L_B-25 %.3f N (L_B %.4f m)\n",
                cb, ref.h, t_ref, ref.GroundTension(0), ref.GroundTension(at[0]),
                ref.GroundTension(at[1]), ref.Lb());
    std::printf("C_B %.1f statics:     H %.3f N, T %.3f N, anchor %.3f N, at L_B-10 %.3f N, "
                "at L_B-25 %.3f N\n",
                cb, fe.horizontal, fe.tension, fe.anchor_tension, fe.tension_at[0],
                fe.tension_at[1]);
    EXPECT_NEAR(fe.horizontal, ref.h, 1e-4 * ref.h);
    EXPECT_NEAR(fe.tension, t_ref, 1e-4 * ref.h);
    const double anchor = ref.GroundTension(0);
    const double short_friction = anchor > 0 ? cb * kW * kEa * 1e-5 / anchor : 0;
    EXPECT_NEAR(fe.anchor_tension, anchor, 1e-4 * ref.h + 2 * short_friction);
    EXPECT_NEAR(fe.tension_at[0], ref.GroundTension(at[0]), 1e-4 * ref.h);
    EXPECT_NEAR(fe.tension_at[1], ref.GroundTension(at[1]), 1e-4 * ref.h);
  }
}

// The sample three-line buoy (scenes/mooring-three-line-buoy.json: bed
// friction 0.5 along and 1.0 across, initial_state STATIC) on coarse
// meshes. Its statics (tolerance 1e-12) stalled at 10 and 15 elements per
// line: Newton reached the rounding floor in 90 iterations, then stayed
// 3e-12 of the force scale above it for 500 more in every load increment,
// because the floor left out the regularised friction's rounding (its
// tangent, mu N / friction_length, times a few eps |q|: MultibodyModel::
// StaticFriction's roundoff). Now each mesh reaches its equilibrium.
TEST(SeabedFrictionTest, CoarseBuoyMooringReachesItsStaticEquilibrium) {
  for (int elements : {10, 15, 50}) {
    Scene scene = testing::SampleScene("mooring-three-line-buoy.json");
    ASSERT_EQ(scene.solver.initial_state, InitialState::kStatic);
    ASSERT_GT(scene.seabed.friction_axial, 0);
    for (CableSpec& c : scene.cables) c.elements = elements;
    scene.solver.duration_s = scene.solver.step_s;  // the statics and one step
    CollectingSink sink;
    const RunSummary summary = RunOk(scene, &sink);
    // Statics that converge take tens of iterations per load increment;
    // the stalled ones took 500 in each and bisected 12 times.
    EXPECT_LT(summary.newton_iterations, 1000) << elements;
  }
}

// What a mooring engineer reads off the same statics (C_B = 0.1): the
// anchor's and the fairlead's forces (output.reactions) and the tension
// along the line (output.tension with the shape), against the closed form:
// the fairlead holds (H, V), the anchor pulls with the grounded line's
// tension there, T(s) = H - C_B w (L_B - s) on the bed and
// sqrt(H^2 + (w (s - L_B))^2) above it. Tolerances as above: 1e-4 of H
// (the mesh), the anchor's plus twice the short friction there. The
// anchor's node tension also leaves out its element's share of the bed's
// friction, C_B w l / 2 = 24 N (model_outputs.cc, Tensions: a cable's end
// node reads one element; the anchor's reaction is exact). Nodes within
// 2 m of the touchdown point are left out: the closed form's tension has a
// kink there (the bed's support ends) that the mesh rounds over an element
// or two.
TEST(SeabedTest, AnchorAndFairleadForcesAndTheTensionAlongTheLine) {
  const double cb = 0.1;
  SeabedCatenary ref;
  ref.cb = cb;
  ASSERT_TRUE(ref.Solve(kXf, kZf + kW / kStiffness));
  const std::string bed = absl::StrFormat(
      R"("seabed": {"depth": 0, "stiffness": %.17g, "friction_axial": %.17g,
         "friction_transverse": %.17g},
         "output": {"reactions": true, "tension": true, "shape": true},)",
      kStiffness, cb, cb);
  CollectingSink sink;
  RunOk(SceneFromJson(MooringScene(160, "STATIC", bed)), &sink);
  ASSERT_FALSE(sink.frames().empty());
  const Frame& f = sink.frames().back();
  ASSERT_EQ(f.reactions.size(), 2u);
  const double tol = 1e-4 * ref.h;
  const double anchor = ref.GroundTension(0);
  const double short_friction = cb * kW * kEa * 1e-5 / anchor;
  std::printf("anchor force (%.3f, %.3f) N, closed form (%.3f, 0); fairlead (%.3f, %.3f) N, "
              "closed form (%.3f, %.3f)\n",
              f.reactions[0].force.x(), f.reactions[0].force.y(), -anchor,
              f.reactions[1].force.x(), f.reactions[1].force.y(), ref.h, ref.v);
  EXPECT_NEAR(f.reactions[0].force.x(), -anchor, tol + 2 * short_friction);
  EXPECT_NEAR(f.reactions[1].force.x(), ref.h, tol);
  EXPECT_NEAR(f.reactions[1].force.y(), ref.v, tol);
  ASSERT_EQ(f.probe_tensions.size(), 1u);
  EXPECT_NEAR(f.probe_tensions[0], std::hypot(ref.h, ref.v), tol);
  const std::vector<double>& node_s = sink.info().node_s;
  ASSERT_EQ(f.node_tensions.size(), node_s.size());
  double worst = 0;
  int checked = 0;
  for (size_t k = 0; k < node_s.size(); ++k) {
    const double s = node_s[k];
    if (std::abs(s - ref.Lb()) < 2) continue;
    const double expected = s < ref.Lb() ? ref.GroundTension(s)
                                         : std::hypot(ref.h, kW * (s - ref.Lb()));
    const double end_share = cb * kW * (kLength / 160) / 2;
    const double allowed = tol + (s == 0 ? 2 * short_friction + end_share : 0);
    EXPECT_NEAR(f.node_tensions[k], expected, allowed) << "s = " << s;
    worst = std::max(worst, std::abs(f.node_tensions[k] - expected));
    ++checked;
  }
  std::printf("%d nodes: largest tension error %.3f N (H %.1f N)\n", checked, worst, ref.h);
}

// A 10 m chain laid flat 0.1 m above the bed falls, bounces on the damped
// bed and comes to rest sunk by w / k, where its weight balances the bed.
// Generalized-alpha with rho_inf = 1 (the trapezoidal rule, which
// conserves the energy of linear systems: the bed is linear in the
// penetration once the flat chain is in it) closes the balance
// energy.total + energy.damped = initial to 1e-3 of the damped work; the
// only other loss is the step in which the chain enters the bed.
TEST(SeabedTest, ChainDroppedFlatRestsWhereWeightBalancesTheBed) {
  const double k = 1e6, c = 1e4;  // omega = sqrt(k / m) = 113 rad/s, zeta 0.56
  const std::string json = absl::StrFormat(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "chain", "length": 10, "elements": 10, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "second_moment": 1e-14,
                "bending": "NONE",
                "points": [{"x": 0, "y": 0.1}, {"x": 10, "y": 0.1}]}],
    "probes": [{"name": "mid", "cable": "chain", "s": 5}],
    "seabed": {"depth": 0, "stiffness": %.17g, "damping": %.17g},
    "solver": {"analysis": "DYNAMIC", "duration": 1, "step": 5e-4, "output_interval": 0.01,
               "integrator": "GENERALIZED_ALPHA", "rho_infinity": 1}})",
                                           kDensity, kEa / kArea, kArea, k, c);
  CollectingSink sink;
  const RunSummary s = RunOk(SceneFromJson(json), &sink);
  ASSERT_FALSE(sink.frames().empty());
  ASSERT_TRUE(sink.info().contact);
  const Frame& last = sink.frames().back();
  const double rest = -kW / k;  // -7.7e-4 m
  std::printf("rest y %.6e m (w/k %.6e), contact energy %.4f J, damped %.3f J, dissipated %.3e J\n",
              last.probes[0].position_m.y(), rest, last.energy.contact, s.energy_damped,
              s.energy_dissipated);
  // After 1 s (16 time constants 1 / (zeta omega)) the residual motion is
  // e^-63 of the impact: the rest depth to 1e-6 of it.
  EXPECT_NEAR(last.probes[0].position_m.y(), rest, 1e-6 * std::abs(rest));
  // The bed then holds (1/2) k (w/k)^2 per metre: w^2 L / (2 k).
  EXPECT_NEAR(last.energy.contact, kW * kW * 10 / (2 * k), 1e-5 * kW * kW * 10 / (2 * k));
  ASSERT_GT(s.energy_damped, 0);
  EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 1e-3 * s.energy_damped);
}

// The mooring line in motion: the fairlead moves 2 m back and forth along
// x with a period of 10 s, the line starts from its static equilibrium on a
// bed of MoorDyn's stiffness (3e6 Pa times a 0.1 m diameter) with damping.
// At a fixed step of 0.01 s the run needs no step halving (no Newton
// failure), and with adaptive steps it takes no more than 1.25 times the
// steps of the same line without a bed (which then hangs through the bed
// level: a free cable).
TEST(SeabedTest, OscillatingFairleadKeepsTheStepOfAFreeCable) {
  const double k = 3e5;
  const std::string motion =
      R"(, "motion": {"x": {"harmonic": {"amplitude": 2, "frequency": 0.1}}})";
  const std::string fixed_step =
      R"(, "duration": 10, "step": 0.01, "output_interval": 0.5, "initial_state": "STATIC")";
  const std::string adaptive =
      R"(, "duration": 10, "step": 0.01, "output_interval": 0.5, "initial_state": "STATIC",
         "adaptive": true, "tolerance": 1e-3)";
  CollectingSink sink;
  const RunSummary bed = RunOk(
      SceneFromJson(MooringScene(50, "DYNAMIC", Bed(1e4, k), motion, fixed_step, k)), &sink);
  const RunSummary free = RunOk(
      SceneFromJson(MooringScene(50, "DYNAMIC", "", motion, fixed_step, k)), &sink);
  EXPECT_EQ(bed.rejected_steps, 0);
  EXPECT_EQ(bed.steps, 1000);
  const RunSummary bed_a =
      RunOk(SceneFromJson(MooringScene(50, "DYNAMIC", Bed(1e4, k), motion, adaptive, k)), &sink);
  const RunSummary free_a =
      RunOk(SceneFromJson(MooringScene(50, "DYNAMIC", "", motion, adaptive, k)), &sink);
  std::printf("fixed step: bed %lld steps, %lld rejected, %lld Newton iterations; free %lld "
              "Newton iterations; adaptive: bed %lld steps (%lld rejected), free %lld steps "
              "(%lld rejected)\n",
              static_cast<long long>(bed.steps), static_cast<long long>(bed.rejected_steps),
              static_cast<long long>(bed.newton_iterations),
              static_cast<long long>(free.newton_iterations), static_cast<long long>(bed_a.steps),
              static_cast<long long>(bed_a.rejected_steps), static_cast<long long>(free_a.steps),
              static_cast<long long>(free_a.rejected_steps));
  EXPECT_LE(bed_a.steps, 1.25 * free_a.steps);
}

// Columns: a scene with a seabed carries energy.contact after the others;
// one without has no seabed object and no such column.
TEST(SeabedTest, ContactColumnOnlyWithASeabed) {
  const Scene with = SceneFromJson(MooringScene(10, "STATIC", Bed()));
  const Scene without = SceneFromJson(MooringScene(10, "STATIC", ""));
  auto a = MultibodyModel::Build(with);
  auto b = MultibodyModel::Build(without);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->seabed(), nullptr);
  EXPECT_EQ(b->seabed(), nullptr);
  const auto ca = FrameColumns(a->Info()), cb = FrameColumns(b->Info());
  EXPECT_EQ(ca.back(), "energy.contact");
  EXPECT_EQ(ca.size(), cb.size() + 1);
  EXPECT_EQ(FrameReader::Find(cb, "energy.contact"), -1);
}

// The bed's force is the gradient of its energy and its tangent the
// gradient of the force (central differences), on an element crossing the
// bed twice (two contact pieces).
TEST(SeabedTest, ForceAndTangentAreDerivativesOfTheEnergy) {
  SeabedSpec spec;
  spec.enabled = true;
  spec.depth_m = 0.3;
  spec.normal = Eigen::Vector3d(0.1, 1, 0.2).normalized();
  spec.stiffness_n_m2 = 1e5;
  Seabed bed(spec);
  Eigen::Matrix<double, 12, 1> e;
  // A sagging element: ends above the bed, middle below.
  e << 0, 0.1, 0, 1, -2.5, 0.3, 2, 0.05, 0.1, 1, 2.5, -0.2;
  double pieces[2][2];
  ASSERT_EQ(bed.ContactPieces<3>(e, 2.0, pieces), 1);
  e << 0, -0.2, 0, 1, -0.5, 0.3, 2, -0.25, 0.1, 1, 0.6, -0.2;
  const int count = bed.ContactPieces<3>(e, 2.0, pieces);
  ASSERT_GE(count, 1);
  Eigen::Matrix<double, 12, 1> g = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::Matrix<double, 12, 12> hm = Eigen::Matrix<double, 12, 12>::Zero();
  const double u = bed.AddPotential<3>(e, 2.0, &g, &hm);
  ASSERT_GT(u, 0);
  const double d = 1e-6;
  for (int i = 0; i < 12; ++i) {
    Eigen::Matrix<double, 12, 1> ep = e, em = e;
    ep(i) += d;
    em(i) -= d;
    // Central differences: error (d^2/6) U''' plus rounding eps U / d.
    EXPECT_NEAR((bed.Energy<3>(ep, 2.0) - bed.Energy<3>(em, 2.0)) / (2 * d), g(i),
                1e-6 * g.cwiseAbs().maxCoeff())
        << i;
    Eigen::Matrix<double, 12, 1> gp = Eigen::Matrix<double, 12, 1>::Zero(), gm = gp;
    bed.AddPotential<3>(ep, 2.0, &gp, nullptr);
    bed.AddPotential<3>(em, 2.0, &gm, nullptr);
    for (int j = 0; j < 12; ++j)
      EXPECT_NEAR((gp(j) - gm(j)) / (2 * d), hm(j, i), 1e-6 * hm.cwiseAbs().maxCoeff())
          << i << "," << j;
  }
}

// The damping's position tangent (Seabed::AddDissipation's `position`):
// the damping force -c (n . v) n acts only on the pieces of the element in
// the bed and does not vanish at their ends, so the generalized force
// moves with the ends; its exact derivative there is what the header
// states. Checked against central differences of the force in e at a fixed
// rate, in 2 and 3 dimensions, on an element that dips into the bed in its
// middle (two interior ends) and on one that leaves it (one end), with
// friction off (whose q-derivative is left out by design). Error bound as
// in ForceAndTangentAreDerivativesOfTheEnergy: with d = 1e-6 the central
// difference's truncation d^2 |Q'''| / 6 and rounding eps |Q| / d are
// below 1e-9 of the tangent's scale here (the ends lie at slopes of order
// 0.1 to 1, a millimetre's move of e moves them a centimetre at most), so
// 1e-6 of its largest entry leaves a margin of 1000; the missing term (the
// code before this tangent existed: zero) errs by the scale itself.
template <int D>
void ExpectDampingPositionTangentIsTheDerivative(const Eigen::Matrix<double, 4 * D, 1>& e,
                                                 const Eigen::Matrix<double, 4 * D, 1>& edot,
                                                 int expected_ends) {
  using Coords = Eigen::Matrix<double, 4 * D, 1>;
  using Matrix = Eigen::Matrix<double, 4 * D, 4 * D>;
  SeabedSpec spec;
  spec.enabled = true;
  spec.depth_m = 0.3;
  spec.normal = Eigen::Vector3d(0.1, 1, D == 3 ? 0.2 : 0.0).normalized();
  spec.stiffness_n_m2 = 1e5;
  spec.damping_n_s_m2 = 2e4;
  Seabed bed(spec);
  constexpr double kL = 2.0;
  double pieces[2][2];
  const int count = bed.ContactPieces<D>(e, kL, pieces);
  int ends = 0;
  for (int p = 0; p < count; ++p)
    for (double xi : pieces[p]) ends += xi > 0 && xi < 1;
  ASSERT_EQ(ends, expected_ends);
  Coords f = Coords::Zero();
  Matrix c = Matrix::Zero(), k = Matrix::Zero();
  bed.AddDissipation<D>(e, edot, kL, &f, &c, &k);
  const double scale = k.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  const double d = 1e-6;
  for (int i = 0; i < 4 * D; ++i) {
    Coords ep = e, em = e, fp = Coords::Zero(), fm = Coords::Zero();
    ep(i) += d;
    em(i) -= d;
    bed.AddDissipation<D>(ep, edot, kL, &fp, nullptr);
    bed.AddDissipation<D>(em, edot, kL, &fm, nullptr);
    for (int j = 0; j < 4 * D; ++j)
      EXPECT_NEAR(-(fp(j) - fm(j)) / (2 * d), k(j, i), 1e-6 * scale) << i << "," << j;
  }
}

TEST(SeabedTest, DampingPositionTangentIsTheDerivativeOfTheDampingForce) {
  Eigen::Matrix<double, 12, 1> e, edot;
  // Sagging into the bed in the middle (ends above it), moving up and
  // sideways: two interior ends.
  e << 0, -0.2, 0, 1, -0.5, 0.3, 2, -0.25, 0.1, 1, 0.6, -0.2;
  edot << 0.3, 0.5, -0.1, 0.05, -0.2, 0.1, -0.2, 0.8, 0.3, 0.1, 0.4, -0.3;
  ExpectDampingPositionTangentIsTheDerivative<3>(e, edot, 2);
  // In the bed at the start, leaving it (one end), sinking.
  e << 0, -0.35, 0, 1, 0.2, 0.1, 2, 0.1, 0.1, 1, 0.3, -0.2;
  edot << 0.1, -0.7, 0.2, 0.0, 0.3, -0.1, 0.2, -0.1, 0.0, 0.1, 0.2, 0.3;
  ExpectDampingPositionTangentIsTheDerivative<3>(e, edot, 1);
  Eigen::Matrix<double, 8, 1> e2, edot2;
  e2 << 0, -0.2, 1, -0.5, 2, -0.25, 1, 0.6;
  edot2 << 0.3, 0.5, 0.05, -0.2, -0.2, 0.8, 0.1, 0.4;
  ExpectDampingPositionTangentIsTheDerivative<2>(e2, edot2, 2);
}

// Newton on a damped bed (issue 34): the OC4 mooring benchmark scene
// (bench/scenes/oc4-three-lines.json: three 835 m chains on the bed,
// fairleads heaving and surging) at 10 elements per line, HHT at h = 0.5 s
// for 100 s. With the damping's position tangent in Newton's matrix
// (DampingPositionTangentIsTheDerivativeOfTheDampingForce) the bed's
// damping is no harder for Newton than no damping: measured 5.6 iterations
// per step without damping, 5.5 at the deck's c = 2.3e4 N s/m^2 and 6.5 at
// ten times it (7 halved steps). Without the tangent it was 9.3 and 15.1
// (13 and 48 halved steps): ratios 1.66 and 2.68 to the undamped bed. The
// bounds, 1.25 at the deck's damping and 1.5 at ten times it, sit between
// (margins of 25 to 30 % above today's 0.97 and 1.15 for other platforms'
// rounding, which changes where a step is halved).
TEST(SeabedTest, BedDampingCostsNewtonAboutWhatAnUndampedBedDoes) {
  auto proto =
      ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/bench/scenes/oc4-three-lines.json");
  ASSERT_TRUE(proto.ok()) << proto.status();
  auto base = SceneFromProto(*proto);
  ASSERT_TRUE(base.ok()) << base.status();
  ASSERT_NEAR(base->seabed.damping_n_s_m2, 22980, 1);
  auto iterations_per_step = [&](double damping) {
    Scene scene = *base;
    for (CableSpec& c : scene.cables) c.elements = 10;
    scene.seabed.damping_n_s_m2 = damping;
    scene.solver.auto_integrator = false;
    scene.solver.integrator = Integrator::kHht;
    scene.solver.adaptive = false;
    scene.solver.step_s = 0.5;
    scene.solver.reuse_factorization = false;
    scene.solver.duration_s = 100;
    scene.solver.output_interval_s = 1;
    CollectingSink sink;
    const RunSummary summary = RunOk(scene, &sink);
    EXPECT_GE(summary.steps, 200);
    return static_cast<double>(summary.newton_iterations) /
           static_cast<double>(std::max<int64_t>(summary.steps, 1));
  };
  const double undamped = iterations_per_step(0);
  const double deck = iterations_per_step(22980);
  const double ten_times = iterations_per_step(229800);
  EXPECT_LT(deck, 1.25 * undamped) << deck << " vs " << undamped;
  EXPECT_LT(ten_times, 1.5 * undamped) << ten_times << " vs " << undamped;
}

}  // namespace
}  // namespace cablesim

namespace cablesim {
namespace {

// Friction: a 10 m chain on the bed dragged at 0.1 m/s by a support moving
// at constant speed, along the chain (planar; its axial coefficient) and
// across it by both ends (spatial; its transverse coefficient). In steady
// sliding the support pulls with mu w L times the regularisation factor
// v / sqrt(v^2 + v_s^2) (1 - 5e-5 here): the chain's inertia and axial
// damping do no work at constant speed, and the bed's normal force adds up
// to w L. Tolerance 2e-3 relative: what is left of the start's axial
// oscillation after 4 s (measured about 1e-4) and Newton's tolerance.
// The friction's work is in energy.damped: with the support's work (in
// energy.potential) the balance closes to 1e-3 of it.
double RegularisedFriction(double mu, double w, double length, double v, double vs) {
  return mu * w * length * v / std::sqrt(v * v + vs * vs);
}

constexpr double kChainLength = 10, kV = 0.1, kK = 1e6;

// The 10 m chain on a bed (stiffness kK, friction mu_a, mu_t) under gravity
// along -`up` ("y": planar, "z": spatial), laid along x over `span` at its
// resting depth, moving at kV along `along` from the start, held by
// `joints` with probes `probes`, at fixed steps of `step` [s].
std::string DraggedChain(const std::string& up, double span, const std::string& along,
                         const std::string& joints, const std::string& probes, double mu_a,
                         double mu_t, const std::string& law = "", double step = 0.01) {
  const double sink = -kW / kK;
  return absl::StrFormat(R"({
    "gravity": {"%s": -9.81},
    "cables": [{"name": "chain", "length": %.17g, "elements": 10, "density": %.17g,
                "youngs_modulus": %.17g, "area": %.17g, "second_moment": 1e-14,
                "bending": "NONE", "damping": {"axial_time": 0.01},
                "points": [{"x": 0, "%s": %.17g}, {"x": %.17g, "%s": %.17g}]}],
    "joints": %s, "probes": %s,
    "initial_velocity": {"linear": {"%s": %.17g}},
    "seabed": {"stiffness": %.17g, "damping": 1e4, "friction_axial": %.17g,
               "friction_transverse": %.17g%s},
    "solver": {"analysis": "DYNAMIC", "duration": 5, "step": %.17g, "output_interval": 0.01}})",
                         up, kChainLength, kDensity, kEa / kArea, kArea, up, sink, span, up, sink,
                         joints, probes, along, kV, kK, mu_a, mu_t, law, step);
}

// The chain's end s = 0 pinned to a support moving along x at kV.
std::string PulledAlongX() {
  return absl::StrFormat(
      R"([{"type": "PIN", "a": {"cable": "chain", "s": 0},
           "motion": {"x": {"ramp": {"slope": %.17g}}}}])",
      kV);
}

// The friction's velocity tangent at one point (contact::PointDissipation):
// its size N / s depends on the rate (s = sqrt(|v_b|^2 + v_s^2), or |v_b|
// on MoorDyn's Coulomb branch), so h = -dq/dv has a rank-one part besides
// N A / s. With mu_a = mu_t h must be -dq/dv (central differences, step
// 1e-7 m/s; tolerance 1e-6 of |h|: their truncation and rounding); without
// the rank-one part it is off by |v_b|^2 / s^2, nearly 1 here. With
// mu_a != mu_t the Newton matrix takes a symmetric positive semi-definite
// form that is exact along v_b (v_b^T h v_b). Statics (rate_tangent false,
// a displacement standing for v) keeps N A / s alone.
TEST(SeabedFrictionTest, FrictionVelocityTangentIsTheDerivativeOfTheForce) {
  using P = Eigen::Vector3d;
  using B = Eigen::Matrix3d;
  const P n(0, 0, 1), u(0.8, 0.6, 0), v(0.03, -0.05, 0.002);
  const B proj = B::Identity() - n * n.transpose();
  const double normal = 700, vs = 1e-3;
  const auto force = [&](const P& w, double mu_a, double mu_t, double md) {
    P q;
    B h;
    contact::PointDissipation<3>(n, proj, normal, w, u, 0.0, mu_a, mu_t, vs, &q, &h, md, 1.0);
    return q;
  };
  for (const double md : {0.0, 1.0}) {  // regularised; MoorDyn's law, Coulomb branch
    for (const auto& [mu_a, mu_t] : {std::pair{0.7, 0.7}, std::pair{0.5, 1.2}}) {
      P q;
      B h;
      contact::PointDissipation<3>(n, proj, normal, v, u, 0.0, mu_a, mu_t, vs, &q, &h, md, 1.0);
      B fd;
      for (int j = 0; j < 3; ++j) {
        P dv = P::Zero();
        dv[j] = 1e-7;
        fd.col(j) = -(force(v + dv, mu_a, mu_t, md) - force(v - dv, mu_a, mu_t, md)) / 2e-7;
      }
      const double size = h.norm();
      EXPECT_LE((h - h.transpose()).norm(), 1e-12 * size);
      Eigen::SelfAdjointEigenSolver<B> eig(h);
      EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * size) << md << " " << mu_a;
      const P vb = proj * v;
      EXPECT_NEAR(vb.dot(h * vb), vb.dot(fd * vb), 1e-6 * size * vb.squaredNorm())
          << md << " " << mu_a;
      if (mu_a == mu_t) {
        EXPECT_LE((h - fd).norm(), 1e-6 * size) << md << "\n" << h << "\n" << fd;
      }
    }
  }
  // Statics: N A / s alone, A = mu P (mu_a = mu_t).
  P q;
  B h;
  contact::PointDissipation<3>(n, proj, normal, v, u, 0.0, 0.7, 0.7, vs, &q, &h, 0.0, 1.0,
                               /*rate_tangent=*/false);
  const double s = std::sqrt((proj * v).squaredNorm() + vs * vs);
  EXPECT_LE((h - (normal * 0.7 / s) * proj).norm(), 1e-12 * h.norm());
}

// What the friction's rate tangent buys: scenes/mooring-chain-landing.json
// (a chain landing on a bed with friction, HHT at 10 ms) took 32,347 Newton
// iterations for its 3,006 steps without it (Newton converged linearly
// while the chain slid) and 6,493 for 3,000 with it. Bound: 3 a step (the
// undamped, frictionless bed takes about 2.2).
TEST(SeabedFrictionTest, ASlidingChainCostsNewtonFewIterations) {
  absl::StatusOr<v1::Scene> proto = ReadSceneFile(
      std::string(CABLESIM_SOURCE_DIR) + "/scenes/mooring-chain-landing.json");
  ASSERT_TRUE(proto.ok()) << proto.status();
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  CollectingSink sink;
  const RunSummary s = RunOk(*scene, &sink);
  std::printf("chain landing: %ld Newton iterations for %ld steps\n",
              static_cast<long>(s.newton_iterations), static_cast<long>(s.steps));
  EXPECT_LT(s.newton_iterations, 3 * s.steps);
}

TEST(SeabedFrictionTest, DraggedAlongTheBedPullsWithMuWL) {
  const double mu = 0.7;
  const std::string joints = PulledAlongX();
  CollectingSink sink;
  const RunSummary s = RunOk(
      SceneFromJson(DraggedChain("y", kChainLength, "x", joints,
                                 R"([{"name": "pull", "cable": "chain", "s": 0}])", mu, 1)),
      &sink);
  ASSERT_FALSE(sink.frames().empty());
  const double expect = RegularisedFriction(mu, kW, kChainLength, kV, 1e-3);
  for (const Frame& f : sink.frames()) {
    if (f.t < 4) continue;
    ASSERT_EQ(f.support_forces.size(), 1u);
    EXPECT_NEAR(f.support_forces[0].x(), expect, 2e-3 * expect) << f.t;
  }
  std::printf("axial: pull %.3f N against mu w L %.3f N; damped %.3f J, balance %.3e J\n",
              sink.frames().back().support_forces[0].x(), expect, s.energy_damped,
              s.energy_final + s.energy_damped - s.energy_initial);
  EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 1e-3 * s.energy_damped);
}

// MoorDyn's law (seabed.friction_law MOORDYN), the same drag along the
// bed: its closed form in steady sliding at v = kV with N = w per unit
// length is a pull of mu c v L while c v <= m_c w (viscous), mu w L above
// (Coulomb's, without the regularised law's factor). Three cases: c v =
// w / 2 (viscous), c v = 5 w with m_c = 1 (saturated) and with m_c = 10
// (viscous again: static friction ten times the kinetic lets the viscous
// branch run up to 10 w). Tolerance 2e-3 relative, as above.
// The viscous branch at c = 5 w / v stops the chain (but for the pushed
// end) in m / (c mu_a) = v / (5 g mu_a) = 2.9 ms, so the step is 2 ms:
// energy.damped is the trapezoidal rule on the dissipated power, which
// over a longer step counts about P(0) h / 2 of the start's 2.7 kW too
// much, and the energy guard fails the run for a rise of more than 5 % of
// its 17.6 J scale (at h = 5 ms: 6.7 J after the first step, 2.3 J at
// t = 10 ms). The run passed at 10 ms only with a kept
// Newton matrix: its slower Newton took the 4 iterations that have the
// guard look at a step before accepting it, which halved the step twice;
// with a fresh matrix Newton converged in 3. Both Newton economies run.
TEST(SeabedFrictionTest, MoorDynLawPullsWithItsClosedForm) {
  const double mu = 0.7;
  const std::string joints = PulledAlongX();
  struct Case {
    double c, scale, expect;
  };
  const Case cases[] = {
      {0.5 * kW / kV, 1, mu * 0.5 * kW * kChainLength},
      {5 * kW / kV, 1, mu * kW * kChainLength},
      {5 * kW / kV, 10, mu * 5 * kW * kChainLength},
  };
  for (const bool reuse : {false, true}) {
    for (const Case& c : cases) {
      const std::string law = absl::StrFormat(
          R"(, "friction_law": "MOORDYN", "friction_damping": %.17g, "static_friction_scale": %.17g)",
          c.c, c.scale);
      Scene scene = SceneFromJson(DraggedChain("y", kChainLength, "x", joints,
                                               R"([{"name": "pull", "cable": "chain", "s": 0}])",
                                               mu, 1, law, 0.002));
      scene.solver.reuse_factorization = reuse;
      CollectingSink sink;
      RunOk(scene, &sink);
      ASSERT_FALSE(sink.frames().empty());
      for (const Frame& f : sink.frames()) {
        if (f.t < 4) continue;
        ASSERT_EQ(f.support_forces.size(), 1u);
        EXPECT_NEAR(f.support_forces[0].x(), c.expect, 2e-3 * c.expect)
            << "c " << c.c << " scale " << c.scale << " reuse " << reuse << " t " << f.t;
      }
      std::printf("MoorDyn law c %.4g, m_c %.3g, reuse %d: pull %.4f N against %.4f N\n", c.c,
                  c.scale, reuse, sink.frames().back().support_forces[0].x(), c.expect);
    }
  }
}

TEST(SeabedFrictionTest, DraggedAcrossTheBedUsesTheTransverseCoefficient) {
  const double mu = 1.0;
  const std::string joints = absl::StrFormat(
      R"([{"type": "PIN", "a": {"cable": "chain", "s": 0},
           "motion": {"y": {"ramp": {"slope": %.17g}}}},
          {"type": "PIN", "a": {"cable": "chain", "s": %.17g},
           "motion": {"y": {"ramp": {"slope": %.17g}}}}])",
      kV, kChainLength, kV);
  const std::string probes = absl::StrFormat(
      R"([{"name": "a", "cable": "chain", "s": 0}, {"name": "b", "cable": "chain", "s": %.17g}])",
      kChainLength);
  CollectingSink sink;
  const RunSummary s = RunOk(
      SceneFromJson(DraggedChain("z", 1.004 * kChainLength, "y", joints, probes, 0.5, mu)), &sink);
  ASSERT_FALSE(sink.frames().empty());
  const double expect = RegularisedFriction(mu, kW, kChainLength, kV, 1e-3);
  // Across the chain, friction is a distributed load that a string only
  // carries by bowing, and where the bowed chain's tangent tilts by theta
  // from the x axis the friction falls by about (1 - mu_a^2 / mu_t^2)
  // theta^2 / 2. Stretched by 0.4 % (tension 2e5 N), the chain bows by
  // theta < mu w L / (2 T) = 0.019: 1.4e-4. It also oscillates about its
  // bow (string waves, undamped by friction, whose force saturates along
  // the sliding direction), and the pull with it; its mean over 4 s is the
  // friction plus the change of the chain's momentum over 4 s, a few N.
  double sum = 0;
  int count = 0;
  for (const Frame& f : sink.frames()) {
    if (f.t < 1) continue;
    ASSERT_EQ(f.support_forces.size(), 2u);
    sum += f.support_forces[0].y() + f.support_forces[1].y();
    ++count;
  }
  std::printf("transverse: mean pull %.3f N against mu w L %.3f N\n", sum / count, expect);
  EXPECT_NEAR(sum / count, expect, 2e-3 * expect);
  EXPECT_NEAR(s.energy_final + s.energy_damped, s.energy_initial, 1e-3 * s.energy_damped);
}

}  // namespace
}  // namespace cablesim
