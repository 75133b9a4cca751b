#ifndef CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_H_
#define CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_H_

// The gradient-deficient ANCF cable element (docs/model.md section 1), planar
// (D = 2, 8 coordinates) or spatial (D = 3, 12 coordinates).
//
// Coordinates e = [r_O, r_O,x, r_A, r_A,x] (paper eq. 4, 6, 7 with its typo
// fixed); r(x) = S(x) e with the cubic Hermite functions of eq. 3.
// With u = r' = S' e and w = r'' = S'' e (eq. 25, 26), the strain energy per
// unit undeformed length is
//
//   psi = EA/2 eps^2 + EI/2 kappa^2,   eps = (u.u - 1) / 2   (Green-Lagrange)
//
// or, with AxialLaw::kEngineering, eps = |u| - 1 (the engineering strain:
// the tension EA eps along the tangent is linear in the stretch, the law a
// mooring data sheet's EA means; Green-Lagrange's tension is
// EA (e + e^2/2)(1 + e) in the engineering strain e, 1.5 % stiffer at 1 %),
// or, with AxialLaw::kTable, psi = W(e) = int_0^e T de of a tension-strain
// table T(e) in the engineering strain (engine/elements/tension_table.h;
// the tension along the tangent is T(e), its stiffness the table's slope),
// or, with AxialLaw::kViscoelastic, the tension T = k e + p and stiffness k
// that engine/elements/viscoelastic_history.h gives each Gauss point for
// the current step (its stored energy that history's).
//
// and, writing a = u.u, b = u.w, c = w.w,
//
//   EXACT:  kappa^2 = |u x w|^2 / |u|^6 = (a c - b^2) / a^3     (eq. 17)
//   LINEAR: kappa^2 = c                                          (eq. 21-22)
//   NONE:   kappa^2 = 0.
//
// The identity |u x w|^2 = a c - b^2 holds in the plane and in space, so
// one formula serves both dimensions and is smooth (no absolute value).
// U = int_0^l psi dx by Gauss quadrature; the force Q_k = dU/de and the
// tangent K = d^2U/de^2 are analytic (no finite differences).
//
// Units: SI. Forces in N (or N for position coordinates and N m for slope
// coordinates), stiffness in N/m accordingly, energy in J.

#include <memory>

#include <Eigen/Core>

#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/tension_table.h"
#include "engine/elements/viscoelastic_history.h"
#include "engine/scene/scene.h"

namespace cablesim {

template <int D>
class AncfCableElement {
 public:
  static constexpr int kCoords = 4 * D;
  using Coords = Eigen::Matrix<double, kCoords, 1>;
  using Matrix = Eigen::Matrix<double, kCoords, kCoords>;
  using Point = Eigen::Matrix<double, D, 1>;

  struct Energy {
    double axial = 0;
    double bending = 0;
  };

  // Default quadrature: 5 points integrate the axial term (degree 8 in xi)
  // exactly. The exact-curvature term is rational; measured against 8
  // points (tests/ancf_cable_element_test.cc) on elements bent through up
  // to 1 rad whose stretch varies by 5 % along them, 5 points agree to
  // better than 1e-5 relative (4 points: 1e-4, 3 points: 1e-3).
  static constexpr int kDefaultGaussPoints = 5;

  AncfCableElement() = default;
  AncfCableElement(double length_m, double ea_n, double ei_n_m2, BendingModel bending,
                   int gauss_points = kDefaultGaussPoints,
                   AxialLaw axial_law = AxialLaw::kGreenLagrange,
                   std::shared_ptr<const TensionTable> table = nullptr);

  // With AxialLaw::kTable, `table` (shared by a cable's elements) gives the
  // tension; ea_n stays the nominal EA that AddDampingMatrix's axial_s
  // multiplies.
  AxialLaw axial_law() const { return axial_law_; }
  // With AxialLaw::kViscoelastic: the history whose points first_point ..
  // first_point + gauss_points() - 1 are this element's (it must outlive
  // the element's use; the model owns both).
  void set_viscoelastic(const ViscoelasticHistory* history, int first_point) {
    visco_ = history;
    visco_first_ = first_point;
  }
  // The engineering strain |r'| - 1 at each Gauss point into out[g].
  void AxialStrains(const Coords& e, double* out) const;

  double length() const { return length_; }
  // A new undeformed length [m] (a winch cable's elements, whose length
  // changes in time): the shape functions at the Gauss points are
  // recomputed. Allocates nothing.
  void set_length(double length_m);

  // Consistent mass matrix (eq. 8-10 of the paper, docs/model.md section 1) for mass per unit
  // length rho A [kg/m].
  Matrix MassMatrix(double mass_per_length_kg_m) const;

