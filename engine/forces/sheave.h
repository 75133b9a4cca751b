#ifndef CABLESIM_ENGINE_FORCES_SHEAVE_H_
#define CABLESIM_ENGINE_FORCES_SHEAVE_H_

// A fixed wheel (a sheave, a drum, a bollard) that cables wrap around: the
// cable is pushed out of the wheel's cylinder by a distributed spring and
// damper per unit undeformed length, like the seabed (engine/forces/
// seabed.h), and rubs on it with Coulomb friction. The cable needs no node
// where it touches the wheel and may run over it freely: the contact
// follows the cable, not a material point, so a rope reeved over a sheave
// slides through without any joint.
//
// Geometry: centre c [m], unit axis a (z in the planar model), radius R [m].
// For a cable point r, rho = P (r - c) with P = I - a a^T (its offset from
// the axis, in the wheel's plane), d = |rho|, n = rho / d the outward
// normal, and the penetration p = max(0, R - d) [m]. Per unit undeformed
// length the wheel pushes with
//
//   q = k p n - c_d pdot n [N/m],   pdot = -n . rdot   (where p > 0),
//
// stores U = int k p^2 / 2 dx [J] (part of energy.contact). The Hessian
// of U per unit length is
//
//   k (n n^T - (p / d) (P - n n^T)),
//
// whose second term (the surface curving away from the cable, -T / R^2 per
// unit length along the surface for a cable under tension T) is negative:
// on a Newton iterate that sinks deep into the wheel it outweighs the mass
// term and makes Newton's matrix indefinite (measured: DIRECT then falls
// back to MINRES). The Newton tangent is therefore k n n^T alone, positive
// semi-definite; what it leaves out is (p / d) of the normal stiffness, so
// Newton still converges fast (linearly at rate ~ T l / (R^2 M / (beta h^2))).
// The exact Hessian is available for tests (exact_tangent). The wheel's cylinder is
// infinitely long along its axis (no flanges or groove): in the spatial
// model a cable may slide along the axis; with friction it is held there
// by the Coulomb force. A wheel hides every cable point inside its
// cylinder, so a cable passing near the axle is pushed out too.
//
// Friction: with N = k p the elastic normal force per unit length and
// v_b the sliding velocity on the (fixed) surface, the regularised
// Coulomb force -N mu v_b / sqrt(|v_b|^2 + v_s^2), isotropic in the
// surface (the seabed's law with mu_axial = mu_transverse;
// engine/forces/contact_point.h). A wheel with friction is one that does
// not turn: a bollard, a capstan or a braked drum; at the onset of slip
// the tensions on its two sides have the capstan ratio T2 / T1 =
// exp(mu theta) (tests/sheave_test.cc). A sheave turning freely on a
// frictionless bearing with negligible inertia holds no tangential force:
// give it friction 0.
//
// Where the element touches: the gap d - R is sampled at 17 points of the
// element; each sign change is bisected to the last bit, and every piece
// inside the wheel is integrated by 8-point Gauss-Legendre (the
// integrands are smooth there but not polynomial: |rho| is a square root;
// the force vanishes at the piece's ends, so its integral has no boundary
// terms). An excursion into the wheel shorter than 1/16 of an element is
// missed: mesh the cable with elements shorter than the radius where it
// wraps (a cubic element bends around at most about a quarter of a turn).
// An element whose Bezier control polygon (which contains it) lies
// outside the wheel's cylinder is rejected before any sampling.
//
// A wheel may be carried by a body (a hook block's sheave): its centre is
// then the body's centre of mass, its axis stays the world axis given (z in
// the planar model; a spatial body's rotation does not turn it), and the
// contact couples the element with the body (AddPotentialOnBody).
//
// Units SI. MultibodyModel holds one per scene sheave, only in scenes with
// sheaves.

#include <Eigen/Core>

#include "engine/scene/scene.h"

namespace cablesim {

class Sheave {
 public:
  // `spec`: radius > 0, stiffness > 0, axis non-zero. With exact_tangent,
  // AddPotential's hessian is U's exact second derivative (tests).
  explicit Sheave(const SheaveSpec& spec, bool exact_tangent = false);

  bool dissipates() const { return c_ != 0 || mu_ != 0; }
  // The body that carries the wheel (index in the scene), or -1: fixed.
  int body() const { return body_; }

