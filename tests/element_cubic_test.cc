// BisectCubicSign (engine/forces/element_cubic.h) is contact::BisectSign
// made faster for the element's cubic: it must return the same double,
// bit for bit, on every bracket. The reference is BisectSign itself, run
// on the same cubic and bracket; the cases are those where a shortcut
// could go wrong: random cubics over many scales, roots at an exact end
// (a line anchored on the bed's plane, h(0) = 0) with a large or tiny
// slope against its curvature, nearly double roots, flat and linear ones.
// SignChanges' memo must return what ComputeSignChanges computes.

#include "engine/forces/element_cubic.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "engine/forces/contact_point.h"

namespace cablesim {
namespace {

// Every bracket [a, b] of a sign change that SignChanges would bisect
// (its monotone pieces), checked against BisectSign. Returns how many.
int CheckBrackets(const ElementCubic& h) {
  const double qa = 3 * h.c[3], qb = 2 * h.c[2], qc = h.c[1];
  double br[4] = {0, 1, 1, 1};
  int nbr = 1;
  if (qa != 0) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc > 0) {
      const double t = -0.5 * (qb + std::copysign(std::sqrt(disc), qb));
      double c0 = t / qa, c1 = t != 0 ? qc / t : c0;
      if (c1 < c0) std::swap(c0, c1);
      for (double c : {c0, c1})
        if (c > 0 && c < 1 && c > br[nbr - 1]) br[nbr++] = c;
    }
  }
  br[nbr] = 1;
  int checked = 0;
  for (int i = 0; i < nbr; ++i) {
    const double a = br[i], b = br[i + 1];
    if ((h(a) < 0) == (h(b) < 0)) continue;
    const double want = contact::BisectSign(h, a, b);
    const double got = BisectCubicSign(h, a, b);
    EXPECT_EQ(std::bit_cast<uint64_t>(got), std::bit_cast<uint64_t>(want))
        << "cubic " << h.c[0] << " " << h.c[1] << " " << h.c[2] << " " << h.c[3] << " on ["
        << a << ", " << b << "]: " << got << " vs " << want;
    ++checked;
  }
  return checked;
}

TEST(BisectCubicSign, RandomCubicsMatchBisectSignToTheBit) {
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> unit(-1, 1), expo(-12, 6);
  int checked = 0;
  for (int k = 0; k < 20000; ++k) {
    ElementCubic h;
    for (double& c : h.c) c = unit(rng) * std::pow(10.0, expo(rng));
    checked += CheckBrackets(h);
  }
  EXPECT_GT(checked, 5000);
}

