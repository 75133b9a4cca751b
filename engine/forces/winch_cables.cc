#include "engine/forces/winch_cables.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "engine/elements/ancf_cable_element.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"
#include "engine/linear/rounding.h"

namespace cablesim {

using Eigen::VectorXd;

template <int D>
WinchCables<D>::WinchCables(std::vector<Winch> winches) : winches_(std::move(winches)) {
  size_t elements = 0;
  for (const Winch& w : winches_) elements += w.elements.size();
  state_.resize(winches_.size());
  now_.resize(elements);
  SetTime(0);
}

template <int D>
void WinchCables<D>::SetTime(double t) {
  size_t slot = 0;
  for (size_t i = 0; i < winches_.size(); ++i) {
    const Winch& w = winches_[i];
    state_[i] = w.reel.At(t);
    const int n = static_cast<int>(w.elements.size());
    const double l = state_[i].length / n, ldot = state_[i].rate / n,
                 lddot = state_[i].accel / n;
    for (int k = 0; k < n; ++k, ++slot) {
      Now& at = now_[slot];
      at.mbar = AncfCableElement<D>::ScalarMassMatrix(l, w.mass_per_length);
      const WinchElementInertia in = ComputeWinchElementInertia(w.mass_per_length, l, k);
      WinchConvectiveCoefficients(in, ldot, lddot, &at.cv, &at.ce);
      at.mdot = ldot * in.m_l;
      at.g = in.g;
      at.h = in.h;
    }
  }
}

template <int D>
double WinchCables<D>::Damping(const Winch& w, const WinchReel::State& now, int k, const Now& at,
                               const VectorXd& q, const VectorXd& qdot, Coords* fe,
                               Matrix* ce) const {
  if (w.alpha_1_s == 0 && w.axial_damping_s == 0 && w.drag_n == 0 && w.drag_t == 0) return 0;
  const int first = w.elements[k].first_coord;
  const auto qe = q.segment<kN>(first);
  const auto ve = qdot.segment<kN>(first);
  const int n = static_cast<int>(w.elements.size());
  const double l = now.length / n, ldot = now.rate / n;
  double power = 0;
  if (w.alpha_1_s != 0) {
    // -alpha int mu S^T v dx with the material velocity v = S edot + ldot W e.
    const Eigen::Matrix4d& g = at.g;
    for (int a = 0; a < 4; ++a) {
      for (int d = 0; d < D; ++d) {
        double p = 0;
        for (int b = 0; b < 4; ++b)
          p += at.mbar(a, b) * ve(D * b + d) + ldot * g(a, b) * qe(D * b + d);
        if (fe) (*fe)(D * a + d) -= w.alpha_1_s * p;
        power += w.alpha_1_s * p * ve(D * a + d);
        if (ce)
          for (int b = 0; b < 4; ++b) (*ce)(D * a + d, D * b + d) += w.alpha_1_s * at.mbar(a, b);
      }
    }
    // The power is alpha int mu |v|^2 = 2 alpha T: add ldot e^T G^T edot +
    // ldot^2 e^T H e to the edot . (M edot + ldot G e) summed above.
    const Eigen::Matrix4d& h = at.h;
    for (int d = 0; d < D; ++d) {
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          power += w.alpha_1_s * ldot * qe(D * a + d) *
                   (g(b, a) * ve(D * b + d) + ldot * h(a, b) * qe(D * b + d));
        }
      }
    }
  }
  if (w.axial_damping_s != 0) {
    // Kelvin-Voigt on the material strain rate u . d(r_s)/dt|_s.
    static const GaussRule rule = MakeGaussRule(AncfCableElement<D>::kDefaultGaussPoints);
    const double c = w.ea * w.axial_damping_s;
    for (int gp = 0; gp < rule.n; ++gp) {
      double d1[4], wd[4];
      HermiteShapeD1(rule.xi[gp], l, d1);
      WinchSlopeRateShape(rule.xi[gp], l, k, wd);
      Eigen::Matrix<double, D, 1> u = Eigen::Matrix<double, D, 1>::Zero(), udot = u;
      for (int a = 0; a < 4; ++a) {
        u += d1[a] * qe.template segment<D>(D * a);
        udot += d1[a] * ve.template segment<D>(D * a) + ldot * wd[a] * qe.template segment<D>(D * a);
      }
      const double wl = rule.weight[gp] * l, rate = u.dot(udot);
      power += wl * c * rate * rate;
      if (fe)
        for (int a = 0; a < 4; ++a) fe->template segment<D>(D * a) -= (wl * c * rate * d1[a]) * u;
      if (ce) {
        const Eigen::Matrix<double, D, D> uu = u * u.transpose();
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            ce->template block<D, D>(D * a, D * b) += (wl * c * d1[a] * d1[b]) * uu;
      }
    }
  }
  if (w.drag_n != 0 || w.drag_t != 0) {
    // Morison drag on the material velocity v = S edot + ldot W e relative
    // to the fluid, W = dS/dl - (xi + k) S' (winch_inertia.h).
    using Point = Eigen::Matrix<double, D, 1>;
    using Block = Eigen::Matrix<double, D, D>;
    static const GaussRule rule = MakeGaussRule(AncfCableElement<D>::kDefaultGaussPoints);
    Eigen::Vector3d r3 = Eigen::Vector3d::Zero();
    for (int gp = 0; gp < rule.n; ++gp) {
      const double xi = rule.xi[gp];
      double sh[4], d1[4], s_l[4];
      HermiteShape(xi, l, sh);
      HermiteShapeD1(xi, l, d1);
      HermiteShape(xi, 1.0, s_l);  // dS/dl: the slope functions' factor l
      s_l[0] = s_l[2] = 0;
      Point r = Point::Zero(), u = Point::Zero(), v = Point::Zero();
      for (int a = 0; a < 4; ++a) {
        const auto ea = qe.template segment<D>(D * a);
        r += sh[a] * ea;
        u += d1[a] * ea;
        v += sh[a] * ve.template segment<D>(D * a) + (ldot * (s_l[a] - (xi + k) * d1[a])) * ea;
      }
      r3.head<D>() = r;
      if (!w.surface.Wet(r3, 0.0)) continue;
      const Point flow = (w.profile.empty() ? w.current : w.profile.At(r3)).template head<D>();
      const double un = u.norm();
      if (!(un > 0)) continue;
      const Point t = u / un, vr = flow - v;
      const Point vt = t.dot(vr) * t, vn = vr - vt;
      const double an = vn.norm(), at_ = vt.norm();
      const Point q = w.drag_n * an * vn + w.drag_t * at_ * vt;  // [N/m]
      const double wl = rule.weight[gp] * l;
      power -= wl * q.dot(v);
      if (fe)
        for (int a = 0; a < 4; ++a) fe->template segment<D>(D * a) += (wl * sh[a]) * q;
      if (ce) {
        // -dq/dv = kn (|v_n| P + v_n v_n^T / |v_n|) + 2 kt |v_t| t t^T
        // (AncfCableElement::AddDrag's), S onto both sides.
        const Block tt = t * t.transpose();
        Block c = (w.drag_n * an) * (Block::Identity() - tt) + (2 * w.drag_t * at_) * tt;
        if (an > 0) c += (w.drag_n / an) * vn * vn.transpose();
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            ce->template block<D, D>(D * a, D * b) += (wl * sh[a] * sh[b]) * c;
      }
    }
  }
  return power;
}