  // A fixed wheel. For an element of undeformed length `length` [m] at
  // coordinates e (AncfCableElement<D> layout): adds dU/de to `gradient`
  // (as the elastic force does), the Newton tangent (above) to `hessian`
  // and a bound on the rounding of the gradient to `roundoff` when not
  // null. Returns U [J]. Allocates nothing.
  template <int D>
  double AddPotential(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                      Eigen::Matrix<double, 4 * D, 1>* gradient,
                      Eigen::Matrix<double, 4 * D, 4 * D>* hessian,
                      Eigen::Matrix<double, 4 * D, 1>* roundoff = nullptr) const {
    return Potential<D, 4>(e, length, centre_.head<D>(), gradient, hessian, roundoff);
  }

  // U [J] alone (a fixed wheel).
  template <int D>
  double Energy(const Eigen::Matrix<double, 4 * D, 1>& e, double length) const {
    return AddPotential<D>(e, length, nullptr, nullptr);
  }

  // A fixed wheel: adds the damping and friction force Q_d to `force` and
  // its velocity tangent -dQ_d/d(edot) (symmetric positive semi-definite:
  // the friction's non-symmetric rank-one part is left out, as on the
  // seabed) to `c` when not null. Returns the power dissipated,
  // -Q_d . edot >= 0 [W].
  template <int D>
  double AddDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                        const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                        Eigen::Matrix<double, 4 * D, 1>* force,
                        Eigen::Matrix<double, 4 * D, 4 * D>* c) const {
    return Dissipation<D, 4>(e, edot, length, centre_.head<D>(), force, c);
  }

  // A wheel carried by a body, centred on the body's centre of mass c: the
  // same terms over x = [e; c] (the element's coordinates, then c's D),
  // since r - c is linear in both (c enters with the shape value -1): the
  // wheel takes the opposite of the force it exerts, and friction and
  // damping act on the cable's velocity relative to c.
  template <int D>
  double AddPotentialOnBody(const Eigen::Matrix<double, 5 * D, 1>& x, double length,
                            Eigen::Matrix<double, 5 * D, 1>* gradient,
                            Eigen::Matrix<double, 5 * D, 5 * D>* hessian,
                            Eigen::Matrix<double, 5 * D, 1>* roundoff = nullptr) const {
    return Potential<D, 5>(x, length, x.template tail<D>(), gradient, hessian, roundoff);
  }
  template <int D>
  double AddDissipationOnBody(const Eigen::Matrix<double, 5 * D, 1>& x,
                              const Eigen::Matrix<double, 5 * D, 1>& xdot, double length,
                              Eigen::Matrix<double, 5 * D, 1>* force,
                              Eigen::Matrix<double, 5 * D, 5 * D>* c) const {
    return Dissipation<D, 5>(x, xdot, length, x.template tail<D>(), force, c);
  }

  // The pieces [xi0, xi1] of [0, 1] where the element is inside the
  // cylinder about the axis through c, at most kMaxPieces; returns their
  // number. Public for tests.
  static constexpr int kMaxPieces = 9;
  template <int D>
  int ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                    const Eigen::Matrix<double, D, 1>& c, double pieces[kMaxPieces][2]) const;
  template <int D>
  int ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                    double pieces[kMaxPieces][2]) const {
    return ContactPieces<D>(e, length, centre_.head<D>(), pieces);
  }

  double radius() const { return radius_; }

 private:
  // Over B blocks of D coordinates: the element's 4 nodes, and with B = 5
  // the wheel's centre c.
  template <int D, int B>
  double Potential(const Eigen::Matrix<double, B * D, 1>& x, double length,
                   const Eigen::Matrix<double, D, 1>& c,
                   Eigen::Matrix<double, B * D, 1>* gradient,
                   Eigen::Matrix<double, B * D, B * D>* hessian,
                   Eigen::Matrix<double, B * D, 1>* roundoff) const;
  // Calls f(point) at every Gauss point of the element inside the wheel
  // centred at c (InsidePoint in sheave.cc).
  template <int D, typename F>
  void ForEachPointInside(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                          const Eigen::Matrix<double, D, 1>& c, F&& f) const;
  template <int D, int B>
  double Dissipation(const Eigen::Matrix<double, B * D, 1>& x,
                     const Eigen::Matrix<double, B * D, 1>& xdot, double length,
                     const Eigen::Matrix<double, D, 1>& c, Eigen::Matrix<double, B * D, 1>* force,
                     Eigen::Matrix<double, B * D, B * D>* cmat) const;

  Eigen::Vector3d centre_;
  Eigen::Vector3d axis_;
  double radius_ = 0;
  double k_ = 0, c_ = 0, mu_ = 0, v_s_ = 1e-3;
  int body_ = -1;
  bool exact_tangent_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_SHEAVE_H_
