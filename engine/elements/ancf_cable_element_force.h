#ifndef CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_FORCE_H_
#define CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_FORCE_H_

// AncfCableElement<D>::ElasticForceWith<kLaw>, the elastic force's
// Gauss-point loop for one axial law, included by the two files that
// instantiate it: ancf_cable_element.cc (GREEN_LAGRANGE, ENGINEERING) and
// ancf_cable_element_table.cc (TABLE, VISCOELASTIC). Kept apart so that a third
// instantiation does not change the compiler's inlining of the other two
// (in one file it outlined parts of the Green-Lagrange loop: +0.8 % of a
// pendulum run's instructions, measured by callgrind).
//
// Include it after engine/elements/ancf_cable_element.h, whose class it
// completes: it does not include that header itself, which would close an
// include cycle between the two (tests/tools/check_engine_layers.py counts
// ancf_cable_element.h and .cc as one unit, and the .cc includes this).

#include <cmath>
#include <limits>

namespace cablesim {

template <int D>
template <AxialLaw kLaw>
void AncfCableElement<D>::ElasticForceWith(const Coords& e, Coords* force, Matrix* tangent,
                                           Coords* roundoff) const {
  using Id = Eigen::Matrix<double, D, D>;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  // For `roundoff`: |e_k| per node (once per element), and per node the
  // bound summed over the Gauss points (the same for each of its D entries).
  double node_size[4] = {0, 0, 0, 0}, node_bound[4] = {0, 0, 0, 0};
  if (roundoff)
    for (int k = 0; k < 4; ++k) node_size[k] = e.template segment<D>(k * D).norm();
  for (int g = 0; g < rule_.n; ++g) {
    const double* s1 = d1_[g];
    const double* s2 = d2_[g];
    Point u = Point::Zero(), w = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      u += s1[k] * e.template segment<D>(k * D);
      w += s2[k] * e.template segment<D>(k * D);
    }
    const double a = u.squaredNorm(), b = u.dot(w), c = w.squaredNorm();
    const double wl = rule_.weight[g] * length_;
    // Spectral-norm bounds of the Hessian blocks of psi (for `roundoff`).
    double nuu = 0, nuw = 0, nww = 0;

    // Gradient (gu, gw) and Hessian blocks of psi with respect to (u, w).
    Point gu = Point::Zero(), gw = Point::Zero();
    Block huu = Block::Zero(), huw = Block::Zero(), hww = Block::Zero();
    if constexpr (kLaw == AxialLaw::kEngineering) {
      // psi_a = EA/2 (s - 1)^2, s = |u|: gradient EA (1 - 1/s) u, Hessian
      // EA ((1 - 1/s) I + u u^T / s^3) (eigenvalues 1 - 1/s and 1).
      const double s = std::sqrt(a);
      if (s > 0) {
        const double f = 1 - 1 / s;
        gu = ea_ * f * u;
        if (tangent) huu = ea_ * (f * Id::Identity() + u * u.transpose() / (a * s));
        if (roundoff) nuu = ea_ * (std::abs(f) + 1);
      }
    } else if constexpr (kLaw == AxialLaw::kTable) {
      // psi = W(s - 1), s = |u|: gradient T u / s, Hessian
      // T / s (I - u u^T / s^2) + k u u^T / s^2 (eigenvalues T / s and k).
      const double s = std::sqrt(a);
      if (s > 0) {
        const TensionTable::Value tk = table_->At(s - 1);
        const double f = tk.tension / s;
        gu = f * u;
        if (tangent) huu = f * Id::Identity() + ((tk.stiffness - f) / a) * u * u.transpose();
        if (roundoff) nuu = std::abs(f) + tk.stiffness;
      }
    } else if constexpr (kLaw == AxialLaw::kViscoelastic) {
      // As the table's, with T = k e + p and slope k of the step
      // (ViscoelasticHistory).
      const double s = std::sqrt(a);
      if (s > 0) {
        const ViscoelasticHistory::Coefficients& vc = visco_->coefficients(visco_first_)[g];
        const double f = (vc.k * (s - 1) + vc.p) / s;
        gu = f * u;
        if (tangent) huu = f * Id::Identity() + ((vc.k - f) / a) * u * u.transpose();
        if (roundoff) nuu = std::abs(f) + vc.k;
      }
    } else {
      const double eps = (a - 1) / 2;
      gu = ea_ * eps * u;
      if (tangent) huu = ea_ * (eps * Id::Identity() + u * u.transpose());
      if (roundoff) nuu = ea_ * (std::abs(eps) + a);
    }
    if (bending_ == BendingModel::kLinear) {
      gw += ei_ * w;
      if (tangent) hww += ei_ * Id::Identity();
      nww = ei_;
    } else if (bending_ == BendingModel::kExact) {
      // psi_b = EI/2 f(a, b, c), f = c / a^2 - b^2 / a^3, with
      // da/du = 2u, db/du = w, db/dw = u, dc/dw = 2w.
      const double ia = 1 / a, ia2 = ia * ia, ia3 = ia2 * ia, ia4 = ia2 * ia2;
      const double k = 0.5 * ei_;
      const double fa = k * (-2 * c * ia3 + 3 * b * b * ia4);
      const double fb = k * (-2 * b * ia3);
      const double fc = k * ia2;
      gu += 2 * fa * u + fb * w;
      gw += fb * u + 2 * fc * w;
      const double faa = k * (6 * c * ia4 - 12 * b * b * ia4 * ia);
      const double fab = k * (6 * b * ia4);
      const double fac = k * (-2 * ia3);
      const double fbb = k * (-2 * ia3);
      if (roundoff) {
        const double nunw = std::sqrt(a * c);  // |u| |w|
        nuu += 4 * std::abs(faa) * a + 4 * std::abs(fab) * nunw + std::abs(fbb) * c +
               2 * std::abs(fa);
        nuw = 2 * std::abs(fab) * a + (4 * std::abs(fac) + std::abs(fbb)) * nunw + std::abs(fb);
        nww = std::abs(fbb) * a + 2 * std::abs(fc);
      }
      if (tangent) {
        // Second derivatives of f through a, b, c, plus f_a, f_b, f_c times
        // the Hessians of a, b, c.
        huu += 4 * faa * u * u.transpose() + 2 * fab * (u * w.transpose() + w * u.transpose()) +
               fbb * w * w.transpose() + 2 * fa * Id::Identity();
        huw += 2 * fab * u * u.transpose() + 4 * fac * u * w.transpose() +
               fbb * w * u.transpose() + fb * Id::Identity();
        hww += fbb * u * u.transpose() + 2 * fc * Id::Identity();
      }
    }
    for (int k = 0; k < 4; ++k)
      force->template segment<D>(k * D) += wl * (s1[k] * gu + s2[k] * gw);
    if (roundoff) {
      double du = 0, dw = 0;
      for (int k = 0; k < 4; ++k) {
        du += std::abs(s1[k]) * node_size[k];
        dw += std::abs(s2[k]) * node_size[k];
      }
      du *= kEps;
      dw *= kEps;
      // |g|_1 >= |g|_2: a bound without a square root.
      const double dgu = wl * (nuu * du + nuw * dw + kEps * gu.template lpNorm<1>());
      const double dgw = wl * (nuw * du + nww * dw + kEps * gw.template lpNorm<1>());
      for (int k = 0; k < 4; ++k) node_bound[k] += std::abs(s1[k]) * dgu + std::abs(s2[k]) * dgw;
    }
    if (tangent) {
      // Without bending huw = hww = 0 by construction: AddUpperBlocks'
      // test for that (18 compares per point) skipped.
      if (bending_ == BendingModel::kNone) {
        AddUpperAxialBlocks(g, wl, huu, tangent);
      } else {
        AddUpperBlocks(g, wl, huu, huw, hww, tangent);
      }
    }
  }
  if (roundoff)
    for (int k = 0; k < 4; ++k) roundoff->template segment<D>(k * D).array() += node_bound[k];
  if (tangent) MirrorUpperBlocks(tangent);
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_ANCF_CABLE_ELEMENT_FORCE_H_