  // Generalized gravity force m [g/2, l g/12, g/2, -l g/12] per component;
  // the element's gravitational potential is exactly -Q_g . e.
  Coords GravityForce(double mass_per_length_kg_m, const Point& g) const;

  // The same two for an element of length `length_m` (what the members
  // return at length()): the 4 x 4 scalar mass matrix mbar (M = mbar (x)
  // I_D) and the gravity force. A winch cable's contributors evaluate them
  // at L(t) / N without holding the element.
  static Eigen::Matrix4d ScalarMassMatrix(double length_m, double mass_per_length_kg_m);
  static Coords GravityForceOfLength(double length_m, double mass_per_length_kg_m,
                                     const Point& g);

  // Position r(xi l) and slope r'(xi l) for xi in [0, 1].
  Point Position(const Coords& e, double xi) const;
  Point Slope(const Coords& e, double xi) const;

  Energy StrainEnergy(const Coords& e) const;

  // Adds the elastic force Q_k = dU/de to `force` and, when `tangent` is not
  // null, the tangent K_T = dQ_k/de to `tangent` (which must be symmetric on
  // entry, usually zero). Allocates nothing.
  //
  // When `roundoff` is not null, also adds to it a bound on the rounding
  // error of each force entry [N, or N m for slopes]: the force computed in
  // double precision from coordinates that are themselves only known to
  // machine precision. At a Gauss point u = sum_k s_k' e_k is off by up to
  // du = eps sum_k |s_k'| |e_k| (and w by dw likewise with s_k''): for a
  // short element far from the origin that is eps |r| / l, far above eps.
  // The gradient (g_u, g_w) of psi then moves by at most
  // |H_uu| du + |H_uw| dw and |H_uw| du + |H_ww| dw (spectral-norm bounds of
  // the Hessian blocks of psi), plus eps |g| for its own evaluation, and the
  // force entry k by l w_g (|s_k'| dg_u + |s_k''| dg_w). Newton cannot drive
  // a residual below this level: it is the floor of its acceptance test
  // (newton_convergence.h). An EA of 1.6e7 N, a 1 mm element and |r| = 10 m
  // give about 3e-5 N, while 100 eps EA (the older global floor) is 3.5e-7 N.
  void ElasticForce(const Coords& e, Coords* force, Matrix* tangent,
                    Coords* roundoff = nullptr) const;

  // The energy-momentum stepper's discrete gradient of the strain energy:
  // adds to `correction` DG U(e0, e1) - dU/de(em), em = (e0 + e1) / 2, so
  // that the force dU/de(em) (ElasticForce at em) plus it is a discrete
  // gradient in Gonzalez's sense (J. Nonlinear Sci. 6:449-467, 1996,
  // section 3): DG U(e0, e1) . (e1 - e0) = U(e1) - U(e0) to rounding,
  // DG U(e, e) = dU/de, and symmetric in (e0, e1), hence second order.
  //
  // Invariants (Gonzalez's section 4): U depends on e only through the
  // Gram matrix G = E^T E of E = [(r_A - r_O) / l, r_O,x, r_A,x], since at
  // a Gauss point u = E alpha, w = E beta (alpha, beta from the shape
  // functions), so a = alpha^T G alpha, b = alpha^T G beta, c = beta^T G
  // beta are linear in G and quadratic in e, and G1 - G0 = Em^T dE +
  // dE^T Em exactly. Per Gauss point the discrete derivative of psi(a, b,
  // c) is taken in (a, b, c):
  //  - axial: psi_a = EA (a - 1) / 4 at the mean a (psi is quadratic in
  //    a: exact; the strain at the mean of its end values, Simo and
  //    Tarnow, ZAMP 43:757-792, 1992); engineering strain, psi =
  //    EA/2 (s - 1)^2 with s = sqrt(a): the exact difference quotient
  //    EA/2 (s0 + s1 - 2) / (s0 + s1) (no cancellation as a1 -> a0);
  //    a table, psi = W(s - 1): the quotient Tbar / (s0 + s1) with Tbar
  //    the table's exact mean tension over [e0, e1] (TensionTable::
  //    MeanTension, free of cancellation as well);
  //  - LINEAR bending: psi = EI c / 2 is linear: exact;
  //  - EXACT bending, psi = k (c A(a) - b^2 B(a)), k = EI / 2, A = a^-2,
  //    B = a^-3, by the discrete product rule
  //      Delta(c A) = Abar Delta c + cbar Delta A,
  //      Delta(b^2 B) = 2 bbar Bbar Delta b + (b^2)bar Delta B,
  //    with the exact difference quotients Delta A / Delta a =
  //    -(a0 + a1) / (a0^2 a1^2) and Delta B / Delta a = -(a0^2 + a0 a1 +
  //    a1^2) / (a0^3 a1^3) (no cancellation as a1 -> a0). Gonzalez's own
  //    correction [U(e1) - U(e0) - grad U . de] de / |de|^2 was tried
  //    first: its numerator is a difference of energies that cancels to
  //    rounding for small steps, and the quotient by |de|^2 turned that
  //    rounding into force noise above the Newton tolerance (the falling
  //    pendulum's first steps did not converge at any step size).
  // The force on the three vectors is 2 Em P with P = sum over Gauss points
  // of the discrete derivatives times aa^T, (al be^T + be al^T) / 2 and
  // be be^T: P symmetric makes its moment sum_k Em_k x (2 Em P)_k vanish,
  // and the two node forces are opposite, so the discrete gradient keeps
  // linear and angular momentum as dU/de does. Allocates nothing.
  void AddDiscreteGradientCorrection(const Coords& e0, const Coords& e1, Coords* correction) const;

