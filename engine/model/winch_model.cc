// MultibodyModel's winch terms (multibody_model.h, "Winches"): the
// elements, mass and gravity of the winch cables at L(t) (UpdateWinches),
// the convective inertia and material damping (WinchForces, WinchDamping)
// and the line tension at the winch (WinchTension).

#include "engine/model/multibody_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"
#include "engine/forces/winch_inertia.h"
#include "engine/linear/rounding.h"

namespace cablesim {

using Eigen::VectorXd;

template <int D>
void MultibodyModel::UpdateWinches() {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  std::vector<ElementData<D>>* elements_ptr;
  if constexpr (D == 2) {
    elements_ptr = &elements2_;
  } else {
    elements_ptr = &elements3_;
  }
  std::vector<ElementData<D>>& elements = *elements_ptr;
  std::copy(mass_base_.begin(), mass_base_.end(), mass_.values());
  constant_force_ = constant_force_base_;
  const Eigen::Matrix<double, D, 1> g = gravity_.head<D>();
  size_t slot = 0;
  for (WinchData& w : winches_) {
    const TimeFunction::Value v = w.speed.Evaluate(time_);
    w.length = w.length0 + w.speed.Integral(time_);
    w.rate = v.f;
    w.accel = v.df;
    const int n = w.element_end - w.element_begin;
    const double l = w.length / n, ldot = w.rate / n, lddot = w.accel / n;
    for (int k = 0; k < n; ++k, ++slot) {
      const int index = w.element_begin + k;
      ElementData<D>& e = elements[index];
      e.element.set_length(l);
      const auto me = e.element.MassMatrix(w.mass_per_length);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(D * a, D * b);
      e.gravity = e.element.GravityForce(w.mass_per_length, g);
      constant_force_.segment<kN>(e.first_coord) += e.gravity;
      ScatterElementMatrix<kN2>(index, me.data(), 1.0, mass_.values());
      const WinchElementInertia in = ComputeWinchElementInertia(w.mass_per_length, l, k);
      WinchConvectiveCoefficients(in, ldot, lddot, &winch_cv_[slot], &winch_ce_[slot]);
      winch_mdot_[slot] = ldot * in.m_l;
      winch_g_[slot] = in.g;
      winch_h_[slot] = in.h;
    }
  }
}

template <int D>
double MultibodyModel::WinchDamping(const WinchData& w, int index, const VectorXd& q,
                                   const VectorXd& qdot,
                                   typename AncfCableElement<D>::Coords* fe,
                                   typename AncfCableElement<D>::Matrix* ce) const {
  constexpr int kN = 4 * D;
  if (w.alpha_1_s == 0 && w.axial_damping_s == 0) return 0;
  const ElementData<D>& e = Elements<D>()[index];
  const auto qe = q.segment<kN>(e.first_coord);
  const auto ve = qdot.segment<kN>(e.first_coord);
  const int n = w.element_end - w.element_begin, k = index - w.element_begin;
  const double l = w.length / n, ldot = w.rate / n;
  double power = 0;
  if (w.alpha_1_s != 0) {
    // -alpha int mu S^T v dx with the material velocity v = S edot + ldot W e.
    const Eigen::Matrix4d& g = winch_g_[winch_slot_[index]];
    for (int a = 0; a < 4; ++a) {
      for (int d = 0; d < D; ++d) {
        double p = 0;
        for (int b = 0; b < 4; ++b) p += e.mbar(a, b) * ve(D * b + d) + ldot * g(a, b) * qe(D * b + d);
        if (fe) (*fe)(D * a + d) -= w.alpha_1_s * p;
        power += w.alpha_1_s * p * ve(D * a + d);
        if (ce)
          for (int b = 0; b < 4; ++b) (*ce)(D * a + d, D * b + d) += w.alpha_1_s * e.mbar(a, b);
      }
    }
    // The power is alpha int mu |v|^2 = 2 alpha T: add ldot e^T G^T edot +
    // ldot^2 e^T H e to the edot . (M edot + ldot G e) summed above.
    const Eigen::Matrix4d& h = winch_h_[winch_slot_[index]];
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
  return power;
}

template <int D>
double MultibodyModel::WinchForces(const VectorXd& q, const VectorXd& qdot, VectorXd* full,
                                   SkylineLdlt* tangent, double tangent_scale,
                                   VectorXd* roundoff) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Coords fe;
  typename AncfCableElement<D>::Matrix ce;
  double size = 0;
  for (const WinchData& w : winches_) {
    for (int index = w.element_begin; index < w.element_end; ++index) {
      const int slot = winch_slot_[index];
      const ElementData<D>& e = elements[index];
      const auto qe = q.segment<kN>(e.first_coord);
      const auto ve = qdot.segment<kN>(e.first_coord);
      const Eigen::Matrix4d& cv = winch_cv_[slot];
      const Eigen::Matrix4d& cx = winch_ce_[slot];
      // The convective force -cv edot - ce e; Newton takes Mdot (the
      // symmetric part of cv).
      fe.setZero();
      ce.setZero();
      for (int a = 0; a < 4; ++a) {
        for (int d = 0; d < D; ++d) {
          double f = 0, abs_sum = 0;
          for (int b = 0; b < 4; ++b) {
            const double tv = cv(a, b) * ve(D * b + d), te = cx(a, b) * qe(D * b + d);
            f -= tv + te;
            abs_sum += std::abs(tv) + std::abs(te);
            ce(D * a + d, D * b + d) = winch_mdot_[slot](a, b);
          }
          fe(D * a + d) = f;
          if (roundoff) (*roundoff)(e.first_coord + D * a + d) += kSumRounding * abs_sum;
        }
      }
      WinchDamping<D>(w, index, q, qdot, &fe, tangent ? &ce : nullptr);
      full->segment<kN>(e.first_coord) += fe;
      size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
      if (roundoff)
        roundoff->segment<kN>(e.first_coord).noalias() += kSumRounding * fe.cwiseAbs();
      if (!tangent) continue;
      const int* slots = &element_slots_[kN2 * index];
      const double* factors = &element_factors_[kN2 * index];
      for (int t = 0; t < kN2; ++t)
        if (slots[t] >= 0) tangent->values()[slots[t]] += tangent_scale * factors[t] * ce(t / kN, t % kN);
    }
  }
  return size;
}

double MultibodyModel::CableMass(int cable) const {
  double mass = 0;
  auto sum = [&](const auto& elements) {
    for (int k = cable_element_begin_[cable]; k < cable_element_begin_[cable + 1]; ++k) {
      const Eigen::Matrix4d& m = elements[k].mbar;
      mass += m(0, 0) + m(0, 2) + m(2, 0) + m(2, 2);
    }
  };
  if (dim_ == 2) {
    sum(elements2_);
  } else {
    sum(elements3_);
  }
  return mass;
}

template <int D>
Eigen::Vector3d MultibodyModel::WinchTension(const VectorXd& q, int w) const {
  const ElementData<D>& e = Elements<D>()[winches_[w].element_end - 1];
  const Eigen::Matrix<double, D, 1> u =
      e.element.Slope(q.segment<4 * D>(e.first_coord), 1.0);
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  f.head<D>() = winches_[w].ea * 0.5 * (u.squaredNorm() - 1) * u;
  return f;
}

template void MultibodyModel::UpdateWinches<2>();
template void MultibodyModel::UpdateWinches<3>();
template double MultibodyModel::WinchDamping<2>(const WinchData&, int, const VectorXd&, const VectorXd&, AncfCableElement<2>::Coords*, AncfCableElement<2>::Matrix*) const;
template double MultibodyModel::WinchDamping<3>(const WinchData&, int, const VectorXd&, const VectorXd&, AncfCableElement<3>::Coords*, AncfCableElement<3>::Matrix*) const;
template double MultibodyModel::WinchForces<2>(const VectorXd&, const VectorXd&, VectorXd*, SkylineLdlt*, double, VectorXd*) const;
template double MultibodyModel::WinchForces<3>(const VectorXd&, const VectorXd&, VectorXd*, SkylineLdlt*, double, VectorXd*) const;
template Eigen::Vector3d MultibodyModel::WinchTension<2>(const VectorXd&, int) const;
template Eigen::Vector3d MultibodyModel::WinchTension<3>(const VectorXd&, int) const;

}  // namespace cablesim
