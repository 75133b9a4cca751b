#include "engine/forces/seabed.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/elements/gauss_quadrature.h"
#include "engine/forces/contact_point.h"
#include "engine/forces/element_cubic.h"
#include "engine/elements/hermite_shape.h"

namespace cablesim {
namespace {

using Cubic = ElementCubic;

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

// The cubic of coordinate `axis` along an element (AncfCableElement<D>
// layout), in xi in [0, 1]; zero for an axis the element does not have.
template <int D>
Cubic CoordinateCubic(const Eigen::Matrix<double, 4 * D, 1>& e, double l, int axis) {
  if (axis >= D) return Cubic{{0, 0, 0, 0}};
  const double a0 = e(axis), b0 = e(D + axis), a1 = e(2 * D + axis), b1 = e(3 * D + axis);
  return Cubic{{a0, l * b0, -3 * a0 - 2 * l * b0 + 3 * a1 - l * b1,
                2 * a0 + l * b0 - 2 * a1 + l * b1}};
}

// The point r, its x-derivative u and its rate v along an element
// (AncfCableElement<D> layout) where the shape functions and their
// x-derivatives are s, ds.
template <int D>
void PointOnElement(const Eigen::Matrix<double, 4 * D, 1>& e,
                    const Eigen::Matrix<double, 4 * D, 1>& edot, const double* s, const double* ds,
                    Eigen::Matrix<double, D, 1>* r, Eigen::Matrix<double, D, 1>* u,
                    Eigen::Matrix<double, D, 1>* v) {
  r->setZero();
  u->setZero();
  v->setZero();
  for (int k = 0; k < 4; ++k) {
    *r += s[k] * e.template segment<D>(k * D);
    *u += ds[k] * e.template segment<D>(k * D);
    *v += s[k] * edot.template segment<D>(k * D);
  }
}

}  // namespace

using contact::AddShapeBlocks;
using contact::BisectSign;

Seabed::Seabed(const SeabedSpec& spec)
    : depth_(spec.depth_m),
      normal_(spec.normal.normalized()),
      k_(spec.stiffness_n_m2),
      c_(spec.damping_n_s_m2),
      mu_a_(spec.friction_axial),
      mu_t_(spec.friction_transverse),
      v_s_(spec.friction_speed_m_s),
      u_s_(spec.friction_length_m),
      moordyn_c_(spec.friction_law == FrictionLaw::kMoorDyn ? spec.friction_damping_n_s_m2 : 0),
      moordyn_scale_(spec.static_friction_scale) {
  if (spec.bathymetry.enabled) {
    int axis = 0;
    normal_.cwiseAbs().maxCoeff(&axis);
    grid_.emplace(spec.bathymetry, axis, normal_(axis) > 0 ? 1.0 : -1.0);
  }
}

double Seabed::GridHeight(const Eigen::Vector3d& r) const {
  const BathymetryGrid& g = *grid_;
  return g.up_sign() * r(g.up_axis()) + g.At(r(g.u_axis()), r(g.v_axis())).depth;
}

template <int D>
double Seabed::GridAt(const Eigen::Matrix<double, D, 1>& r, Eigen::Matrix<double, D, 1>* grad,
                      Eigen::Matrix<double, D, D>* hess) const {
  const BathymetryGrid& g = *grid_;
  const int iu = g.u_axis(), iv = g.v_axis();
  const BathymetryGrid::Sample b = g.At(iu < D ? r(iu) : 0.0, iv < D ? r(iv) : 0.0);
  grad->setZero();
  (*grad)(g.up_axis()) = g.up_sign();
  if (iu < D) (*grad)(iu) = b.du;
  if (iv < D) (*grad)(iv) = b.dv;
  if (hess) {
    hess->setZero();
    if (iu < D && iv < D) (*hess)(iu, iv) = (*hess)(iv, iu) = b.duv;
  }
  return g.up_sign() * r(g.up_axis()) + b.depth;
}

template <int D, typename F, typename L>
void Seabed::ForEachGridPiece(const Eigen::Matrix<double, 4 * D, 1>& e, double length, F&& f,
                              L&& line_crossed) const {
  const BathymetryGrid& grid = *grid_;
  const Cubic w = CoordinateCubic<D>(e, length, grid.up_axis());
  // g >= s w + min depth: most elements end here.
  const double s = grid.up_sign();
  if (s * w.c[0] - std::abs(w.c[1]) - std::abs(w.c[2]) - std::abs(w.c[3]) + grid.min_depth() > 0)
    return;
  const Cubic cu = CoordinateCubic<D>(e, length, grid.u_axis());
  const Cubic cv = CoordinateCubic<D>(e, length, grid.v_axis());
  auto height = [&](double xi) { return s * w(xi) + grid.At(cu(xi), cv(xi)).depth; };
  constexpr int kSub = 16, kMaxLines = 8;
  // The open contact piece [start, ...), if any; pieces are closed at grid
  // lines and where g turns positive.
  double start = 0;
  bool open = false;
  double xa = 0, ga = height(0);
  if (ga < 0) open = true;
  // Moves from xa to xb (no grid line or sign change strictly between
  // unless found here); `line`: a grid line lies at xb.
  auto advance = [&](double xb, int line) {
    const double gb = height(xb);
    if ((ga < 0) != (gb < 0)) {
      const double r = BisectSign(height, xa, xb);
      if (ga < 0) {
        if (r > start) f(start, r);
        open = false;
      } else {
        start = r;
        open = true;
      }
    }
    if (line >= 0 && open) {
      if (xb > start) f(start, xb);
      start = xb;
      line_crossed(xb, line);
    }
    xa = xb;
    ga = gb;
  };
  double cut[2 * kMaxLines];
  int cut_axis[2 * kMaxLines];
  for (int j = 0; j < kSub; ++j) {
    const double a = static_cast<double>(j) / kSub, b = static_cast<double>(j + 1) / kSub;
    int nc = 0;
    // The grid lines between the cells of the sub-interval's ends, each
    // crossed once (the cubic taken monotone over 1/16 of the element).
    auto lines = [&](const Cubic& c, int ca, int cb, int axis, auto line_at) {
      const int lo = std::min(ca, cb), hi = std::max(ca, cb);
      for (int i = lo + 1; i <= hi && i - lo <= kMaxLines; ++i) {
        const double at = line_at(i);
        const auto d = [&](double x) { return c(x) - at; };
        cut_axis[nc] = axis;
        cut[nc++] = BisectSign(d, a, b);
      }
    };
    if (grid.u_axis() < D)
      lines(cu, grid.CellU(cu(a)), grid.CellU(cu(b)), 0, [&](int i) { return grid.LineU(i); });
    if (grid.v_axis() < D)
      lines(cv, grid.CellV(cv(a)), grid.CellV(cv(b)), 1, [&](int i) { return grid.LineV(i); });
    // Insertion sort by position (a few entries).
    for (int i = 1; i < nc; ++i)
      for (int k = i; k > 0 && cut[k] < cut[k - 1]; --k) {
        std::swap(cut[k], cut[k - 1]);
        std::swap(cut_axis[k], cut_axis[k - 1]);
      }
    // Each line is found in one sub-interval only (the cell at a shared end
    // is the same for both), and may round to either end of it.
    for (int i = 0; i < nc; ++i) advance(std::clamp(cut[i], xa, b), cut_axis[i]);
    advance(b, -1);
  }
  if (open && start < 1) f(start, 1.0);
}

template <int D>
double Seabed::GridPotential(const Eigen::Matrix<double, 4 * D, 1>& e, double length,
                             Eigen::Matrix<double, 4 * D, 1>* gradient,
                             Eigen::Matrix<double, 4 * D, 4 * D>* hessian,
                             Eigen::Matrix<double, 4 * D, 1>* roundoff) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  // 7 points: exact to degree 13, the integrands are of degree <= 12.
  static const GaussRule rule = MakeGaussRule(7);
  double energy = 0;
  // Where the element crosses a grid line in the bed, the slope across the
  // line jumps by J, and so does the integrand of the gradient; as the
  // crossing point xi* moves (dxi*/de = -s e_a^T / a', a the coordinate
  // across the line, a' = da/dxi), the gradient changes by
  // l k g J / a' s s^T e_a e_a^T (J taken in the direction of xi).
  const BathymetryGrid& grid = *grid_;
  auto crossing = [&](double xi, int which) {
    if (!hessian) return;
    const int axis = which == 0 ? grid.u_axis() : grid.v_axis();
    double s[4], ds[4];
    HermiteShape(xi, length, s);
    HermiteShapeD1(xi, length, ds);
    Point r = Point::Zero();
    double rate = 0;  // da/dxi
    for (int k = 0; k < 4; ++k) {
      r += s[k] * e.template segment<D>(k * D);
      rate += ds[k] * length * e(k * D + axis);
    }
    Point grad;
    const double g = GridAt<D>(r, &grad, nullptr);
    if (!(g < 0) || rate == 0) return;
    const double spacing = which == 0 ? grid.LineU(1) - grid.LineU(0)
                                      : grid.LineV(1) - grid.LineV(0);
    const double delta = std::copysign(1e-6 * spacing, rate);
    Point after = r, before = r;
    after(axis) += delta;
    before(axis) -= delta;
    Point ga, gb;
    GridAt<D>(after, &ga, nullptr);
    GridAt<D>(before, &gb, nullptr);
    const double jump = ga(axis) - gb(axis);
    Eigen::Matrix<double, D, D> block = Eigen::Matrix<double, D, D>::Zero();
    block(axis, axis) = length * k_ * g * jump / rate;
    AddShapeBlocks<D>(1.0, s, block, hessian);
  };
  ForEachGridPiece<D>(e, length, [&](double a, double b) {
    for (int gp = 0; gp < rule.n; ++gp) {
      double s[4];
      HermiteShape(a + (b - a) * rule.xi[gp], length, s);
      const double wl = rule.weight[gp] * (b - a) * length;
      Point r = Point::Zero();
      double size = 0;
      for (int k = 0; k < 4; ++k) {
        r += s[k] * e.template segment<D>(k * D);
        size += std::abs(s[k]) * e.template segment<D>(k * D).template lpNorm<1>();
      }
      Point grad;
      Block hess;
      const double pen = std::max(0.0, -GridAt<D>(r, &grad, hessian ? &hess : nullptr));
      energy += wl * 0.5 * k_ * pen * pen;
      if (gradient)
        for (int k = 0; k < 4; ++k)
          gradient->template segment<D>(k * D) -= (wl * k_ * pen * s[k]) * grad;
      if (roundoff) {
        size += std::abs(GridHeight(Eigen::Vector3d::Zero()));
        for (int k = 0; k < 4; ++k)
          roundoff->template segment<D>(k * D) +=
              (wl * k_ * kEps * size * std::abs(s[k])) * grad.cwiseAbs();
      }
      if (hessian)
        AddShapeBlocks<D>(wl, s, (k_ * (grad * grad.transpose() - pen * hess)).eval(), hessian);
    }
  }, crossing);
  return energy;
}

