#include "engine/elements/gauss_quadrature.h"

#include <cmath>
#include <numbers>

namespace cablesim {

namespace {

// P_n(x) and P_n'(x) by the three-term recurrence.
void Legendre(int n, double x, double* p, double* dp) {
  double p0 = 1, p1 = x;
  for (int k = 2; k <= n; ++k) {
    const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  *p = p1;
  *dp = n * (x * p1 - p0) / (x * x - 1);
}

}  // namespace

// Points are the roots of the Legendre polynomial P_n on [-1, 1], found by
// Newton's method from Chebyshev-like starting guesses, then mapped to [0, 1].
GaussRule MakeGaussRule(int n) {
  GaussRule rule;
  if (n < 1) n = 1;
  if (n > GaussRule::kMaxPoints) n = GaussRule::kMaxPoints;
  rule.n = n;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double p, dp;
    for (int it = 0; it < 100; ++it) {
      Legendre(n, x, &p, &dp);
      const double dx = p / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    Legendre(n, x, &p, &dp);  // the derivative at the converged root
    rule.xi[i] = 0.5 * (1 - x);  // ascending in [0, 1]
    rule.weight[i] = 0.5 * 2 / ((1 - x * x) * dp * dp);
  }
  return rule;
}

}  // namespace cablesim
