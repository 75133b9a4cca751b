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
// polynomial terms). STATIC analyses see no friction (no velocities).
//
// Units SI. Used by MultibodyModel only when the scene has a seabed.

#include <Eigen/Core>

#include "engine/scene.h"

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
  // above) to `c` when not null. Returns the power they dissipate,
  // -Q_d . edot >= 0 [W].
  template <int D>
  double AddDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                        const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                        Eigen::Matrix<double, 4 * D, 1>* force,
                        Eigen::Matrix<double, 4 * D, 4 * D>* c) const;

  // The pieces [xi0, xi1] of [0, 1] where the element is in the bed
  // (h < 0), at most 2; returns their number. Public for tests.
  template <int D>
  int ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                    double pieces[2][2]) const;

  // Height above the bed [m] of a point.
  double Height(const Eigen::Vector3d& r) const { return depth_ + normal_.dot(r); }

 private:
  double depth_ = 0;
  Eigen::Vector3d normal_ = Eigen::Vector3d::UnitY();
  double k_ = 0, c_ = 0, mu_a_ = 0, mu_t_ = 0, v_s_ = 1e-3;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_SEABED_H_
