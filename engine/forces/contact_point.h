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
template <int D>
double PointDissipation(const Eigen::Matrix<double, D, 1>& n,
                        const Eigen::Matrix<double, D, D>& proj, double normal_force,
                        const Eigen::Matrix<double, D, 1>& v,
                        const Eigen::Matrix<double, D, 1>& u, double c, double mu_a, double mu_t,
                        double v_s, Eigen::Matrix<double, D, 1>* q,
                        Eigen::Matrix<double, D, D>* h, double moordyn_damping = 0,
                        double moordyn_scale = 1) {
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
    const Point qf = -factor * (amat * vb);
    *q += qf;
    *h += factor * amat;
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
