#include "engine/forces/sheave.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/forces/contact_point.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"

namespace cablesim {
namespace {

constexpr int kSamples = 16;  // sub-intervals of an element searched for crossings

// 8 points per contact piece (the integrands are smooth, not polynomial).
const GaussRule& PieceRule() {
  static const GaussRule rule = MakeGaussRule(8);
  return rule;
}

}  // namespace

Sheave::Sheave(const SheaveSpec& spec, bool exact_tangent)
    : centre_(spec.position_m),
      axis_(spec.axis.normalized()),
      radius_(spec.radius_m),
      k_(spec.stiffness_n_m2),
      c_(spec.damping_n_s_m2),
      mu_(spec.friction),
      v_s_(spec.friction_speed_m_s),
      body_(spec.body),
      exact_tangent_(exact_tangent) {}

template <int D>
int Sheave::ContactPieces(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                          const Eigen::Matrix<double, D, 1>& c, double pieces[kMaxPieces][2]) const {
  using Point = Eigen::Matrix<double, D, 1>;
  // The offset from the axis in the wheel's plane.
  auto in_plane = [&](const Point& x) -> Point {
    Point rho = x - c;
    if constexpr (D == 3) rho -= axis_.dot(rho) * axis_;
    return rho;
  };
  // The Bezier control points of the cubic contain it: if the ball around
  // their middle that holds them all stays outside the cylinder, so does
  // the element.
  const Point r0 = e.template segment<D>(0), r1 = e.template segment<D>(2 * D);
  const Point b1 = r0 + (length / 3) * e.template segment<D>(D);
  const Point b2 = r1 - (length / 3) * e.template segment<D>(3 * D);
  const Point mid = 0.5 * (r0 + r1);
  const double ball = std::max({(r0 - mid).norm(), (b1 - mid).norm(), (b2 - mid).norm(),
                                (r1 - mid).norm()});
  if (in_plane(mid).norm() - ball > radius_) return 0;
  auto gap = [&](double xi) {
    double s[4];
    HermiteShape(xi, length, s);
    Point r = Point::Zero();
    for (int k = 0; k < 4; ++k) r += s[k] * e.template segment<D>(k * D);
    return in_plane(r).norm() - radius_;
  };
  int count = 0;
  double xa = 0, ga = gap(0), start = 0;
  bool open = ga < 0;
  for (int j = 1; j <= kSamples; ++j) {
    const double xb = static_cast<double>(j) / kSamples;
    const double gb = gap(xb);
    if ((ga < 0) != (gb < 0)) {
      const double root = contact::BisectSign(gap, xa, xb);
      if (ga < 0) {
        if (root > start && count < kMaxPieces) {
          pieces[count][0] = start;
          pieces[count++][1] = root;
        }
        open = false;
      } else {
        start = root;
        open = true;
      }
    }
    xa = xb;
    ga = gb;
  }
  if (open && start < 1 && count < kMaxPieces) {
    pieces[count][0] = start;
    pieces[count++][1] = 1;
  }
  return count;
}

namespace {

// One Gauss point of a piece of an element inside the wheel: its weight
// times the element length wl [m], the shape values (then -1 for a body's
// centre: the offset r - c is linear in both) and their x-derivatives, the
// point r, slope u, the projector P on the wheel's plane, the distance d
// from the axis, the penetration pen > 0, the outward normal n, and a size
// for the rounding bound.
template <int D>
struct InsidePoint {
  double wl = 0;
  double s[5] = {0, 0, 0, 0, -1};
  double ds[4] = {0, 0, 0, 0};
  Eigen::Matrix<double, D, 1> r, u, n;
  Eigen::Matrix<double, D, D> proj;
  double d = 0, pen = 0, size = 0;
};

// m += wl s_k s_m h on every block (k, m) of B blocks of size D.
template <int D, int B>
void AddBlocks(double wl, const double* s, const Eigen::Matrix<double, D, D>& h,
               Eigen::Matrix<double, B * D, B * D>* m) {
  for (int k = 0; k < B; ++k)
    for (int j = 0; j < B; ++j) m->template block<D, D>(k * D, j * D) += (wl * s[k] * s[j]) * h;
}

}  // namespace

template <int D, typename F>
void Sheave::ForEachPointInside(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                                const Eigen::Matrix<double, D, 1>& c, F&& f) const {
  double pieces[kMaxPieces][2];
  const int count = ContactPieces<D>(e, length, c, pieces);
  if (count == 0) return;
  InsidePoint<D> pt;
  pt.proj.setIdentity();
  if constexpr (D == 3) pt.proj -= axis_ * axis_.transpose();
  const GaussRule& rule = PieceRule();
  for (int p = 0; p < count; ++p) {
    const double a = pieces[p][0], span = pieces[p][1] - a;
    for (int g = 0; g < rule.n; ++g) {
      const double xi = a + span * rule.xi[g];
      HermiteShape(xi, length, pt.s);
      HermiteShapeD1(xi, length, pt.ds);
      pt.wl = rule.weight[g] * span * length;
      pt.r.setZero();
      pt.u.setZero();
      pt.size = c.template lpNorm<1>() + radius_;
      for (int k = 0; k < 4; ++k) {
        pt.r += pt.s[k] * e.template segment<D>(k * D);
        pt.u += pt.ds[k] * e.template segment<D>(k * D);
        pt.size += std::abs(pt.s[k]) * e.template segment<D>(k * D).template lpNorm<1>();
      }
      const Eigen::Matrix<double, D, 1> rho = pt.proj * (pt.r - c);
      pt.d = rho.norm();
      pt.pen = radius_ - pt.d;
      // At the axle the direction is undefined; a cable there is deep in
      // the wheel and the outward push is taken as zero.
      if (!(pt.pen > 0) || pt.d <= 1e-12 * radius_) continue;
      pt.n = rho / pt.d;
      f(pt);
    }
  }
}

template <int D, int B>
double Sheave::Potential(const Eigen::Matrix<double, B * D, 1>& x, double length,
                         const Eigen::Matrix<double, D, 1>& c,
                         Eigen::Matrix<double, B * D, 1>* gradient,
                         Eigen::Matrix<double, B * D, B * D>* hessian,
                         Eigen::Matrix<double, B * D, 1>* roundoff) const {
  using Block = Eigen::Matrix<double, D, D>;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  double energy = 0;
  ForEachPointInside<D>(x.template head<4 * D>(), length, c, [&](const InsidePoint<D>& pt) {
    const double wl = pt.wl, pen = pt.pen;
    energy += wl * 0.5 * k_ * pen * pen;
    if (gradient)
      for (int k = 0; k < B; ++k)
        gradient->template segment<D>(k * D) -= (wl * k_ * pen * pt.s[k]) * pt.n;
    if (roundoff) {
      const double bound = wl * k_ * kEps * pt.size;
      for (int k = 0; k < B; ++k)
        roundoff->template segment<D>(k * D).array() += bound * std::abs(pt.s[k]);
    }
    if (hessian) {
      const Block nn = pt.n * pt.n.transpose();
      const Block h = exact_tangent_ ? (k_ * (nn - (pen / pt.d) * (pt.proj - nn))).eval()
                                     : (k_ * nn).eval();
      AddBlocks<D, B>(wl, pt.s, h, hessian);
    }
  });
  return energy;
}

template <int D, int B>
double Sheave::Dissipation(const Eigen::Matrix<double, B * D, 1>& x,
                           const Eigen::Matrix<double, B * D, 1>& xdot, double length,
                           const Eigen::Matrix<double, D, 1>& c,
                           Eigen::Matrix<double, B * D, 1>* force,
                           Eigen::Matrix<double, B * D, B * D>* cmat) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  double power = 0;
  ForEachPointInside<D>(x.template head<4 * D>(), length, c, [&](const InsidePoint<D>& pt) {
    // The sliding velocity: the cable's minus the wheel centre's.
    Point v = Point::Zero();
    for (int k = 0; k < B; ++k) v += pt.s[k] * xdot.template segment<D>(k * D);
    const Block surface = Block::Identity() - pt.n * pt.n.transpose();
    Point q;
    Block h;
    power += pt.wl * contact::PointDissipation<D>(pt.n, surface, k_ * pt.pen, v, pt.u, c_, mu_,
                                                  mu_, v_s_, &q, &h);
    for (int k = 0; k < B; ++k) force->template segment<D>(k * D) += (pt.wl * pt.s[k]) * q;
    if (cmat) AddBlocks<D, B>(pt.wl, pt.s, h, cmat);
  });
  return power;
}

