#ifndef CABLESIM_ENGINE_FORCES_SEABED_H_
#define CABLESIM_ENGINE_FORCES_SEABED_H_

// A flat seabed under ANCF cable elements: a distributed spring-damper
// normal to the bed and Coulomb friction in its plane, per unit undeformed
// cable length (the lumped-node form is MoorDyn's, Hall, "MoorDyn v2
// theory", the seabed contact and friction sections; here the load is
// distributed along the element's cubic and integrated exactly).
//
// The bed is the plane n . r = -depth (n unit, pointing into the water).
// Along an element, r(x) = S(x) e (cubic Hermite, AncfCableElement), the
// height above the bed
//
//   h(xi) = depth + n . r(xi l),   xi in [0, 1],
//
// is a cubic in xi; the penetration is p = max(0, -h) [m]. Per unit
// undeformed length the bed pushes with
//
//   q = k p n - c pdot n [N/m],   pdot = -n . rdot   (where p > 0)
//
// (k: stiffness [N/m^2], c: damping [N s/m^2]) and stores U = int k p^2 / 2
// dx [J]. The damping acts only where the cable is in the bed (p > 0) and
// is not clipped: a cable leaving the bed fast is briefly held by it, as in
// MoorDyn.
//
// Lift-off. The roots of the cubic h in (0, 1) (found by splitting [0, 1]
// at the roots of h', then bisecting each monotone piece to the last bit)
// split the element into pieces wholly in or out of the bed; on each piece
// in the bed the integrands of the force (s_k p: degree 6), the energy
// (p^2: 6) and the tangent and damping (s_k s_m: 6) are polynomials, which
// 4-point Gauss-Legendre integrates exactly. So the touchdown point is
// resolved to rounding inside an element, whatever the mesh; the mesh only
// limits how well the cubic follows the cable (tests/seabed_test.cc
// measures the touchdown point converging with the mesh). The force
// vanishes at the roots, so the derivative of the integral is the integral
// of the derivative (no boundary terms): the tangent k int S^T n n^T S dx
// is exact and Newton converges quadratically through lift-off.
//
// The damping's integrand -c pdot s_k n does not vanish at the roots (a
// cable entering or leaving the bed at speed), so its integral moves with
// them: at a root x* of h (inside the element), dx*/de_m = -s_m n^T /
// (n . r'), and the damping force changes by s_k q dx* there (with the
// sign of the end), which is the symmetric position tangent
//
//   -dQ_d/de = -c (n . rdot) / |n . r'| S(x*)^T n n^T S(x*)
//
// (negative where the cable lifts off). It is large where the cable meets
// the bed at a small angle (a catenary's touchdown, n . r' -> 0): on the
// OC4 mooring (bench/scenes/oc4-three-lines.json, 10 elements per line,
// HHT at h = 0.5 s) leaving it out of Newton's matrix cost 9.3 iterations
// per step and 13 halved steps at the deck's damping, 15 and 48 at ten
// times it, against 5.5 and 6.5 with it (docs/mooring-speed.md).
// AddDissipation gives it (the model adds it with the position-dependent
// forces' scale, MultibodyModel::DampingForce); on a grid bed with
// |grad g| / |grad g . r'| in place of 1 / |n . r'|, and there the
// damping's other position dependences (n turning inside a cell, its jump
// at a grid line the element crosses in the bed) are left out.
//
// Friction (dynamic runs), with N = k p the elastic normal force per unit
// length (the damping part is left out, so friction never pulls), the
// sliding velocity v_b = rdot - (n . rdot) n in the bed's plane, the
// cable's direction in the bed's plane t_b = normalize(P r') (P = I - n n^T)
// and v_a = t_b . v_b, v_t = v_b - v_a t_b:
//
//   q_f = -N (mu_a v_a t_b + mu_t v_t) / sqrt(|v_b|^2 + v_s^2),
//
// Coulomb's mu_a N along the cable and mu_t N across it once |v_b| >> v_s
// (the regularisation speed, a scene parameter), viscous (slope
// N mu / v_s) below it; a static line under a force below mu N creeps at a
// speed of order v_s F / (mu N). Its power -q_f . v_b >= 0 is dissipated.
// Its velocity tangent N/s (mu_a t_b t_b^T + mu_t (P - t_b t_b^T)) (s the
// square root above) leaves out the (non-symmetric) rank-one term
// -N (A v_b) v_b^T / s^3: an over-estimate, symmetric positive
// semi-definite, that keeps Newton's matrix definite. The friction's q
// derivative (through N and t_b) is left out too. Friction is integrated
// with the same Gauss points as the damping (exact only for the
// polynomial terms). STATIC analyses see the static friction below.
//
// MoorDyn's law (seabed.friction_law MOORDYN, dynamic runs; MoorDyn's
// Line.cpp bottom contact, per unit length here): with c the friction
// damping [N s/m^2] and m_c the static scale,
//
//   q_f = -c A v_b                 while c |v_b| <= m_c N,
//   q_f = -N A v_b / |v_b|         above,
//
// A = mu_a t_b t_b^T + mu_t (P - t_b t_b^T) as above: a viscous law of
// slope c mu up to the speed m_c N / c, where it jumps to Coulomb's mu N
// (down when m_c > 1: MoorDyn's static friction above the kinetic one;
// continuous at m_c = 1). Its tangent is c A and N A / |v_b| (the same
// over-estimate as above); STATIC analyses keep the static friction
// below.
//
// Bathymetry (engine/forces/bathymetry_grid.h). When the scene gives a
// grid, the height above the bed is measured along the grid's up axis,
//
//   g(r) = s r_up + d(u, v),   penetration p = max(0, -g) [m],
//
// and the bed stores U = int k p^2 / 2 dx and pushes with
// q = k p grad g (grad g = s e_up + d_u e_u + d_v e_v): along the bed's
// local normal n = grad g / |grad g|, of size k p |grad g|. On a plane of
// slope theta, p = p_n / cos(theta) (p_n the penetration along the normal)
// and |grad g| = 1 / cos(theta): the bed is stiffer along its normal by
// 1 / cos^2(theta) than a plane of the same k (3% at 10 degrees), and a
// uniformly sloped grid is exactly the tilted plane of stiffness
// k / cos^2(theta) (tests/seabed_bathymetry_test.cc). The vertical gap is
// chosen because it is continuous across the grid lines, where the
// gradient (and the normal) jumps: U's integrand stays continuous there,
// the force stays the exact gradient of U and energy is conserved, and
// only the tangent jumps where a cable node crosses a grid line (a
// kink in U's gradient along the line).
// Dividing by |grad g| (the true normal gap) would make U's integrand jump
// at the grid lines, and the force would miss an impulse there.
// Damping and friction use the local normal n and N = k p |grad g|, as on
// a plane. The tangent adds the curvature term: k (grad g grad g^T -
// p d_uv (e_u e_v^T + e_v e_u^T)) per unit length, and, where the element
// crosses a grid line a = a_i in the bed, the term of the moving crossing
// l k g J / a' S^T e_a e_a^T S there (J the jump of the slope dd/da across
// the line in the direction of xi, a' = da/dxi): the force's integrand
// jumps at the line, so its integral moves with the crossing point.
//
// Cutting. Inside one grid cell g along an element is a polynomial of
// degree 6 in xi (the bilinear d of cubics u, v); the force, energy and
// tangent integrands are of degree <= 12, which 7-point Gauss integrates
// exactly. So the element is cut at every grid line it crosses and where
// g changes sign, and each piece in the bed is integrated by 7-point
// Gauss: exact, and the cut points do not move U's derivative (the
// integrand vanishes at the zero crossings and is continuous at the grid
// lines). The crossings are found on 16 equal sub-intervals of the
// element (bisection to the last bit on each: the grid line crossings of
// the cubics u, v, then the sign changes of g between them); an excursion
// in or out of the bed, or a double crossing of one grid line, shorter
// than 1/16 of the element is missed (the cable's mesh, not the grid,
// then limits the resolution).
//
// Static friction (STATIC analyses: no velocities). Friction opposes the
// displacement in the bed's plane of each material point from where the
// analysis started (where the line was laid, e0), u_b = P (r(e) - r(e0)),
// with the dynamic law's shape, the speed replaced by the displacement
// and v_s by the regularisation length u_s (seabed.friction_length):
//
//   q_s = -N (mu_a u_a t_b + mu_t u_t) / sqrt(|u_b|^2 + u_s^2),
//
// a stiff spring (slope mu N / u_s) capped at Coulomb's mu N once |u_b|
// >> u_s. It reproduces the grounded line of the elastic catenary with
// seabed friction (MAP's and MoorPy's C_B: the tension falls by C_B w per
// metre from the touchdown point toward the anchor) when the line was laid
// nearer the anchor than it ends, so that every grounded point moved toward
// the fairlead; within a length sqrt(2 EA u_s / (mu w)) of where the
// tension reaches zero the friction is not fully mobilised
// (tests/seabed_test.cc measures it against the closed form). The answer
// depends on the start (path dependence: a line laid elsewhere carries other
// friction), as real static friction does. The force is not a gradient (N
// varies with the penetration); its matrix is the velocity tangent's form
// N A / s (symmetric, positive semi-definite; the rank-one term and the
// derivative through N left out), and the static solver's merit counts its
// work along each step (StaticSolver).
//
// Bodies (PointPotential, PointDissipation): a body point r on the bed has its own
// spring k [N/m] and damper c [N s/m] on the penetration along the bed's
// up (the same gap g as the cable's, so a point on a grid bed sees the grid):
// U = k p^2 / 2, force k p grad g, damping -c pdot n, isotropic Coulomb
// friction mu N (N = k p |grad g|) regularised by v_s, and the same static
// friction as the cable's with mu_a = mu_t = mu.
//
// Units SI. Used by MultibodyModel only when the scene has a seabed; the
// plane's loops only test whether a grid is present.