template <int D>
double Seabed::GridDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                               const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                               Eigen::Matrix<double, 4 * D, 1>* force,
                               Eigen::Matrix<double, 4 * D, 4 * D>* c, double damping,
                               double speed, double moordyn_damping,
                               Eigen::Matrix<double, 4 * D, 4 * D>* position, bool rate_tangent) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  static const GaussRule rule = MakeGaussRule(7);
  double power = 0;
  // The damping's moving ends (PlaneDissipation), where g changes sign: at
  // a root x* (g(r(x*)) = 0), dx*/de_m = -s_m grad g^T / g' (g' = grad g .
  // r'), so -dQ/de = -c (n . v) |grad g| / |g'| s_k s_m n n^T. A piece also
  // ends at a grid line (line_crossed, called after the piece it closes)
  // and at the element's ends: no term there. `pending` holds a piece's
  // far end until it is known not to be a grid line.
  const bool ends = position && damping != 0;
  double pending = -1, last_line = -1;
  auto end_term = [&](double xi) {
    if (!(xi > 0 && xi < 1)) return;
    double s[4], ds[4];
    HermiteShape(xi, length, s);
    HermiteShapeD1(xi, length, ds);
    Point r, u, v;
    PointOnElement<D>(e, edot, s, ds, &r, &u, &v);
    Point grad;
    GridAt<D>(r, &grad, nullptr);
    const double slope = grad.dot(u), gn = grad.norm();
    if (slope == 0) return;
    const Point n = grad / gn;
    AddShapeBlocks<D>(-damping * n.dot(v) * gn / std::abs(slope), s, Block(n * n.transpose()),
                      position);
  };
  ForEachGridPiece<D>(e, length, [&](double a, double b) {
    if (ends) {
      if (pending >= 0) end_term(pending);
      if (a != last_line) end_term(a);
      pending = b;
    }
    for (int gp = 0; gp < rule.n; ++gp) {
      double s[4], ds[4];
      const double xi = a + (b - a) * rule.xi[gp];
      HermiteShape(xi, length, s);
      HermiteShapeD1(xi, length, ds);
      const double wl = rule.weight[gp] * (b - a) * length;
      Point r, u, v;
      PointOnElement<D>(e, edot, s, ds, &r, &u, &v);
      Point grad;
      const double pen = std::max(0.0, -GridAt<D>(r, &grad, nullptr));
      const double gn = grad.norm();
      const Point n = grad / gn;
      const Block proj = Block::Identity() - n * n.transpose();
      Point q;
      Block h;
      power += wl * contact::PointDissipation<D>(n, proj, k_ * pen * gn, v, u, damping, mu_a_,
                                                 mu_t_, speed, &q, &h, moordyn_damping,
                                                 moordyn_scale_, rate_tangent);
      if (force)
        for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) += (wl * s[k]) * q;
      if (c) AddShapeBlocks<D>(wl, s, h, c);
    }
  }, [&](double xi, int) {
    if (pending == xi) pending = -1;
    last_line = xi;
  });
  if (ends && pending >= 0) end_term(pending);
  return power;
}

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
  // Where h changes sign (monotone pieces split at the roots of h').
  double cuts[5];
  int ncuts = 0;
  cuts[ncuts++] = 0;
  ncuts += SignChanges(h, cuts + 1);
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
  if (grid_) return GridPotential<D>(e, length, gradient, hessian, roundoff);
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
                              Eigen::Matrix<double, 4 * D, 4 * D>* c,
                              Eigen::Matrix<double, 4 * D, 4 * D>* position) const {
  if (grid_)
    return GridDissipation<D>(e, edot, length, force, c, c_, v_s_, moordyn_c_, position);
  return PlaneDissipation<D>(e, edot, length, force, c, c_, v_s_, moordyn_c_, position);
}

