// The skyline LDL^T and the preallocated Krylov solvers against Eigen's
// dense LU and Eigen's own (allocating) MINRES, on random systems of the
// shapes the steppers produce.

#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <unsupported/Eigen/IterativeSolvers>

#include "engine/linear/krylov.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/linear/skyline_ldlt.h"

namespace cablesim {
namespace {

// A random symmetric matrix with a variable band: row i couples to
// max(0, i - band_i)..i. Diagonally dominant when `definite`.
Eigen::MatrixXd RandomBanded(int n, std::vector<int>* first, bool definite, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> band(0, 6);
  first->resize(n);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    (*first)[i] = std::max(0, i - band(*rng));
    for (int j = (*first)[i]; j < i; ++j) a(i, j) = a(j, i) = u(*rng);
  }
  for (int i = 0; i < n; ++i) a(i, i) = (definite ? 8.0 : 3.0 * u(*rng)) + (definite ? 0 : 0.5);
  return a;
}

// `blocks` uncoupled RandomBanded blocks of size `block` (cables that no
// joint connects), with the skyline's first columns in `first`.
Eigen::MatrixXd BlockBanded(int block, int blocks, bool definite, std::vector<int>* first,
                            std::mt19937* rng) {
  const int n = block * blocks;
  first->resize(n);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int b = 0; b < blocks; ++b) {
    std::vector<int> f;
    a.block(b * block, b * block, block, block) = RandomBanded(block, &f, definite, rng);
    for (int i = 0; i < block; ++i) (*first)[b * block + i] = b * block + f[i];
  }
  return a;
}

void Load(const Eigen::MatrixXd& a, SkylineLdlt* s) {
  s->SetZero();
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j <= i; ++j)
      if (s->Slot(i, j) >= 0) s->values()[s->Slot(i, j)] = a(i, j);
}

// `s` with `a`'s pattern and values, factored; false if a pivot is not finite.
bool LoadAndFactor(const Eigen::MatrixXd& a, const std::vector<int>& first, SkylineLdlt* s) {
  s->SetPattern(first);
  Load(a, s);
  return s->Factor();
}

TEST(SkylineLdltTest, SolvesIndefiniteBandedSystemsLikeDenseLu) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<int> first;
    const Eigen::MatrixXd a = RandomBanded(60, &first, false, &rng);
    SkylineLdlt s;
    s.SetPattern(first);
    Load(a, &s);
    Eigen::VectorXd x = Eigen::VectorXd::Random(60), y(60);
    s.Multiply(x.data(), y.data());
    EXPECT_LT((y - a * x).norm(), 1e-12 * (a * x).norm());
    ASSERT_TRUE(s.Factor());
    const Eigen::VectorXd b = Eigen::VectorXd::Random(60);
    Eigen::VectorXd sol = b;
    s.Solve(sol.data());
    const Eigen::VectorXd ref = a.partialPivLu().solve(b);
    EXPECT_LT((sol - ref).norm(), 1e-8 * ref.norm());
  }
}

TEST(SkylineLdltTest, AbsoluteSolveIsPositiveDefinite) {
  std::mt19937 rng(4);
  std::vector<int> first;
  const Eigen::MatrixXd a = RandomBanded(40, &first, false, &rng);
  SkylineLdlt s;
  s.SetPattern(first);
  Load(a, &s);
  ASSERT_TRUE(s.Factor());
  EXPECT_GT(s.negative_pivots(), 0);  // the test matrix is indefinite
  Eigen::MatrixXd p(40, 40);
  for (int c = 0; c < 40; ++c) {
    Eigen::VectorXd e = Eigen::VectorXd::Unit(40, c);
    s.SolveAbs(e.data());
    p.col(c) = e;
  }
  EXPECT_LT((p - p.transpose()).norm(), 1e-10 * p.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(p).eigenvalues().minCoeff(), 0);
}