#include <memory>
#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "engine/forces/force_contributor.h"

#include "engine/forces/bathymetry_grid.h"
#include "engine/scene/scene.h"

namespace cablesim {

class Seabed {
 public:
  // `spec` must be enabled with stiffness > 0 and a unit normal.
  explicit Seabed(const SeabedSpec& spec);

  // Whether velocity-dependent forces (damping or friction) act.
  bool dissipates() const { return c_ != 0 || mu_a_ != 0 || mu_t_ != 0; }
  bool has_friction() const { return mu_a_ != 0 || mu_t_ != 0; }

  // For an element of undeformed length `length` [m] at coordinates e
  // (AncfCableElement<D> layout): adds the gradient of the bed's energy
  // dU/de (minus its generalized force, as AncfCableElement::ElasticForce
  // adds dU/de) to `gradient`, its Hessian d^2U/de^2 to `hessian` when not
  // null and a bound on the rounding of the gradient to `roundoff` when not
  // null. Returns U [J]. Allocates nothing.
  template <int D>
  double AddPotential(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                      Eigen::Matrix<double, 4 * D, 1>* gradient,
                      Eigen::Matrix<double, 4 * D, 4 * D>* hessian,
                      Eigen::Matrix<double, 4 * D, 1>* roundoff = nullptr) const;

