#ifndef CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_
#define CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_

// A scalar linear function of a cable element's position along it (a
// height above a plane, n . r(x)), which on the ANCF element's Hermite
// cubic is the cubic c0 + c1 xi + c2 xi^2 + c3 xi^3 in xi = x / l in
// [0, 1], and where it changes sign: where an element enters the seabed
// (engine/forces/seabed.cc) or the water (engine/forces/cable_buoyancy.cc).

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

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

// contact::BisectSign(h, a, b) for the cubic h, to the bit: the same
// midpoints and the same signs of h there, so the same root; faster where
// a line is anchored on the bed's plane. There h(0) = 0 exactly (c0 = 0)
// and, with c1 < 0, BisectSign halves b toward 0 for its full 200 rounds
// (h < 0 at every midpoint, which is never 0): 63 % of its evaluations on
// the OC4 mooring (bench/scenes/oc4-three-lines.json). Those signs are
// known in advance. Horner's rule at m >= 0 returns
// m (c1 (1 + t1) + c2 m (1 + t2) + c3 m^2 (1 + t3)) with |t_i| <=
// gamma_6 = 6 u / (1 - 6 u) (Higham, Accuracy and Stability of Numerical
// Algorithms, 2nd ed., section 5.1; c0 = 0 adds nothing), which is
// negative when m (|c2| + |c3|) <= |c1| / 4 and m <= 1: for every
// midpoint m <= sure = |c1| / (4 (|c2| + |c3|)). Underflow cannot spoil
// it: m |c1| >= |c1| b 2^-200 > 2^-990 in 200 halvings. Once b <= sure
// (and a = 0) every later round halves b, exactly while b stays normal, so
// the remaining rounds are one ldexp.
// tests/element_cubic_test.cc compares it with BisectSign on random,
// anchored, flat and nearly double roots.
inline double BisectCubicSign(const ElementCubic& h, double a, double b) {
  if (a == 0 && h.c[0] == 0 && h.c[1] < 0 && -h.c[1] * b > 0x1p-790) {
    const double rest = std::abs(h.c[2]) + std::abs(h.c[3]);
    const double sure = rest > 0 ? std::min(1.0, -0.25 * h.c[1] / rest) : 1.0;
    for (int i = 0; i < 200; ++i) {
      if (b <= sure && b >= 0x1p-822) return 0.5 * std::ldexp(b, i - 200);
      const double m = 0.5 * (a + b);
      if (m <= a || m >= b) break;
      if (h(m) < 0) {
        b = m;  // h(a) = 0 is not below: the root lies below m
      } else {
        // a = m: an ordinary bracket from here, in the rounds left.
        return contact::BisectSign(h, m, b, 200 - i - 1);
      }
    }
    return 0.5 * (a + b);
  }
  return contact::BisectSign(h, a, b);
}

// SignChanges without its memo.
inline int ComputeSignChanges(const ElementCubic& h, double roots[3]) {
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
  // Sorted (two at most: what std::sort does with them, without GCC's
  // -Warray-bounds false alarm where it is inlined).
  if (ncrit == 2 && crit[1] < crit[0]) std::swap(crit[0], crit[1]);
  for (int i = 0; i < ncrit; ++i)
    if (crit[i] > 0 && crit[i] < 1 && crit[i] > br[nbr - 1]) br[nbr++] = crit[i];
  int n = 0;
  double prev = 0;
  for (int i = 0; i < nbr; ++i) {
    const double a = br[i], b = i + 1 < nbr ? br[i + 1] : 1.0;
    if ((h(a) < 0) != (h(b) < 0)) {
      const double r = BisectCubicSign(h, a, b);
      if (r > prev && r < 1) {
        roots[n++] = r;
        prev = r;
      }
    }
  }
  return n;
}

// The points of (0, 1) where h changes sign, increasing: h is split at its
// turning points (the roots of h') into monotone pieces, and each piece
// whose ends differ in sign (h < 0 at one end only) holds one root, found
// by bisection to the last bit (BisectCubicSign). Returns how many (at
// most 3).
//
// The answer depends on the four coefficients alone, and the same cubic
// comes back several times at the same coordinates: the seabed's energy,
// force and damping (MultibodyModel's NetForce and DampingForce at one
// Newton iterate, the frames' energy and damped power at one state). A
// small memo per thread, direct-mapped on the coefficients' bits, returns
// the roots found before: the same doubles, since a computation of them
// from the same bits repeats every rounding. On the OC4 mooring it halved
// the profile's share of SignChanges and ContactPieces.
inline int SignChanges(const ElementCubic& h, double roots[3]) {
  // Zero-initialised (no guard on each thread_local access): filled = 0
  // marks an empty slot.
  struct Slot {
    uint64_t key[4];
    int filled;
    int count;
    double roots[3];
  };
  constexpr int kSlots = 32;
  thread_local Slot memo[kSlots];
  uint64_t key[4], mix = 0;
  for (int i = 0; i < 4; ++i) {
    key[i] = std::bit_cast<uint64_t>(h.c[i]);
    mix = (mix ^ key[i]) * 0x9E3779B97F4A7C15ull;
  }
  Slot& slot = memo[mix >> 59];  // the top 5 bits: 32 slots
  if (slot.filled && slot.key[0] == key[0] && slot.key[1] == key[1] &&
      slot.key[2] == key[2] && slot.key[3] == key[3]) {
    std::copy(slot.roots, slot.roots + slot.count, roots);
    return slot.count;
  }
  const int count = ComputeSignChanges(h, roots);
  std::copy(key, key + 4, slot.key);
  std::copy(roots, roots + count, slot.roots);
  slot.count = count;
  slot.filled = 1;
  return count;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_ELEMENT_CUBIC_H_