TEST(BisectCubicSign, AnchoredOnThePlaneMatchesBisectSignToTheBit) {
  // h(0) = 0 exactly: BisectSign halves toward 0 for its 200 rounds when
  // h < 0 just above 0 (c1 < 0), and leaves 0 at once when c1 > 0. The
  // curvature terms range from negligible to 1e12 times the slope, so the
  // range where the shortcut skips evaluations goes from all of the
  // bracket to nothing.
  std::mt19937_64 rng(340);
  std::uniform_real_distribution<double> unit(-1, 1), expo(-8, 8);
  int checked = 0;
  for (int k = 0; k < 20000; ++k) {
    ElementCubic h;
    h.c[0] = k % 2 == 0 ? 0.0 : -0.0;
    h.c[1] = -std::pow(10.0, expo(rng));
    if (k % 5 == 0) h.c[1] = -h.c[1];
    h.c[2] = unit(rng) * std::pow(10.0, expo(rng));
    h.c[3] = k % 7 == 0 ? 0.0 : unit(rng) * std::pow(10.0, expo(rng));
    if (k % 11 == 0) h.c[2] = 0;
    checked += CheckBrackets(h);
    // Brackets from 0 to a few ends, not only the turning points.
    for (double b : {1.0, 0.75, 1e-3, 1e-200}) {
      if ((h(0) < 0) == (h(b) < 0)) continue;
      EXPECT_EQ(std::bit_cast<uint64_t>(BisectCubicSign(h, 0, b)),
                std::bit_cast<uint64_t>(contact::BisectSign(h, 0, b)))
          << h.c[1] << " " << h.c[2] << " " << h.c[3] << " b " << b;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20000);
}

TEST(BisectCubicSign, AnchoredBracketWithRootsInsideMatchesBisectSign) {
  // h = -x + 10 x^2 - 20 x^3: h(0) = 0, h(1) = -11, but h > 0 on
  // (0.138, 0.362); BisectSign on [0, 1] finds the root near 0.362 (h at
  // its midpoint 0.25 is positive), which a shortcut that took h < 0
  // for granted on all of (0, 1] would miss.
  const ElementCubic h{{0.0, -1.0, 10.0, -20.0}};
  const double want = contact::BisectSign(h, 0, 1);
  EXPECT_NEAR(want, (10 + std::sqrt(20.0)) / 40, 1e-15);
  EXPECT_EQ(std::bit_cast<uint64_t>(BisectCubicSign(h, 0, 1)), std::bit_cast<uint64_t>(want));
}

TEST(BisectCubicSign, AnchoredBracketKeepsBisectSignsRoundLimit) {
  // h = -x (x - r1) (x - r2) / (r1 r2), r1,2 = (1 -+ 1/3) 2^-170: below 0
  // on (0, r1) and beyond r2, above between, where the midpoint 2^-170
  // falls after 169 halvings; the bracket [2^-170, 2^-169] then gets the
  // 50 rounds left of BisectSign's 200, too few to close it to the last
  // bit, and the shortcut must stop where BisectSign stops.
  const double r1 = 0x1p-170 * 2 / 3, r2 = 0x1p-170 * 4 / 3;
  const ElementCubic h{{0.0, -1.0, (r1 + r2) / (r1 * r2), -1 / (r1 * r2)}};
  const double want = contact::BisectSign(h, 0, 1);
  EXPECT_GT(want, 0x1p-170);
  EXPECT_LT(want, 0x1p-169);
  // Not closed to the last bit: 200 fresh rounds from there end elsewhere.
  EXPECT_NE(std::bit_cast<uint64_t>(contact::BisectSign(h, 0x1p-170, 0x1p-169)),
            std::bit_cast<uint64_t>(want));
  EXPECT_EQ(std::bit_cast<uint64_t>(BisectCubicSign(h, 0, 1)), std::bit_cast<uint64_t>(want));
}

TEST(BisectCubicSign, DoubleFlatAndLinearRootsMatchBisectSignToTheBit) {
  // (xi - r)^2 (xi - s) shifted by tiny amounts: two roots a hair apart,
  // where h's rounding decides the sign over many ulps.
  std::mt19937_64 rng(3400);
  std::uniform_real_distribution<double> u01(0.05, 0.95), tiny(-1e-12, 1e-12);
  int checked = 0;
  for (int k = 0; k < 5000; ++k) {
    const double r = u01(rng), s = u01(rng) + 2, d = tiny(rng);
    // (x - r)^2 (x - s) + d.
    const ElementCubic h{{-r * r * s + d, r * r + 2 * r * s, -(2 * r + s), 1.0}};
    checked += CheckBrackets(h);
    const ElementCubic flat{{-r * 1e-14, 1e-14, 0, 0}};  // linear, a tiny slope
    checked += CheckBrackets(flat);
    const ElementCubic steep{{-r * 1e9, 1e9, tiny(rng), 0}};
    checked += CheckBrackets(steep);
  }
  EXPECT_GT(checked, 5000);
}

TEST(SignChanges, MemoReturnsWhatTheComputationReturns) {
  // Many more cubics than the memo has slots, each asked for again at
  // once and again later (after others may have taken its slot), with
  // coefficients a bit apart: every answer must be ComputeSignChanges'.
  std::mt19937_64 rng(34000);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<ElementCubic> cubics;
  for (int k = 0; k < 500; ++k) {
    ElementCubic h{{unit(rng), unit(rng), unit(rng), unit(rng)}};
    cubics.push_back(h);
    h.c[0] = std::nextafter(h.c[0], 2.0);  // one ulp apart: another cubic
    cubics.push_back(h);
  }
  int roots_seen = 0;
  for (int pass = 0; pass < 3; ++pass) {
    for (const ElementCubic& h : cubics) {
      double want[3], got[3];
      const int n = ComputeSignChanges(h, want);
      for (int again = 0; again < 2; ++again) {
        ASSERT_EQ(SignChanges(h, got), n);
        for (int i = 0; i < n; ++i)
          EXPECT_EQ(std::bit_cast<uint64_t>(got[i]), std::bit_cast<uint64_t>(want[i]));
      }
      roots_seen += n;
    }
  }
  EXPECT_GT(roots_seen, 1000);
}

}  // namespace
}  // namespace cablesim