// A right-hand side with few non-zeros (a constraint row's column: one node
// of one cable) in a matrix of uncoupled blocks (three cables): the solve
// skips the zeros, so its solution must still match dense LU everywhere and
// be exactly zero outside the block that holds the non-zeros.
TEST(SkylineLdltTest, SparseRightHandSidesInUncoupledBlocksMatchDenseLu) {
  std::mt19937 rng(5);
  constexpr int kBlock = 20, kBlocks = 3, n = kBlock * kBlocks;
  std::vector<int> first;
  const Eigen::MatrixXd a = BlockBanded(kBlock, kBlocks, false, &first, &rng);
  SkylineLdlt s;
  ASSERT_TRUE(LoadAndFactor(a, first, &s));
  const auto lu = a.partialPivLu();
  // Non-zeros: inside the middle block (its last rows, as a fairlead's), at
  // the first and last index of the whole system, and one in two blocks.
  const std::vector<std::vector<int>> patterns = {
      {kBlock + 17, kBlock + 18, kBlock + 19}, {0}, {n - 1}, {3, 2 * kBlock + 5}};
  for (const std::vector<int>& nz : patterns) {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    for (int i : nz) b(i) = 1.0 + i;
    Eigen::VectorXd x = b;
    s.Solve(x.data());
    const Eigen::VectorXd ref = lu.solve(b);
    EXPECT_LT((x - ref).norm(), 1e-8 * ref.norm());
    for (int blk = 0; blk < kBlocks; ++blk) {
      bool touched = false;
      for (int i : nz) touched |= i / kBlock == blk;
      if (!touched) {
        EXPECT_EQ(x.segment(blk * kBlock, kBlock).norm(), 0) << "block " << blk;
      }
    }
  }
}

// The forward solve alone, from the first non-zero of a right-hand side on
// a block's last rows (a fairlead's column of B^T): it must report where its
// fill-in ends (inside that block), and with the pivots and the backward
// solve give A^{-1} b of dense LU.
TEST(SkylineLdltTest, ForwardSolveStopsWhereItsFillEndsAndBackwardSolveCompletesIt) {
  std::mt19937 rng(11);
  constexpr int kBlock = 20, kBlocks = 3, n = kBlock * kBlocks;
  std::vector<int> first;
  const Eigen::MatrixXd a = BlockBanded(kBlock, kBlocks, false, &first, &rng);
  SkylineLdlt s;
  ASSERT_TRUE(LoadAndFactor(a, first, &s));
  const auto lu = a.partialPivLu();
  for (int from : {kBlock - 3, kBlock + 5, n - 1}) {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
    b(from) = 2.0;
    if (from + 1 < n) b(from + 1) = -1.0;
    Eigen::VectorXd x = b;
    const int end = s.ForwardSolve(x.data(), from);
    const int block_end = (from / kBlock + 1) * kBlock;
    EXPECT_GT(end, from);
    EXPECT_LE(end, block_end) << "fill-in left the block of row " << from;
    EXPECT_EQ(x.tail(n - end).norm(), 0);
    EXPECT_EQ(x.head(from).norm(), 0);
    for (int i = 0; i < n; ++i) x(i) /= s.pivot(i);
    s.BackwardSolve(x.data());
    const Eigen::VectorXd ref = lu.solve(b);
    EXPECT_LT((x - ref).norm(), 1e-8 * ref.norm()) << "from " << from;
  }
}

