#ifndef CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_
#define CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_

// A scalar linear function of a cable element's position along it (a
// height above a plane, n . r(x)), which on the ANCF element's Hermite
// cubic is the cubic c0 + c1 xi + c2 xi^2 + c3 xi^3 in xi = x / l in
// [0, 1], and where it changes sign: where an element enters the seabed
// (engine/forces/seabed.cc) or the water (engine/forces/cable_buoyancy.cc).

#include <algorithm>
#include <cmath>

#include "engine/forces/contact_point.h"

namespace cablesim {

struct ElementCubic {
  double c[4];
  // From the values v0, v1 at the element's ends and their slopes d0, d1
  // in x (the function of the nodal vectors r and r_x), l the length [m].
  static ElementCubic FromEnds(double v0, double d0, double v1, double d1, double l) {
    return ElementCubic{{v0, l * d0, -3 * v0 - 2 * l * d0 + 3 * v1 - l * d1,
                         2 * v0 + l * d0 - 2 * v1 + l * d1}};
  }
  double operator()(double x) const { return c[0] + x * (c[1] + x * (c[2] + x * c[3])); }
  // d/dxi.
  double Slope(double x) const { return c[1] + x * (2 * c[2] + x * 3 * c[3]); }
};

// The points of (0, 1) where h changes sign, increasing: h is split at its
// turning points (the roots of h') into monotone pieces, and each piece
// whose ends differ in sign (h < 0 at one end only) holds one root, found
// by bisection to the last bit (contact::BisectSign). Returns how many
// (at most 3).
inline int SignChanges(const ElementCubic& h, double roots[3]) {
  double br[4] = {0, 0, 0, 0};
  int nbr = 0;
  br[nbr++] = 0;
  const double qa = 3 * h.c[3], qb = 2 * h.c[2], qc = h.c[1];
  double crit[2];
  int ncrit = 0;
  if (qa != 0) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc > 0) {
      // Stable quadratic roots.
      const double t = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
      crit[ncrit++] = t / qa;
      if (t != 0) crit[ncrit++] = qc / t;
    }
  } else if (qb != 0) {
    crit[ncrit++] = -qc / qb;
  }
  std::sort(crit, crit + ncrit);
  for (int i = 0; i < ncrit; ++i)
    if (crit[i] > 0 && crit[i] < 1 && crit[i] > br[nbr - 1]) br[nbr++] = crit[i];
  int n = 0;
  double prev = 0;
  for (int i = 0; i < nbr; ++i) {
    const double a = br[i], b = i + 1 < nbr ? br[i + 1] : 1.0;
    if ((h(a) < 0) != (h(b) < 0)) {
      const double r = contact::BisectSign(h, a, b);
      if (r > prev && r < 1) {
        roots[n++] = r;
        prev = r;
      }
    }
  }
  return n;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_