template <int D>
void WinchCables<D>::AddDissipative(const ForceState& s, ForceOutput* out) const {
  const VectorXd& q = *s.q;
  const VectorXd& qdot = *s.qdot;
  VectorXd* full = out->full;
  VectorXd* roundoff = out->roundoff;
  SkylineLdlt* tangent = out->matrix;
  Coords fe;
  Matrix ce;
  size_t slot = 0;
  for (size_t i = 0; i < winches_.size(); ++i) {
    const Winch& w = winches_[i];
    for (int k = 0; k < static_cast<int>(w.elements.size()); ++k, ++slot) {
      const Element& e = w.elements[k];
      const Now& at = now_[slot];
      const auto qe = q.segment<kN>(e.first_coord);
      const auto ve = qdot.segment<kN>(e.first_coord);
      // The convective force -cv edot - ce e; Newton takes Mdot (the
      // symmetric part of cv).
      fe.setZero();
      ce.setZero();
      for (int a = 0; a < 4; ++a) {
        for (int d = 0; d < D; ++d) {
          double f = 0, abs_sum = 0;
          for (int b = 0; b < 4; ++b) {
            const double tv = at.cv(a, b) * ve(D * b + d), te = at.ce(a, b) * qe(D * b + d);
            f -= tv + te;
            abs_sum += std::abs(tv) + std::abs(te);
            ce(D * a + d, D * b + d) = at.mdot(a, b);
          }
          fe(D * a + d) = f;
          if (roundoff) (*roundoff)(e.first_coord + D * a + d) += kSumRounding * abs_sum;
        }
      }
      Damping(w, state_[i], k, at, q, qdot, &fe, tangent ? &ce : nullptr);
      full->segment<kN>(e.first_coord) += fe;
      out->size = std::max(out->size, fe.template lpNorm<Eigen::Infinity>());
      if (roundoff)
        roundoff->segment<kN>(e.first_coord).noalias() += kSumRounding * fe.cwiseAbs();
      if (!tangent) continue;
      // The element's matrix onto z, entry by entry in the order (and with
      // the factor s_a s_b) of the model's element scatter: pairs with
      // j_a > j_b once, j_a == j_b all.
      const CoordinateMap& map = out->map;
      double* values = tangent->values();
      for (int a = 0; a < kN; ++a) {
        const int ia = e.first_coord + a, ja = map.j[ia];
        if (ja < 0) continue;
        for (int b = 0; b < kN; ++b) {
          const int ib = e.first_coord + b, jb = map.j[ib];
          if (jb < 0 || jb > ja) continue;
          const int slot = tangent->Slot(ja, jb);
          if (slot >= 0) values[slot] += out->scale * (map.s[ia] * map.s[ib]) * ce(a, b);
        }
      }
    }
  }
}