  // The bed's energy U [J] alone.
  template <int D>
  double Energy(const Eigen::Matrix<double, 4 * D, 1>& e, double length) const;

  // Adds the generalized damping and friction force Q_d to `force` and its
  // velocity tangent -dQ_d/d(edot) (symmetric positive semi-definite, see
  // above) to `c` when not null. When `position` is not null, adds the
  // damping's position tangent -dQ_d/de there: on a plane bed the exact
  // one of the damping c (the ends of the pieces in the bed move with e,
  // and the damping force does not vanish there; symmetric, indefinite),
  // friction's left out as above; on a grid bed only the ends' part
  // (exact on a uniformly sloped grid).
  // Returns the power they dissipate, -Q_d . edot >= 0 [W].
  template <int D>
  double AddDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                        const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                        Eigen::Matrix<double, 4 * D, 1>* force,
                        Eigen::Matrix<double, 4 * D, 4 * D>* c,
                        Eigen::Matrix<double, 4 * D, 4 * D>* position = nullptr) const;

  // STATIC analyses: adds the static friction force q_s integrated with
  // the shape functions (a generalized force, like AddDissipation's) to
  // `force` and its matrix -dQ_s/de (the symmetric form above) to `matrix`
  // when not null; e0 the element's coordinates where the analysis
  // started.
  template <int D>
  void AddStaticFriction(const Eigen::Matrix<double, 4 * D, 1>& e,
                           const Eigen::Matrix<double, 4 * D, 1>& e0, double length,
                           Eigen::Matrix<double, 4 * D, 1>* force,
                           Eigen::Matrix<double, 4 * D, 4 * D>* matrix) const;
  bool has_static_friction() const { return has_friction(); }