// A mass-like matrix, mbar (x) I_3 node by node: two thirds of its
// envelope are exact zeros. The compressed multiply must give the full
// loop's sums bit for bit, and writing through values() must drop the
// record (a changed matrix multiplies as changed).
TEST(SkylineLdltTest, CompressedMultiplyIsTheFullMultiplyBitForBit) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.5, 2);
  constexpr int kNodes = 8, n = 6 * kNodes;  // position and slope, 3 components
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  std::vector<int> first(n);
  for (int e = 0; e + 1 < kNodes; ++e) {  // elements between nodes e and e + 1
    Eigen::Matrix4d mbar;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j <= i; ++j) mbar(i, j) = mbar(j, i) = u(rng) + (i == j ? 4 : 0);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        for (int d = 0; d < 3; ++d) a(6 * e + 3 * i + d, 6 * e + 3 * j + d) += mbar(i, j);
  }
  for (int i = 0; i < n; ++i) first[i] = std::max(0, 6 * (i / 6 - 1));
  SkylineLdlt full, compressed;
  full.SetPattern(first);
  compressed.SetPattern(first);
  Load(a, &full);
  Load(a, &compressed);
  compressed.CompressForMultiply();
  const Eigen::VectorXd x = Eigen::VectorXd::Random(n);
  Eigen::VectorXd y_full(n), y_compressed(n);
  full.Multiply(x.data(), y_full.data());
  compressed.Multiply(x.data(), y_compressed.data());
  for (int i = 0; i < n; ++i) EXPECT_EQ(y_compressed(i), y_full(i)) << i;
  EXPECT_LT((y_full - a * x).norm(), 1e-12 * (a * x).norm());
  // An entry that was zero (x of node 0 against y of node 1) is written.
  a(7, 0) = a(0, 7) = 0.25;
  compressed.values()[compressed.Slot(7, 0)] = 0.25;
  compressed.Multiply(x.data(), y_compressed.data());
  EXPECT_LT((y_compressed - a * x).norm(), 1e-12 * (a * x).norm());
}

TEST(KrylovTest, MinresMatchesEigenMinresOnSymmetricIndefiniteSystems) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<int> first;
    const Eigen::MatrixXd a = RandomBanded(50, &first, false, &rng);
    const Eigen::VectorXd b = Eigen::VectorXd::Random(50);
    Minres minres;
    Eigen::VectorXd x(50);
    auto op = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { out = a * in; };
    auto ident = [](const Eigen::VectorXd& in, Eigen::VectorXd& out) { out = in; };
    const KrylovResult r = minres.Solve(op, ident, b, 1e-12, 2000, x);
    EXPECT_TRUE(r.converged);
    Eigen::MINRES<Eigen::MatrixXd, Eigen::Lower | Eigen::Upper, Eigen::IdentityPreconditioner> ref;
    ref.setTolerance(1e-12);
    ref.setMaxIterations(2000);
    ref.compute(a);
    const Eigen::VectorXd xr = ref.solve(b);
    EXPECT_LT((x - xr).norm(), 1e-7 * xr.norm());
    EXPECT_LT((a * x - b).norm(), 1e-8 * b.norm());
  }
}

TEST(KrylovTest, GmresSolvesNonsymmetricSystemsWithRestarts) {
  std::mt19937 rng(6);
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(80, 80) + 12 * Eigen::MatrixXd::Identity(80, 80);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(80);
  Gmres gmres(10);  // forces restarts
  Eigen::VectorXd x(80);
  auto op = [&](const Eigen::VectorXd& in, Eigen::VectorXd& out) { out = a * in; };
  auto ident = [](const Eigen::VectorXd& in, Eigen::VectorXd& out) { out = in; };
  const KrylovResult r = gmres.Solve(op, ident, b, 1e-12, 500, x);
  EXPECT_TRUE(r.converged);
  EXPECT_LT((a * x - b).norm(), 1e-10 * b.norm());
}

TEST(SaddlePointSolverTest, BlockPreconditionedMinresNeedsFewIterations) {
  // A positive definite A and a full-rank B: with the exact Schur
  // complement MINRES needs at most 3 iterations in exact arithmetic
  // (Murphy, Golub and Wathen 2000); allow 6 for rounding.
  std::mt19937 rng(7);
  std::vector<int> first;
  const int n = 40, m = 5;
  const Eigen::MatrixXd a = RandomBanded(n, &first, true, &rng);
  SparseRows pattern;
  pattern.cols = n;
  std::uniform_int_distribution<int> col(0, n - 1);
  Eigen::MatrixXd bd = Eigen::MatrixXd::Zero(m, n);
  for (int r = 0; r < m; ++r) {
    for (int k = 0; k < 4; ++k) {
      const int c = col(rng);
      const double v = 1 + k;
      pattern.col.push_back(c);
      pattern.value.push_back(v);
      bd(r, c) += v;
    }
    pattern.row_start.push_back(static_cast<int>(pattern.col.size()));
  }
  for (LinearSolverKind kind : {LinearSolverKind::kMinres, LinearSolverKind::kGmres}) {
    SaddlePointSolver solver;
    solver.Resize(first, pattern);
    Load(a, &solver.a());
    ASSERT_TRUE(solver.Prepare());
    const Eigen::VectorXd rhs = Eigen::VectorXd::Random(n + m);
    Eigen::VectorXd x(n + m);
    const auto stats = solver.Solve(kind, rhs, 1e-12, 200, &x);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n + m, n + m);
    k.topLeftCorner(n, n) = a;
    k.topRightCorner(n, m) = bd.transpose();
    k.bottomLeftCorner(m, n) = bd;
    const Eigen::VectorXd ref = k.partialPivLu().solve(rhs);
    EXPECT_LT((x - ref).norm(), 1e-8 * ref.norm());
    EXPECT_LE(stats.iterations, 6);
    EXPECT_LT(stats.relative_residual, 1e-10);
  }
}