template <int D>
void Seabed::AddStaticFriction(const Eigen::Matrix<double, 4 * D, 1>& e,
                                 const Eigen::Matrix<double, 4 * D, 1>& e0, double length,
                                 Eigen::Matrix<double, 4 * D, 1>* force,
                                 Eigen::Matrix<double, 4 * D, 4 * D>* matrix) const {
  if (!has_friction()) return;
  // The displacement from the start takes the rate's place, u_s v_s's.
  const Eigen::Matrix<double, 4 * D, 1> displacement = e - e0;
  if (grid_) {
    GridDissipation<D>(e, displacement, length, force, matrix, 0.0, u_s_, 0.0, nullptr, false);
  } else {
    PlaneDissipation<D>(e, displacement, length, force, matrix, 0.0, u_s_, 0.0, nullptr, false);
  }
}

template <int D>
double Seabed::GapAt(const Eigen::Matrix<double, D, 1>& r, Eigen::Matrix<double, D, 1>* grad,
                     Eigen::Matrix<double, D, D>* hess) const {
  if (grid_) return GridAt<D>(r, grad, hess);
  *grad = normal_.head<D>();
  if (hess) hess->setZero();
  return depth_ + grad->dot(r);
}

template <int D>
double Seabed::PointPotential(const Eigen::Matrix<double, D, 1>& r, double k,
                              Eigen::Matrix<double, D, 1>* gradient,
                              Eigen::Matrix<double, D, D>* hessian) const {
  Eigen::Matrix<double, D, 1> grad;
  Eigen::Matrix<double, D, D> hess;
  const double g = GapAt<D>(r, &grad, hessian ? &hess : nullptr);
  if (!(g < 0)) return 0;
  const double pen = -g;
  if (gradient) *gradient -= (k * pen) * grad;
  if (hessian) *hessian += k * (grad * grad.transpose() - pen * hess);
  return 0.5 * k * pen * pen;
}

