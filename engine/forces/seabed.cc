#include "engine/forces/seabed.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/gauss_quadrature.h"
#include "engine/hermite_shape.h"

namespace cablesim {
namespace {

struct Cubic {
  double c[4];
  double operator()(double x) const { return c[0] + x * (c[1] + x * (c[2] + x * c[3])); }
};

// The root of the monotone f on [a, b] (f(a), f(b) of opposite signs), by
// bisection to the last bit.
double Bisect(const Cubic& f, double a, double b) {
  const bool rising = f(a) < 0;
  for (int i = 0; i < 200; ++i) {
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

// Calls f(wl, s, ds) at the 4 Gauss points of every contact piece: the
// weight times the element length [m], the shape functions and their
// x-derivatives there.
template <typename F>
void ForEachContactPoint(const double pieces[2][2], int count, double length, F&& f) {
  // 4 points: exact to degree 7, the integrands are of degree 6.
  static const GaussRule rule = MakeGaussRule(4);
  for (int p = 0; p < count; ++p) {
    const double a = pieces[p][0], span = pieces[p][1] - a;
    for (int g = 0; g < rule.n; ++g) {
      double s[4], ds[4];
      const double xi = a + span * rule.xi[g];
      HermiteShape(xi, length, s);
      HermiteShapeD1(xi, length, ds);
      f(rule.weight[g] * span * length, s, ds);
    }
  }
}

// m += wl s_k s_m h on every node block (k, m).
template <int D>
void AddShapeBlocks(double wl, const double* s, const Eigen::Matrix<double, D, D>& h,
                    Eigen::Matrix<double, 4 * D, 4 * D>* m) {
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j) m->template block<D, D>(k * D, j * D) += (wl * s[k] * s[j]) * h;
}

}  // namespace

Seabed::Seabed(const SeabedSpec& spec)
    : depth_(spec.depth_m),
      normal_(spec.normal.normalized()),
      k_(spec.stiffness_n_m2),
      c_(spec.damping_n_s_m2),
      mu_a_(spec.friction_axial),
      mu_t_(spec.friction_transverse),
      v_s_(spec.friction_speed_m_s) {}

template <int D>
int Seabed::ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                          double pieces[2][2]) const {
  const auto n = normal_.head<D>();
  const double a0 = n.dot(e.template segment<D>(0)), b0 = n.dot(e.template segment<D>(D));
  const double a1 = n.dot(e.template segment<D>(2 * D)), b1 = n.dot(e.template segment<D>(3 * D));
  const double l = length;
  const Cubic h{{depth_ + a0, l * b0, -3 * a0 - 2 * l * b0 + 3 * a1 - l * b1,
                 2 * a0 + l * b0 - 2 * a1 + l * b1}};
  // h >= c0 - |c1| - |c2| - |c3| on [0, 1]: most elements end here.
  if (h.c[0] - std::abs(h.c[1]) - std::abs(h.c[2]) - std::abs(h.c[3]) > 0) return 0;
  // Monotone pieces: split at the roots of h' = c1 + 2 c2 x + 3 c3 x^2.
  double br[4] = {0, 0, 0, 0};
  int nbr = 0;
  br[nbr++] = 0;
  const double qa = 3 * h.c[3], qb = 2 * h.c[2], qc = h.c[1];
  double crit[2];
  int ncrit = 0;
  if (qa != 0) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc > 0) {
      // Stable quadratic roots.
      const double t = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
      crit[ncrit++] = t / qa;
      if (t != 0) crit[ncrit++] = qc / t;
    }
  } else if (qb != 0) {
    crit[ncrit++] = -qc / qb;
  }
  std::sort(crit, crit + ncrit);
  for (int i = 0; i < ncrit; ++i)
    if (crit[i] > 0 && crit[i] < 1 && crit[i] > br[nbr - 1]) br[nbr++] = crit[i];
  // Roots of h on each monotone piece.
  double cuts[5];
  int ncuts = 0;
  cuts[ncuts++] = 0;
  double prev = 0;
  for (int i = 0; i < nbr; ++i) {
    const double a = br[i], b = i + 1 < nbr ? br[i + 1] : 1.0;
    if ((h(a) < 0) != (h(b) < 0)) {
      const double r = Bisect(h, a, b);
      if (r > prev && r < 1) {
        cuts[ncuts++] = r;
        prev = r;
      }
    }
  }
  cuts[ncuts++] = 1;
  int count = 0;
  for (int i = 0; i + 1 < ncuts; ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(h(0.5 * (a + b)) < 0)) continue;
    if (count > 0 && pieces[count - 1][1] == a) {
      pieces[count - 1][1] = b;  // a touching point: one piece
    } else if (count < 2) {
      pieces[count][0] = a;
      pieces[count][1] = b;
      ++count;
    }
  }
  return count;
}