template <int D>
void WinchCables<D>::AddDissipatedPower(const ForceState& s, double* power) const {
  // The damping only: the convective inertia dissipates nothing.
  size_t slot = 0;
  for (size_t i = 0; i < winches_.size(); ++i) {
    const Winch& w = winches_[i];
    for (int k = 0; k < static_cast<int>(w.elements.size()); ++k, ++slot)
      *power += Damping(w, state_[i], k, now_[slot], *s.q, *s.qdot, nullptr, nullptr);
  }
}

template <int D>
void WinchCables<D>::AddExternalPower(const ForceState& s, double* power) const {
  const VectorXd& q = *s.q;
  const VectorXd& qdot = *s.qdot;
  Coords fd;
  size_t slot = 0;
  for (size_t i = 0; i < winches_.size(); ++i) {
    const Winch& w = winches_[i];
    for (int k = 0; k < static_cast<int>(w.elements.size()); ++k, ++slot) {
      const Now& at = now_[slot];
      const int first = w.elements[k].first_coord;
      const auto qe = q.segment<kN>(first);
      const auto ve = qdot.segment<kN>(first);
      for (int d = 0; d < D; ++d) {
        for (int a = 0; a < 4; ++a) {
          for (int b = 0; b < 4; ++b) {
            *power -= ve(D * a + d) * (0.5 * at.mdot(a, b) * ve(D * b + d) +
                                       at.ce(a, b) * qe(D * b + d));
          }
        }
      }
      fd.setZero();
      *power += Damping(w, state_[i], k, at, q, qdot, &fd, nullptr);
      *power += fd.dot(ve);
    }
  }
}

template <int D>
std::unique_ptr<ForceContributor> MakeWinchCables(
    std::vector<typename WinchCables<D>::Winch> winches) {
  if (winches.empty()) return nullptr;
  return std::make_unique<WinchCables<D>>(std::move(winches));
}

template class WinchCables<2>;
template class WinchCables<3>;
template std::unique_ptr<ForceContributor> MakeWinchCables<2>(std::vector<WinchCables<2>::Winch>);
template std::unique_ptr<ForceContributor> MakeWinchCables<3>(std::vector<WinchCables<3>::Winch>);

}  // namespace cablesim