template <int D>
double Seabed::PointDissipation(const Eigen::Matrix<double, D, 1>& r,
                                const Eigen::Matrix<double, D, 1>& v, double k, double c,
                                double mu, Eigen::Matrix<double, D, 1>* force,
                                Eigen::Matrix<double, D, D>* tangent) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  Point grad;
  const double g = GapAt<D>(r, &grad, nullptr);
  if (!(g < 0)) return 0;
  const double gn = grad.norm();
  const Point n = grad / gn;
  Point q;
  Block h;
  // Isotropic: no cable direction (u = 0 gives A = mu P).
  const double power =
      contact::PointDissipation<D>(n, Block::Identity() - n * n.transpose(), -k * g * gn, v,
                                   Point::Zero(), c, mu, mu, v_s_, &q, &h);
  if (force) *force += q;
  if (tangent) *tangent += h;
  return power;
}

template <int D>
void Seabed::PointStaticFriction(const Eigen::Matrix<double, D, 1>& r,
                                   const Eigen::Matrix<double, D, 1>& r0, double k, double mu,
                                   Eigen::Matrix<double, D, 1>* force,
                                   Eigen::Matrix<double, D, D>* matrix) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  if (mu == 0) return;
  Point grad;
  const double g = GapAt<D>(r, &grad, nullptr);
  if (!(g < 0)) return;
  const double gn = grad.norm();
  const Point n = grad / gn;
  Point q;
  Block h;
  contact::PointDissipation<D>(n, Block::Identity() - n * n.transpose(), -k * g * gn,
                               (r - r0).eval(), Point::Zero(), 0.0, mu, mu, u_s_, &q, &h, 0.0, 1.0,
                               false);
  if (force) *force += q;
  if (matrix) *matrix += h;
}

