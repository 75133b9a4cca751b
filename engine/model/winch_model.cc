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
template Eigen::Vector3d MultibodyModel::WinchTension<2>(const VectorXd&, int) const;
template Eigen::Vector3d MultibodyModel::WinchTension<3>(const VectorXd&, int) const;

}  // namespace cablesim