  // A body point at r with a spring k [N/m]: adds dU/dr to `gradient` and
  // d^2U/dr^2 to `hessian` when not null; returns U [J].
  template <int D>
  double PointPotential(const Eigen::Matrix<double, D, 1>& r, double k,
                        Eigen::Matrix<double, D, 1>* gradient,
                        Eigen::Matrix<double, D, D>* hessian) const;
  // Its damping c [N s/m] and friction mu at velocity v: adds the force to
  // `force` and its velocity tangent to `tangent` when not null; returns
  // the power dissipated [W].
  template <int D>
  double PointDissipation(const Eigen::Matrix<double, D, 1>& r,
                          const Eigen::Matrix<double, D, 1>& v, double k, double c, double mu,
                          Eigen::Matrix<double, D, 1>* force,
                          Eigen::Matrix<double, D, D>* tangent) const;
  // Its static friction (force and matrix), r0 where the analysis started.
  template <int D>
  void PointStaticFriction(const Eigen::Matrix<double, D, 1>& r,
                             const Eigen::Matrix<double, D, 1>& r0, double k, double mu,
                             Eigen::Matrix<double, D, 1>* force,
                             Eigen::Matrix<double, D, D>* matrix) const;

  // The pieces [xi0, xi1] of [0, 1] where the element is in a plane bed
  // (h < 0), at most 2; returns their number. Public for tests.
  template <int D>
  int ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                    double pieces[2][2]) const;

  // Height above the bed [m] of a point (along the grid's up axis with a
  // bathymetry grid).
  double Height(const Eigen::Vector3d& r) const {
    return grid_ ? GridHeight(r) : depth_ + normal_.dot(r);
  }

  // The bathymetry grid, or null for a plane bed.
  const BathymetryGrid* grid() const { return grid_ ? &*grid_ : nullptr; }

 private:
  double GridHeight(const Eigen::Vector3d& r) const;
  // Calls f(xi0, xi1) for every piece of the element in a grid bed (within
  // one cell and in the bed), and line_crossed(xi, axis) (axis 0: a u
  // line, 1: a v line) where a piece in the bed crosses a grid line.
  template <int D, typename F, typename L>
  void ForEachGridPiece(const Eigen::Matrix<double, 4 * D, 1>& e, double length, F&& f,
                        L&& line_crossed) const;
  // The grid bed at a point r: the height g, its gradient and Hessian.
  template <int D>
  double GridAt(const Eigen::Matrix<double, D, 1>& r, Eigen::Matrix<double, D, 1>* grad,
                Eigen::Matrix<double, D, D>* hess) const;
  template <int D>
  double GridPotential(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                       Eigen::Matrix<double, 4 * D, 1>* gradient,
                       Eigen::Matrix<double, 4 * D, 4 * D>* hessian,
                       Eigen::Matrix<double, 4 * D, 1>* roundoff) const;
  // Damping c and friction regularised at `speed` on the rate edot (the
  // dynamic law), or friction alone on a displacement (statics, with
  // rate_tangent false: contact::PointDissipation). Returns the power.
  template <int D>
  double GridDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                         const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                         Eigen::Matrix<double, 4 * D, 1>* force,
                         Eigen::Matrix<double, 4 * D, 4 * D>* c, double damping,
                         double speed, double moordyn_damping,
                         Eigen::Matrix<double, 4 * D, 4 * D>* position = nullptr,
                         bool rate_tangent = true) const;
  template <int D>
  double PlaneDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                          const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                          Eigen::Matrix<double, 4 * D, 1>* force,
                          Eigen::Matrix<double, 4 * D, 4 * D>* c, double damping,
                          double speed, double moordyn_damping,
                          Eigen::Matrix<double, 4 * D, 4 * D>* position = nullptr,
                          bool rate_tangent = true) const;
  // The gap g at a point of D coordinates, its gradient (and, on a grid,
  // Hessian when not null).
  template <int D>
  double GapAt(const Eigen::Matrix<double, D, 1>& r, Eigen::Matrix<double, D, 1>* grad,
               Eigen::Matrix<double, D, D>* hess) const;

  double depth_ = 0;
  Eigen::Vector3d normal_ = Eigen::Vector3d::UnitY();
  double k_ = 0, c_ = 0, mu_a_ = 0, mu_t_ = 0, v_s_ = 1e-3, u_s_ = 1e-5;
  // MoorDyn's friction law (seabed.friction_law MOORDYN): its damping
  // [N s/m^2] (0: the regularised Coulomb law) and static scale.
  double moordyn_c_ = 0, moordyn_scale_ = 1;
  std::optional<BathymetryGrid> grid_;  // only with a bathymetry grid
};