template <int D>
double Seabed::PlaneDissipation(const Eigen::Matrix<double, 4 * D, 1>& e,
                                const Eigen::Matrix<double, 4 * D, 1>& edot, double length,
                                Eigen::Matrix<double, 4 * D, 1>* force,
                                Eigen::Matrix<double, 4 * D, 4 * D>* c, double damping,
                                double speed, double moordyn_damping,
                                Eigen::Matrix<double, 4 * D, 4 * D>* position, bool rate_tangent) const {
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  double pieces[2][2];
  const int count = ContactPieces<D>(e, length, pieces);
  if (count == 0) return 0;
  const Point n = normal_.head<D>();
  const Block proj = Block::Identity() - n * n.transpose();
  double power = 0;
  ForEachContactPoint(pieces, count, length, [&](double wl, const double* s, const double* ds) {
    Point r, u, v;
    PointOnElement<D>(e, edot, s, ds, &r, &u, &v);
    const double pen = std::max(0.0, -(depth_ + n.dot(r)));
    Point q;
    Block h;
    power += wl * contact::PointDissipation<D>(n, proj, k_ * pen, v, u, damping, mu_a_, mu_t_,
                                               speed, &q, &h, moordyn_damping, moordyn_scale_,
                                               rate_tangent);
    if (force)
      for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) += (wl * s[k]) * q;
    if (c) AddShapeBlocks<D>(wl, s, h, c);
  });
  // The damping's integrand -c (n . v) s_k n does not vanish where the
  // element enters or leaves the bed, so the force moves with those ends
  // (see the header): at an end x* (h(x*) = 0, inside the element) moved by
  // dx*/de_m = -s_m n^T / (n . r'), Q_k changes by +-s_k q dx*, which is
  // -dQ/de = -c (n . v) / |n . r'| s_k s_m n n^T at either end (symmetric;
  // negative where the cable lifts off, n . v > 0). Friction vanishes there
  // (N = k p = 0) and adds no such term.
  if (position && damping != 0) {
    for (int p = 0; p < count; ++p)
      for (int end = 0; end < 2; ++end) {
        const double xi = pieces[p][end];
        if (!(xi > 0 && xi < 1)) continue;  // an element end, not a root of h
        double s[4], ds[4];
        HermiteShape(xi, length, s);
        HermiteShapeD1(xi, length, ds);
        Point r, u, v;
        PointOnElement<D>(e, edot, s, ds, &r, &u, &v);
        const double slope = n.dot(u);
        if (slope == 0) continue;
        AddShapeBlocks<D>(-damping * n.dot(v) / std::abs(slope), s, Block(n * n.transpose()),
                          position);
      }
  }
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
      double, Eigen::Matrix<double, 4 * D, 1>*, Eigen::Matrix<double, 4 * D, 4 * D>*,      \
      Eigen::Matrix<double, 4 * D, 4 * D>*) const;                                         \
  template void Seabed::AddStaticFriction<D>(                                            \
      const Eigen::Matrix<double, 4 * D, 1>&, const Eigen::Matrix<double, 4 * D, 1>&,      \
      double, Eigen::Matrix<double, 4 * D, 1>*, Eigen::Matrix<double, 4 * D, 4 * D>*) const; \
  template double Seabed::PointPotential<D>(const Eigen::Matrix<double, D, 1>&, double,    \
                                            Eigen::Matrix<double, D, 1>*,                  \
                                            Eigen::Matrix<double, D, D>*) const;           \
  template double Seabed::PointDissipation<D>(                                             \
      const Eigen::Matrix<double, D, 1>&, const Eigen::Matrix<double, D, 1>&, double, double, \
      double, Eigen::Matrix<double, D, 1>*, Eigen::Matrix<double, D, D>*) const;           \
  template void Seabed::PointStaticFriction<D>(                                          \
      const Eigen::Matrix<double, D, 1>&, const Eigen::Matrix<double, D, 1>&, double, double, \
      Eigen::Matrix<double, D, 1>*, Eigen::Matrix<double, D, D>*) const;