#define CABLESIM_SHEAVE_INSTANTIATE(D)                                                      \
  template double Sheave::Potential<D, 4>(                                                  \
      const Eigen::Matrix<double, 4 * D, 1>&, double, const Eigen::Matrix<double, D, 1>&,  \
      Eigen::Matrix<double, 4 * D, 1>*, Eigen::Matrix<double, 4 * D, 4 * D>*,             \
      Eigen::Matrix<double, 4 * D, 1>*) const;                                              \
  template double Sheave::Potential<D, 5>(                                                  \
      const Eigen::Matrix<double, 5 * D, 1>&, double, const Eigen::Matrix<double, D, 1>&,  \
      Eigen::Matrix<double, 5 * D, 1>*, Eigen::Matrix<double, 5 * D, 5 * D>*,             \
      Eigen::Matrix<double, 5 * D, 1>*) const;                                              \
  template double Sheave::Dissipation<D, 4>(                                                \
      const Eigen::Matrix<double, 4 * D, 1>&, const Eigen::Matrix<double, 4 * D, 1>&,      \
      double, const Eigen::Matrix<double, D, 1>&, Eigen::Matrix<double, 4 * D, 1>*,        \
      Eigen::Matrix<double, 4 * D, 4 * D>*) const;                                          \
  template double Sheave::Dissipation<D, 5>(                                                \
      const Eigen::Matrix<double, 5 * D, 1>&, const Eigen::Matrix<double, 5 * D, 1>&,      \
      double, const Eigen::Matrix<double, D, 1>&, Eigen::Matrix<double, 5 * D, 1>*,        \
      Eigen::Matrix<double, 5 * D, 5 * D>*) const;                                          \
  template int Sheave::ContactPieces<D>(const Eigen::Matrix<double, 4 * D, 1>&, double,    \
                                        const Eigen::Matrix<double, D, 1>&,                 \
                                        double[Sheave::kMaxPieces][2]) const;
CABLESIM_SHEAVE_INSTANTIATE(2)
CABLESIM_SHEAVE_INSTANTIATE(3)
#undef CABLESIM_SHEAVE_INSTANTIATE

}  // namespace cablesim