// The seabed under the scene's cables as an ElementTerm: the bed's energy
// and force (energy.contact), its damping and friction, its static friction.
// A cable with its own stiffness and damping (CableSpec::seabed_*) lies on
// a bed of its own with those (the same plane or grid and friction).
class CableSeabed : public ElementTerm {
 public:
  explicit CableSeabed(const SeabedSpec& spec) { beds_.emplace_back(spec); }
  // `bed_of_element[k]`: the index in `beds` of element k's bed (every
  // element's; beds[0] the scene's).
  CableSeabed(std::vector<Seabed> beds, std::vector<int> bed_of_element)
      : beds_(std::move(beds)), bed_of_(std::move(bed_of_element)) {}
  // The scene's bed.
  const Seabed& bed() const { return beds_.front(); }

  std::string_view name() const override { return "cable_seabed"; }
  double AddPotential(const ElementCoords<2>& e, double length, ElementCoords<2>* gradient,
                      ElementMatrix<2>* hessian, ElementCoords<2>* roundoff) const override;
  double AddPotential(const ElementCoords<3>& e, double length, ElementCoords<3>* gradient,
                      ElementMatrix<3>* hessian, ElementCoords<3>* roundoff) const override;
  double Energy(const ElementCoords<2>& e, double length) const override;
  double Energy(const ElementCoords<3>& e, double length) const override;
  double AddElementPotential(const ElementAt<2>& at, const ElementCoords<2>& e,
                             ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                             ElementCoords<2>* roundoff) const override;
  double AddElementPotential(const ElementAt<3>& at, const ElementCoords<3>& e,
                             ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                             ElementCoords<3>* roundoff) const override;
  void AddElementEnergy(const ElementAt<2>& at, const ElementCoords<2>& e,
                        double* energy) const override;
  void AddElementEnergy(const ElementAt<3>& at, const ElementCoords<3>& e,
                        double* energy) const override;
  bool dissipates() const override;
  double AddDissipation(const ElementCoords<2>& e, const ElementCoords<2>& edot, double length,
                        ElementCoords<2>* force, ElementMatrix<2>* c) const override;
  double AddDissipation(const ElementCoords<3>& e, const ElementCoords<3>& edot, double length,
                        ElementCoords<3>* force, ElementMatrix<3>* c) const override;
  double AddElementDissipation(const ElementAt<2>& at, const ElementCoords<2>& e,
                               const ElementCoords<2>& edot, ElementCoords<2>* force,
                               ElementMatrix<2>* c) const override;
  double AddElementDissipation(const ElementAt<3>& at, const ElementCoords<3>& e,
                               const ElementCoords<3>& edot, ElementCoords<3>* force,
                               ElementMatrix<3>* c) const override;
  bool has_static_friction() const override { return bed().has_friction(); }
  void AddStaticFriction(const ElementCoords<2>& e, const ElementCoords<2>& e0, double length,
                         ElementCoords<2>* force, ElementMatrix<2>* matrix) const override;
  void AddStaticFriction(const ElementCoords<3>& e, const ElementCoords<3>& e0, double length,
                         ElementCoords<3>* force, ElementMatrix<3>* matrix) const override;
  void AddElementStaticFriction(int index, const ElementCoords<2>& e, const ElementCoords<2>& e0,
                                double length, ElementCoords<2>* force,
                                ElementMatrix<2>* matrix) const override;
  void AddElementStaticFriction(int index, const ElementCoords<3>& e, const ElementCoords<3>& e0,
                                double length, ElementCoords<3>* force,
                                ElementMatrix<3>* matrix) const override;

 private:
  // Element `index`'s bed.
  const Seabed& BedOf(int index) const {
    return bed_of_.empty() ? beds_.front() : beds_[bed_of_[index]];
  }
  std::vector<Seabed> beds_;
  std::vector<int> bed_of_;  // empty: every element on beds_[0]
};

// The term for the scene's seabed under its cables, or null without one.
// `cable_element_begin[c]`: cable c's first element in the model's element
// list (and its size the list's), for the cables with a bed of their own.
std::unique_ptr<CableSeabed> MakeCableSeabed(const Scene& scene,
                                             const std::vector<int>& cable_element_begin);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_SEABED_H_