CABLESIM_SEABED_INSTANTIATE(2)
CABLESIM_SEABED_INSTANTIATE(3)
#undef CABLESIM_SEABED_INSTANTIATE

double CableSeabed::AddPotential(const ElementCoords<2>& e, double length,
                                 ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                                 ElementCoords<2>* roundoff) const {
  return bed().AddPotential<2>(e, length, gradient, hessian, roundoff);
}

double CableSeabed::AddPotential(const ElementCoords<3>& e, double length,
                                 ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                                 ElementCoords<3>* roundoff) const {
  return bed().AddPotential<3>(e, length, gradient, hessian, roundoff);
}

double CableSeabed::Energy(const ElementCoords<2>& e, double length) const {
  return bed().Energy<2>(e, length);
}

double CableSeabed::Energy(const ElementCoords<3>& e, double length) const {
  return bed().Energy<3>(e, length);
}

double CableSeabed::AddElementPotential(const ElementAt<2>& at, const ElementCoords<2>& e,
                                        ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                                        ElementCoords<2>* roundoff) const {
  return BedOf(at.index).AddPotential<2>(e, at.element.length(), gradient, hessian, roundoff);
}

double CableSeabed::AddElementPotential(const ElementAt<3>& at, const ElementCoords<3>& e,
                                        ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                                        ElementCoords<3>* roundoff) const {
  return BedOf(at.index).AddPotential<3>(e, at.element.length(), gradient, hessian, roundoff);
}

void CableSeabed::AddElementEnergy(const ElementAt<2>& at, const ElementCoords<2>& e,
                                   double* energy) const {
  *energy += BedOf(at.index).Energy<2>(e, at.element.length());
}

void CableSeabed::AddElementEnergy(const ElementAt<3>& at, const ElementCoords<3>& e,
                                   double* energy) const {
  *energy += BedOf(at.index).Energy<3>(e, at.element.length());
}

bool CableSeabed::dissipates() const {
  for (const Seabed& b : beds_)
    if (b.dissipates()) return true;
  return false;
}

