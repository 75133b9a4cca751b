#ifndef CABLESIM_ENGINE_FORCES_CONTACT_POINT_H_
#define CABLESIM_ENGINE_FORCES_CONTACT_POINT_H_

// Pieces shared by the distributed contacts of cables with surfaces (the
// seabed, engine/forces/seabed.h, and sheaves, engine/forces/sheave.h): the
// damping and Coulomb friction at one point of the surface, the scatter of
// a point's D x D block onto an element's node blocks, and the bisection
// that finds where an element enters or leaves the surface. Units SI.

#include <cmath>

#include <Eigen/Core>

namespace cablesim {
namespace contact {

// m += wl s_k s_m h on every node block (k, m).
template <int D>
void AddShapeBlocks(double wl, const double* s, const Eigen::Matrix<double, D, D>& h,
                    Eigen::Matrix<double, 4 * D, 4 * D>* m) {
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) m->template block<D, D>(k * D, j * D) += (wl * s[k] * s[j]) * h;
}

// The damping and friction per unit length at one point of a bed with unit
// normal n (proj = I - n n^T) under the elastic normal force `normal_force`
// [N/m], velocity v and tangent u: adds the force to *q and its velocity
// tangent to *h; returns the power they dissipate per unit length [W/m].
// `rate_tangent` false leaves out the tangent of the friction's size in
// the rate (statics, where a displacement stands for v: there the friction
// saturated along the slide would leave Newton's matrix without stiffness
// along it, and the load increments of scenes/mooring-three-line-buoy.json
// no longer converged).
template <int D>
double PointDissipation(const Eigen::Matrix<double, D, 1>& n,
                        const Eigen::Matrix<double, D, D>& proj, double normal_force,
                        const Eigen::Matrix<double, D, 1>& v,
                        const Eigen::Matrix<double, D, 1>& u, double c, double mu_a, double mu_t,
                        double v_s, Eigen::Matrix<double, D, 1>* q,
                        Eigen::Matrix<double, D, D>* h, double moordyn_damping = 0,
                        double moordyn_scale = 1, bool rate_tangent = true) {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  const double vn = n.dot(v);
  *q = (-c * vn) * n;
  *h = c * n * n.transpose();
  double power = c * vn * vn;
  if ((mu_a != 0 || mu_t != 0) && normal_force > 0) {
    const Point vb = v - vn * n;
    Point t = proj * u;
    const double tn = t.norm();
    Block amat = mu_t * proj;  // the friction's A: q_f = -N A v_b / s
    if (tn > 0) {
      t /= tn;
      amat += (mu_a - mu_t) * t * t.transpose();
    }
    // MoorDyn's law (moordyn_damping c > 0): viscous, q_f = -c A v_b,
    // while c |v_b| <= moordyn_scale N, else Coulomb's -N A v_b / |v_b|.
    const double speed = vb.norm();
    const bool viscous =
        moordyn_damping > 0 && moordyn_damping * speed <= moordyn_scale * normal_force;
    const double factor =
        moordyn_damping > 0 ? (viscous ? moordyn_damping : normal_force / speed)
                            : normal_force / std::sqrt(speed * speed + v_s * v_s);
    const Point avb = amat * vb;
    const Point qf = -factor * avb;
    *q += qf;
    *h += factor * amat;
    // Where the friction's size is rate-dependent (regularised Coulomb, or
    // MoorDyn's Coulomb branch), factor depends on v_b too:
    // d factor / d v = -factor v_b^T / s^2 (s^2 = |v_b|^2 + v_s^2, or
    // |v_b|^2), so -d q_f / d v gains -(factor / s^2) (A v_b) v_b^T. The
    // Newton matrix is symmetric, so it takes the symmetric positive
    // semi-definite -(factor / s^2) |v_b|^2 (A v_b)(A v_b)^T / (v_b^T A v_b):
    // the same term when mu_a = mu_t (A v_b along v_b), and never more than
    // factor A removes (Cauchy-Schwarz in A). Without it Newton converged
    // linearly on a sliding chain (scenes/mooring-chain-landing.json: 32,347
    // iterations for 3,006 steps, 6,493 for 3,000 with it).
    const double avb_vb = avb.dot(vb);
    if (rate_tangent && !(moordyn_damping > 0 && viscous) && avb_vb > 0) {
      const double s2 = moordyn_damping > 0 ? speed * speed : speed * speed + v_s * v_s;
      *h -= (factor * speed * speed / (s2 * avb_vb)) * (avb * avb.transpose());
    }
    power -= qf.dot(vb);
  }
  return power;
}

// The root of f on [a, b] (f(a) < 0 <= f(b) or the reverse, f continuous
// and crossing once), by bisection to the last bit (at most `rounds`
// halvings).
template <typename F>
double BisectSign(const F& f, double a, double b, int rounds = 200) {
  const bool rising = f(a) < 0;
  for (int i = 0; i < rounds; ++i) {
    const double m = 0.5 * (a + b);
    if (m <= a || m >= b) break;
    if ((f(m) < 0) == rising) {
      a = m;
    } else {
      b = m;
    }
  }
  return 0.5 * (a + b);
}

}  // namespace contact
}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CONTACT_POINT_H_