  // Kelvin-Voigt damping: adds to `c` the symmetric positive semi-definite
  // matrix C(e) of the damping force Q_d = C(e) edot [N s/m] derived from
  // the dissipation function per unit length
  //
  //   D = EA axial_s / 2 (d eps/dt)^2 + EI bending_s / 2 |d k/dt|^2,
  //
  // d eps/dt = u.udot (engineering strain, also under a table:
  // u.udot / |u|, so its term is EA axial_s u u^T / |u|^2), k = u x w / |u|^3 the curvature vector (a scalar in
  // the plane; |k| is the EXACT model's curvature), so that
  // C = int B^T (EA axial_s u u^T + EI bending_s G^T G) B dx with
  // G = dk/d(u, w). This is exactly axial_s times the material part of the
  // axial tangent stiffness and bending_s times the material part of the
  // EXACT bending tangent (the tangent without its stress-times-curvature
  // geometric terms), which is why Rayleigh's beta adds to both times.
  // It vanishes on rigid motion in the plane and on rigid translation in
  // space; in space the rotation of a curved cable turns k and is damped
  // by EI bending_s |omega x k|^2 per unit length (zero for a straight
  // one). With bending NONE (EI = 0) only the axial term acts.
  void AddDampingMatrix(const Coords& e, double axial_s, double bending_s, Matrix* c) const;
  // The damping force of AddDampingMatrix's C without forming C, when the
  // bending term is absent (bending NONE, EI = 0 or bending_s = 0): adds
  // -C edot = -int S'^T EA axial_s (u.udot) u / a dx to `force` (a = |u|^2
  // under the engineering and table laws, 1 under Green-Lagrange; udot =
  // S' edot) point by point, and returns edot^T C edot >= 0 [W]. False
  // (nothing added) when the bending term acts: form C instead. The
  // residual-only Newton iterations need the force alone (OC4's mooring
  // lines: 3 x 10 elements, 2,853 iterations, 1,800 force-only passes
  // formed the 12 x 12 C for them before: 5 % of the run).
  bool AddAxialDampingForce(const Coords& e, const Coords& edot, double axial_s,
                            double bending_s, Coords* force, double* power) const;

  // Morison drag (Morison et al., J. Petroleum Technology 2(5), 1950, the
  // drag term; the cross-flow split of MoorDyn's and OrcaFlex's line
  // models): at each Gauss point, with the relative velocity
  // v_r = current - rdot, the unit tangent t = r' / |r'|, v_t = (v_r . t) t
  // and v_n = v_r - v_t, the force per unit undeformed length
  //
  //   q = kn |v_n| v_n + kt |v_t| v_t   [N/m],
  //
  // kn = rho C_dn d / 2 and kt = rho C_dt pi d / 2 [kg/m^2] (normal drag on
  // the projected diameter, tangential drag on the wetted perimeter).
  // Adds Q = int S^T q dx to `force` and, when `c` is not null,
  // -dQ/d(edot) = int S^T (kn (|v_n| P + v_n v_n^T / |v_n|)
  // + 2 kt |v_t| t t^T) S dx to it (P = I - t t^T; symmetric positive
  // semi-definite; the derivative through t in e is left out).
  void AddDrag(const Coords& e, const Coords& edot, const Point& current, double kn, double kt,
               Coords* force, Matrix* c) const;

  // The Gauss points of the element's rule and the position r(x_g) = S(x_g) e
  // [m] at point g (WaveLoad evaluates the flow there).
  int gauss_points() const { return rule_.n; }
  Point GaussPosition(const Coords& e, int g) const;
  // Adds Gauss point g's share of a load q per unit length [N/m],
  // w_g l S(x_g)^T q, to `force` (the quadrature of int S^T q dx).
  void AddLoadAtGaussPoint(int g, const Point& q, Coords* force) const {
    const double wl = rule_.weight[g] * length_;
    for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) += (wl * s0_[g][k]) * q;
  }
  // The quadrature weight of point g times the length, w_g l [m].
  double GaussLength(int g) const { return rule_.weight[g] * length_; }