// DIRECT's block elimination (forward solves for L^{-1} B^T, the Schur
// complement from them, one forward and one backward solve per right-hand
// side) against dense LU of the whole saddle-point matrix, with rows on a
// block's last coordinates (fairleads) and rows across blocks; and the
// modified step of an indefinite A (SolveAbs) against dense LU with A
// replaced by L |D| L^T.
TEST(SaddlePointSolverTest, DirectEliminationMatchesDenseLu) {
  std::mt19937 rng(13);
  constexpr int kBlock = 18, kBlocks = 3, n = kBlock * kBlocks, m = 6;
  for (bool definite : {true, false}) {
    std::vector<int> first;
    const Eigen::MatrixXd a = BlockBanded(kBlock, kBlocks, definite, &first, &rng);
    SparseRows pattern;
    pattern.cols = n;
    Eigen::MatrixXd bd = Eigen::MatrixXd::Zero(m, n);
    auto add = [&](int r, int c, double v) {
      pattern.col.push_back(c);
      pattern.value.push_back(v);
      bd(r, c) += v;
    };
    for (int r = 0; r < 3; ++r) {  // a support on each block's last node
      add(r, (r + 1) * kBlock - 3 + r, 1.0);
      pattern.row_start.push_back(static_cast<int>(pattern.col.size()));
    }
    for (int r = 3; r < m; ++r) {  // rows coupling two blocks, and one inside
      add(r, 4 * r - 9, 1.5);
      add(r, r == 5 ? 5 : kBlock + 2 * r, -0.5 * r);
      pattern.row_start.push_back(static_cast<int>(pattern.col.size()));
    }
    SaddlePointSolver solver;
    solver.Resize(first, pattern);
    Load(a, &solver.a());
    ASSERT_TRUE(solver.Prepare());
    EXPECT_EQ(solver.direct_ready(), definite);
    const Eigen::VectorXd rhs = Eigen::VectorXd::Random(n + m);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n + m, n + m);
    k.topRightCorner(n, m) = bd.transpose();
    k.bottomLeftCorner(m, n) = bd;
    Eigen::VectorXd x(n + m);
    if (definite) {
      k.topLeftCorner(n, n) = a;
      const auto stats = solver.Solve(LinearSolverKind::kDirect, rhs, 1e-12, 200, &x);
      EXPECT_TRUE(stats.direct);
      EXPECT_FALSE(stats.fallback);
    } else {
      // L |D| L^T, from its inverse column by column.
      Eigen::MatrixXd p_inv(n, n);
      for (int c = 0; c < n; ++c) {
        Eigen::VectorXd e = Eigen::VectorXd::Unit(n, c);
        solver.a().SolveAbs(e.data());
        p_inv.col(c) = e;
      }
      k.topLeftCorner(n, n) = p_inv.inverse();
      ASSERT_TRUE(solver.SolveAbs(rhs, &x));
    }
    const Eigen::VectorXd ref = k.partialPivLu().solve(rhs);
    EXPECT_LT((x - ref).norm(), 1e-9 * ref.norm()) << (definite ? "definite" : "indefinite");
  }
}

}  // namespace
}  // namespace cablesim
