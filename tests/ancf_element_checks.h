#ifndef CABLESIM_TESTS_ANCF_ELEMENT_CHECKS_H_
#define CABLESIM_TESTS_ANCF_ELEMENT_CHECKS_H_

// Checks shared by the axial-law tests (axial_law_test.cc,
// tension_table_test.cc): a strongly deformed element, and its force and
// tangent against central differences of its energy and force.

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "engine/elements/ancf_cable_element.h"
#include "tests/test_util.h"

namespace cablesim::testing {

// An element of length `length` deformed strongly: nodes displaced, slopes
// turned by up to ~60 degrees and stretched or shortened by up to 20 %.
template <int D>
typename AncfCableElement<D>::Coords Deformed(std::mt19937* rng, double length) {
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::Matrix<double, D, 1> r0, dir, t0, t1;
  for (int d = 0; d < D; ++d) r0(d) = u(*rng);
  dir.setZero();
  dir(0) = 1;
  for (int d = 1; d < D; ++d) dir(d) = 0.8 * u(*rng);
  dir.normalize();
  const Eigen::Matrix<double, D, 1> r1 = r0 + length * (1 + 0.2 * u(*rng)) * dir;
  for (int d = 0; d < D; ++d) {
    t0(d) = dir(d) + 0.6 * u(*rng);
    t1(d) = dir(d) + 0.6 * u(*rng);
  }
  t0 *= (1 + 0.2 * u(*rng)) / t0.norm();
  t1 *= (1 + 0.2 * u(*rng)) / t1.norm();
  typename AncfCableElement<D>::Coords e;
  e << r0, t0, r1, t1;
  return e;
}

template <int D>
double TotalStrainEnergy(const AncfCableElement<D>& element,
                         const typename AncfCableElement<D>::Coords& e) {
  const auto u = element.StrainEnergy(e);
  return u.axial + u.bending;
}

// On 20 deformed elements: the force is the gradient of the energy and the
// tangent the Jacobian of the force (central differences with h = 1e-6,
// error O(h^2 U''') ~ 1e-10 relative where the law is smooth; 1e-6
// relative is far above it and far below any wrong term, a missing 1/s
// factor being O(20 %)), and the tangent symmetric.
template <int D>
void CheckForceAndTangent(const AncfCableElement<D>& element, int seed) {
  using C = typename AncfCableElement<D>::Coords;
  using M = typename AncfCableElement<D>::Matrix;
  std::mt19937 rng(seed);
  const double h = 1e-6;
  for (int trial = 0; trial < 20; ++trial) {
    const C e = Deformed<D>(&rng, element.length());
    C f = C::Zero();
    M k = M::Zero();
    element.ElasticForce(e, &f, &k);
    M fd;
    for (int i = 0; i < AncfCableElement<D>::kCoords; ++i) {
      C ep = e, em = e, fp = C::Zero(), fm = C::Zero();
      ep(i) += h;
      em(i) -= h;
      EXPECT_NEAR(f(i), (TotalStrainEnergy(element, ep) - TotalStrainEnergy(element, em)) / (2 * h),
                  1e-6 * f.cwiseAbs().maxCoeff())
          << "coordinate " << i;
      element.ElasticForce(ep, &fp, nullptr);
      element.ElasticForce(em, &fm, nullptr);
      fd.col(i) = (fp - fm) / (2 * h);
    }
    EXPECT_LT((k - fd).cwiseAbs().maxCoeff(), 1e-6 * k.cwiseAbs().maxCoeff());
    EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
  }
}

// The spatial pendulum of energy_momentum_test (1 m, spun about the
// vertical at 4 rad/s, stretching as it swings) under the axial law given
// as the cable's JSON fields (`"axial_law": ...`), run 0.5 s by
// ENERGY_MOMENTUM at h = 1e-3 s: the largest drifts of the angular
// momentum about the vertical (relative) and of the total energy [J], the
// largest axial energy [J], the largest tip stretch [m] and the initial
// kinetic energy [J].
struct PendulumDrift {
  double momentum = 0, energy = 0, axial = 0, stretch = 0, kinetic = 0;
};

inline PendulumDrift SpunPendulumDrift(const std::string& axial_law_fields) {
  const std::string json = R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "pendulum", "length": 1.0, "elements": 16, "direction": {"x": 1},
                "density": 320, "youngs_modulus": 1.6e6, "area": 2.5e-5,
                "second_moment": 4.973591971621729e-11, "bending": "EXACT", )" +
                           axial_law_fields + R"(}],
    "joints": [{"type": "PIN", "a": {"cable": "pendulum", "s": 0}}],
    "initial_velocity": {"angular": {"y": 4.0}},
    "probes": [{"name": "tip", "cable": "pendulum", "s": 1.0}],
    "solver": {"duration": 0.5, "step": 1e-3, "output_interval": 0.01,
               "newton_tolerance": 1e-12, "integrator": "ENERGY_MOMENTUM"}})";
  CollectingSink sink;
  RunOk(SceneFromJson(json), &sink);
  PendulumDrift d;
  if (sink.frames().empty()) {
    ADD_FAILURE() << "no frames";
    return d;
  }
  const Frame& first = sink.frames().front();
  d.kinetic = first.energy.kinetic;
  for (const Frame& f : sink.frames()) {
    d.momentum = std::max(d.momentum, std::abs(f.angular_momentum.y() -
                                               first.angular_momentum.y()) /
                                          std::abs(first.angular_momentum.y()));
    d.energy = std::max(d.energy, std::abs(f.energy.total - first.energy.total));
    d.axial = std::max(d.axial, f.energy.axial);
    d.stretch = std::max(d.stretch, f.probes[0].position_m.norm() - 1);
  }
  return d;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_ANCF_ELEMENT_CHECKS_H_
