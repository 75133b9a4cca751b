#ifndef CABLESIM_ENGINE_ELEMENTS_GAUSS_QUADRATURE_H_
#define CABLESIM_ENGINE_ELEMENTS_GAUSS_QUADRATURE_H_

// Gauss-Legendre points and weights on [0, 1]. An n-point rule integrates
// polynomials of degree 2n - 1 exactly.

#include <array>

namespace cablesim {

struct GaussRule {
  static constexpr int kMaxPoints = 8;
  int n = 0;
  std::array<double, kMaxPoints> xi{};      // in [0, 1]
  std::array<double, kMaxPoints> weight{};  // sum to 1
};

// n in [1, GaussRule::kMaxPoints].
GaussRule MakeGaussRule(int n);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_GAUSS_QUADRATURE_H_
