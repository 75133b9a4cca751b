// MultibodyModel's winch terms (multibody_model.h, "Winches"): the
// elements and mass of the winch cables at L(t) (UpdateWinches) and the
// line tension at the winch (WinchTension). Their gravity, convective
// inertia and material damping are contributors (forces/gravity_loads.h,
// forces/winch_cables.h); the mass stays here, since the mass matrix the
// steppers factor is the model's.

#include "engine/model/multibody_model.h"

#include <algorithm>

#include <Eigen/Dense>
#include <Eigen/Geometry>


namespace cablesim {

using Eigen::VectorXd;

template <int D>
void MultibodyModel::UpdateWinches() {
  constexpr int kN2 = 16 * D * D;
  std::vector<ElementData<D>>* elements_ptr;
  if constexpr (D == 2) {
    elements_ptr = &elements2_;
  } else {
    elements_ptr = &elements3_;
  }
  std::vector<ElementData<D>>& elements = *elements_ptr;
  std::copy(mass_base_.begin(), mass_base_.end(), mass_.values());
  for (WinchData& w : winches_) {
    w.length = w.reel.At(time_).length;
    const int n = w.element_end - w.element_begin;
    const double l = w.length / n;
    for (int k = 0; k < n; ++k) {
      const int index = w.element_begin + k;
      ElementData<D>& e = elements[index];
      e.element.set_length(l);
      const auto me = e.element.MassMatrix(w.mass_per_length);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(D * a, D * b);
      ScatterElementMatrix<kN2>(index, me.data(), 1.0, mass_.values());
    }
  }
  // The record was reserved for the whole envelope: no allocation here.
  mass_.CompressForMultiply();
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

template <int D>
double MultibodyModel::WinchPotentialRate(const VectorXd& q, const VectorXd& qdot) const {
  constexpr int kN = 4 * D;
  double power = 0;
  for (const WinchData& w : winches_) {
    const int n = w.element_end - w.element_begin;
    const WinchReel::State now = w.reel.At(time_);
    if (now.rate == 0) continue;
    const double l = now.length / n, ldot = now.rate / n, dl = 1e-4 * l;
    for (int index = w.element_begin; index < w.element_end; ++index) {
      const ElementData<D>& data = Elements<D>()[index];
      const ElementCoords<D> qe = q.segment<kN>(data.first_coord);
      // The element's stored energy at length `length`, e fixed.
      auto energy = [&](double length) {
        AncfCableElement<D> element = data.element;
        element.set_length(length);
        const auto se = element.StrainEnergy(qe);
        double u = se.axial + se.bending;
        const ElementAt<D> at{element, index, time_, data.first_coord, &q, &qdot};
        for (const ElementTerm* t : potential_terms_) t->AddElementEnergy(at, qe, &u);
        return u;
      };
      // Central differences at dl and dl / 2, extrapolated (Richardson):
      // the error of one difference, dl^2 / 6 d^3U/dl^3 ~ dl^2 EA / l^2,
      // is EA, not the tension, times the relative step squared (1e-8 of
      // EA at 1e-4: 0.3 N on a steel rope, a drift of 1e-6 of the
      // winch's work); the extrapolation's is dl^4 EA / l^4 (1e-16 of
      // EA), and the rounding of U (its strain's cancellation, EA eps l
      // 1e-16) over dl stays below 1e-8 N.
      auto difference = [&](double h) { return (energy(l + h) - energy(l - h)) / (2 * h); };
      power += ldot * (4 * difference(dl / 2) - difference(dl)) / 3;
    }
  }
  return power;
}

double MultibodyModel::ExternalPower(const VectorXd& q, const VectorXd& qdot) const {
  if (winches_.empty()) return 0;
  double power = dim_ == 2 ? WinchPotentialRate<2>(q, qdot) : WinchPotentialRate<3>(q, qdot);
  const ForceState state = StateAt(q, &qdot, 1.0);
  for (const auto& c : contributors_) c->AddExternalPower(state, &power);
  return power;
}

template void MultibodyModel::UpdateWinches<2>();
template void MultibodyModel::UpdateWinches<3>();
template Eigen::Vector3d MultibodyModel::WinchTension<2>(const VectorXd&, int) const;
template Eigen::Vector3d MultibodyModel::WinchTension<3>(const VectorXd&, int) const;

}  // namespace cablesim