  // The Morison load in a flow that varies along the element
  // (engine/forces/wave_load.h): AddDrag with the fluid's velocity
  // flow_velocity[g] [m/s] at Gauss point g in place of the uniform current,
  // plus the flow's inertia (mi_n P + mi_t t t^T) flow_acceleration[g] per
  // unit length (P = I - t t^T; mi_n across the line, mi_t along it
  // [kg/m]; flow_acceleration null: none); the inertia does not depend on
  // edot, so `c` is AddDrag's. `wet` (null: every point) marks the Gauss
  // points the fluid reaches: the others get no load.
  void AddMorison(const Coords& e, const Coords& edot, const Point* flow_velocity,
                  const Point* flow_acceleration, double kn, double kt, double mi_n,
                  double mi_t, const bool* wet, Coords* force, Matrix* c) const;

  // A mass per unit length that depends on the direction of the line
  // (engine/forces/cable_added_mass.h): at Gauss point g the matrix
  // A_g = a_n[g] (I - t t^T) + a_t[g] t t^T [kg/m], t the unit tangent at
  // e. Adds the inertia force -int S^T A S edd dx [N] to `force` (edd the
  // element's coordinate accelerations) and, when `m` is not null, its
  // acceleration derivative int S^T A S dx [kg] to `m` (symmetric; the
  // derivative through t in e is left out). Points with a_n = a_t = 0 cost
  // nothing.
  void AddDirectionalMass(const Coords& e, const Coords& edd, const double* a_n,
                          const double* a_t, Coords* force, Matrix* m) const;
  // The kinetic energy of that mass at coordinate velocities edot,
  // 1/2 edot^T (int S^T A S dx) edot = 1/2 int a_n |v|^2 + (a_t - a_n)
  // (t.v)^2 dx, v = S edot [J], point by point (the energy at every output
  // frame, without AddDirectionalMass's force pass).
  double DirectionalKineticEnergy(const Coords& e, const Coords& edot, const double* a_n,
                                  const double* a_t) const;

 private:
  // ElasticForce for one axial law (the law a template argument, so the
  // Gauss-point loop does not branch on it).
  template <AxialLaw kLaw>
  void ElasticForceWith(const Coords& e, Coords* force, Matrix* tangent, Coords* roundoff) const;

  // B maps e to (u, w) at Gauss point g: rows 0..D-1 are S', rows D..2D-1
  // are S''.
  using BMatrix = Eigen::Matrix<double, 2 * D, kCoords>;
  BMatrix B(int g) const;
  // tangent += wl B_g^T [huu huw; huw^T hww] B_g on the upper node blocks
  // (k <= m); the caller mirrors them.
  using Block = Eigen::Matrix<double, D, D>;
  void AddUpperBlocks(int g, double wl, const Block& huu, const Block& huw, const Block& hww,
                      Matrix* tangent) const;
  // AddUpperBlocks with huw = hww = 0 (its path for them).
  void AddUpperAxialBlocks(int g, double wl, const Block& huu, Matrix* tangent) const;
  static void MirrorUpperBlocks(Matrix* tangent);
  // The drag (and, with `accel` not null, the inertia mi accel) at Gauss
  // point g for the flow velocity `flow`: AddMorison's first pass. kLoad:
  // the load q per unit length [N/m] and, when `tangent`, its velocity
  // derivative h; kInertiaOnly (a collapsed point): q holds accel, whose
  // share is mi_n accel; kDry: nothing.
  struct FlowPoint {
    enum Kind { kDry, kInertiaOnly, kLoad } kind = kDry;
    Point q;
    Block h;
  };
  void FlowLoadAt(int g, const Coords& e, const Coords& edot, const Point& flow,
                  const Point* accel, double kn, double kt, double mi_n, double mi_t,
                  bool tangent, FlowPoint* point) const;

  double length_ = 0;
  double ea_ = 0;
  double ei_ = 0;
  BendingModel bending_ = BendingModel::kExact;
  AxialLaw axial_law_ = AxialLaw::kGreenLagrange;
  std::shared_ptr<const TensionTable> table_;  // AxialLaw::kTable only
  const ViscoelasticHistory* visco_ = nullptr;  // AxialLaw::kViscoelastic only
  int visco_first_ = 0;
  GaussRule rule_;
  // Shape-function derivatives at the Gauss points: d1_[g][k] = s_k'(x),
  // d2_[g][k] = s_k''(x), derivatives in x.
  double s0_[GaussRule::kMaxPoints][4] = {};  // s_k(x), for drag
  double d1_[GaussRule::kMaxPoints][4] = {};
  double d2_[GaussRule::kMaxPoints][4] = {};
};

extern template class AncfCableElement<2>;
extern template class AncfCableElement<3>;

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_H_