double CableSeabed::AddDissipation(const ElementCoords<2>& e, const ElementCoords<2>& edot,
                                   double length, ElementCoords<2>* force,
                                   ElementMatrix<2>* c) const {
  return bed().AddDissipation<2>(e, edot, length, force, c);
}

double CableSeabed::AddDissipation(const ElementCoords<3>& e, const ElementCoords<3>& edot,
                                   double length, ElementCoords<3>* force,
                                   ElementMatrix<3>* c) const {
  return bed().AddDissipation<3>(e, edot, length, force, c);
}

double CableSeabed::AddElementDissipation(const ElementAt<2>& at, const ElementCoords<2>& e,
                                          const ElementCoords<2>& edot, ElementCoords<2>* force,
                                          ElementMatrix<2>* c) const {
  return BedOf(at.index).AddDissipation<2>(e, edot, at.element.length(), force, c,
                                            at.position_tangent);
}

double CableSeabed::AddElementDissipation(const ElementAt<3>& at, const ElementCoords<3>& e,
                                          const ElementCoords<3>& edot, ElementCoords<3>* force,
                                          ElementMatrix<3>* c) const {
  return BedOf(at.index).AddDissipation<3>(e, edot, at.element.length(), force, c,
                                            at.position_tangent);
}

void CableSeabed::AddStaticFriction(const ElementCoords<2>& e, const ElementCoords<2>& e0,
                                    double length, ElementCoords<2>* force,
                                    ElementMatrix<2>* matrix) const {
  bed().AddStaticFriction<2>(e, e0, length, force, matrix);
}

void CableSeabed::AddStaticFriction(const ElementCoords<3>& e, const ElementCoords<3>& e0,
                                    double length, ElementCoords<3>* force,
                                    ElementMatrix<3>* matrix) const {
  bed().AddStaticFriction<3>(e, e0, length, force, matrix);
}

void CableSeabed::AddElementStaticFriction(int index, const ElementCoords<2>& e,
                                           const ElementCoords<2>& e0, double length,
                                           ElementCoords<2>* force,
                                           ElementMatrix<2>* matrix) const {
  BedOf(index).AddStaticFriction<2>(e, e0, length, force, matrix);
}

void CableSeabed::AddElementStaticFriction(int index, const ElementCoords<3>& e,
                                           const ElementCoords<3>& e0, double length,
                                           ElementCoords<3>* force,
                                           ElementMatrix<3>* matrix) const {
  BedOf(index).AddStaticFriction<3>(e, e0, length, force, matrix);
}

std::unique_ptr<CableSeabed> MakeCableSeabed(const Scene& scene,
                                             const std::vector<int>& cable_element_begin) {
  if (!scene.seabed.enabled) return nullptr;
  bool own = false;
  for (const CableSpec& c : scene.cables)
    own = own || c.seabed_stiffness_n_m2 >= 0 || c.seabed_damping_n_s_m2 >= 0;
  if (!own || cable_element_begin.size() != scene.cables.size() + 1)
    return std::make_unique<CableSeabed>(scene.seabed);
  std::vector<Seabed> beds{Seabed(scene.seabed)};
  std::vector<int> bed_of(cable_element_begin.back(), 0);
  for (size_t c = 0; c < scene.cables.size(); ++c) {
    const CableSpec& cable = scene.cables[c];
    if (cable.seabed_stiffness_n_m2 < 0 && cable.seabed_damping_n_s_m2 < 0) continue;
    SeabedSpec spec = scene.seabed;
    if (cable.seabed_stiffness_n_m2 >= 0) spec.stiffness_n_m2 = cable.seabed_stiffness_n_m2;
    if (cable.seabed_damping_n_s_m2 >= 0) spec.damping_n_s_m2 = cable.seabed_damping_n_s_m2;
    beds.emplace_back(spec);
    for (int k = cable_element_begin[c]; k < cable_element_begin[c + 1]; ++k)
      bed_of[k] = static_cast<int>(beds.size()) - 1;
  }
  return std::make_unique<CableSeabed>(std::move(beds), std::move(bed_of));
}

}  // namespace cablesim