template <int D>
double Seabed::AddPotential(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                            Eigen::Matrix<double, 4 * D, 1>* gradient,
                            Eigen::Matrix<double, 4 * D, 4 * D>* hessian,
                            Eigen::Matrix<double, 4 * D, 1>* roundoff) const {
  using Point = Eigen::Matrix<double, D, 1>;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double pieces[2][2];
  const int count = ContactPieces<D>(e, length, pieces);
  if (count == 0) return 0;
  const Point n = normal_.head<D>();
  const Eigen::Matrix<double, D, D> nn = k_ * n * n.transpose();
  double energy = 0;
  ForEachContactPoint(pieces, count, length, [&](double wl, const double* s, const double* ds) {
    (void)ds;
    Point r = Point::Zero();
    double size = std::abs(depth_);
    for (int k = 0; k < 4; ++k) {
      r += s[k] * e.template segment<D>(k * D);
      size += std::abs(s[k]) * e.template segment<D>(k * D).template lpNorm<1>();
    }
    const double pen = std::max(0.0, -(depth_ + n.dot(r)));
    energy += wl * 0.5 * k_ * pen * pen;
    if (gradient)
      for (int k = 0; k < 4; ++k)
        gradient->template segment<D>(k * D) -= (wl * k_ * pen * s[k]) * n;
    if (roundoff)
      for (int k = 0; k < 4; ++k)
        roundoff->template segment<D>(k * D) +=
            (wl * k_ * kEps * size * std::abs(s[k])) * n.cwiseAbs();
    if (hessian) AddShapeBlocks<D>(wl, s, nn, hessian);
  });
  return energy;
}

template <int D>
double Seabed::Energy(const Eigen::Matrix<double, 4 * D, 1>& e, double length) const {
  return AddPotential<D>(e, length, nullptr, nullptr);
}

template <int D>
double Seabed::AddDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                              const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                              Eigen::Matrix<double, 4 * D, 1>* force,
                              Eigen::Matrix<double, 4 * D, 4 * D>* c) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  double pieces[2][2];
  const int count = ContactPieces<D>(e, length, pieces);
  if (count == 0) return 0;
  const Point n = normal_.head<D>();
  const Block proj = Block::Identity() - n * n.transpose();
  double power = 0;
  ForEachContactPoint(pieces, count, length, [&](double wl, const double* s, const double* ds) {
    Point r = Point::Zero(), v = Point::Zero(), u = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      r += s[k] * e.template segment<D>(k * D);
      u += ds[k] * e.template segment<D>(k * D);
      v += s[k] * edot.template segment<D>(k * D);
    }
    const double pen = std::max(0.0, -(depth_ + n.dot(r)));
    const double vn = n.dot(v);
    Point q = (-c_ * vn) * n;
    Block h = c_ * n * n.transpose();
    power += c_ * vn * vn * wl;
    const double normal_force = k_ * pen;
    if ((mu_a_ != 0 || mu_t_ != 0) && normal_force > 0) {
      const Point vb = v - vn * n;
      Point t = proj * u;
      const double tn = t.norm();
      Block amat = mu_t_ * proj;  // the friction's A: q_f = -N A v_b / s
      if (tn > 0) {
        t /= tn;
        amat += (mu_a_ - mu_t_) * t * t.transpose();
      }
      const double sq = std::sqrt(vb.squaredNorm() + v_s_ * v_s_);
      const Point qf = (-normal_force / sq) * (amat * vb);
      q += qf;
      h += (normal_force / sq) * amat;
      power -= wl * qf.dot(vb);
    }
    if (force)
      for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) += (wl * s[k]) * q;
    if (c) AddShapeBlocks<D>(wl, s, h, c);
  });
  return power;
}

#define CABLESIM_SEABED_INSTANTIATE(D)                                                       \
  template int Seabed::ContactPieces<D>(const Eigen::Matrix<double, 4 * D, 1>&, double,    \
                                        double[2][2]) const;                               \
  template double Seabed::AddPotential<D>(                                                 \
      const Eigen::Matrix<double, 4 * D, 1>&, double, Eigen::Matrix<double, 4 * D, 1>*,    \
      Eigen::Matrix<double, 4 * D, 4 * D>*, Eigen::Matrix<double, 4 * D, 1>*) const;       \
  template double Seabed::Energy<D>(const Eigen::Matrix<double, 4 * D, 1>&, double) const; \
  template double Seabed::AddDissipation<D>(                                               \
      const Eigen::Matrix<double, 4 * D, 1>&, const Eigen::Matrix<double, 4 * D, 1>&,      \
      double, Eigen::Matrix<double, 4 * D, 1>*, Eigen::Matrix<double, 4 * D, 4 * D>*) const;
CABLESIM_SEABED_INSTANTIATE(2)
CABLESIM_SEABED_INSTANTIATE(3)
#undef CABLESIM_SEABED_INSTANTIATE

}  // namespace cablesim
