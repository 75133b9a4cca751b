#ifndef CABLESIM_TESTS_NET_FORCE_DERIVATIVES_H_
#define CABLESIM_TESTS_NET_FORCE_DERIVATIVES_H_

// Central differences of a model's energy and net force in its unknowns,
// against the net force and its Newton matrix, at the model's initial
// configuration with the body at rest: whether the force is minus the
// gradient of the stored energy, and the matrix minus the force's
// derivative (MultibodyModel::NetForce).

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "engine/linear/skyline_ldlt.h"
#include "engine/model/multibody_model.h"

namespace cablesim::testing {

struct NetForceDerivativeErrors {
  double force = 0;        // max_j |f_j + dE/dz_j|
  double force_size = 0;   // |f|_inf
  double matrix = 0;       // max_ij |K_ij + df_i/dz_j|
  double matrix_size = 0;  // max_ij |K_ij| (stored entries)
};

// Step `d` in every unknown z_j, both ways (truncation ~d^2, rounding ~eps
// |E| / d).
inline NetForceDerivativeErrors NetForceDerivatives(MultibodyModel& m, double d) {
  NetForceDerivativeErrors e;
  const int n = m.dofs(), nq = m.coordinates();
  const Eigen::VectorXd z = m.initial_z();
  Eigen::VectorXd q(nq), f = Eigen::VectorXd::Zero(n);
  m.ToFull(z, &q);
  SkylineLdlt k;
  k.SetPattern(m.envelope());
  k.SetZero();
  m.NetForce(q, 1.0, &f, &k, 1.0);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nq);
  e.force_size = f.lpNorm<Eigen::Infinity>();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j)
      if (k.Slot(i, j) >= 0)
        e.matrix_size = std::max(e.matrix_size, std::abs(k.values()[k.Slot(i, j)]));
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd zp = z, zm = z, qp(nq), qm(nq), fp = Eigen::VectorXd::Zero(n),
                    fm = Eigen::VectorXd::Zero(n);
    zp(j) += d;
    zm(j) -= d;
    m.ToFull(zp, &qp);
    m.ToFull(zm, &qm);
    const double de = (m.Energy(qp, zero, 1.0).total - m.Energy(qm, zero, 1.0).total) / (2 * d);
    e.force = std::max(e.force, std::abs(-de - f(j)));
    m.NetForce(qp, 1.0, &fp);
    m.NetForce(qm, 1.0, &fm);
    for (int i = 0; i < n; ++i) {
      const double fd = -(fp(i) - fm(i)) / (2 * d);
      const int slot = i >= j ? k.Slot(i, j) : k.Slot(j, i);
      const double an = slot >= 0 ? k.values()[slot] : 0.0;
      e.matrix = std::max(e.matrix, std::abs(fd - an));
    }
  }
  return e;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_NET_FORCE_DERIVATIVES_H_
