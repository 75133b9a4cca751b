// solver.preconditioner (BLOCK, JACOBI, NONE) and solver.accept_inexact_solves:
// every preconditioner solves the saddle-point system to the same answer
// (checked against a dense LU), the plain method needs more iterations than
// the block-preconditioned one, and a solve stopped by max_linear_iterations
// is refused unless accepted, and counted either way.

#include <random>
#include <string>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "engine/linear/saddle_point_solver.h"
#include "tests/test_util.h"

namespace cablesim {
namespace {

using cablesim::testing::CollectingSink;
using cablesim::testing::SceneFromJson;

// The Newton matrix of a cable under tension: M + h^2 K on a tridiagonal
// stiffness (a chain of springs, stiff against the mass: the ratio that makes
// an unpreconditioned Krylov method slow), and a few rows of B pinning
// coordinates and tying pairs.
struct System {
  std::vector<int> first;
  SparseRows pattern;
  Eigen::MatrixXd k;  // dense copy of the whole saddle-point matrix
};

System StiffChain(int n, int m, double stiffness) {
  System s;
  s.first.resize(n);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    s.first[i] = std::max(0, i - 1);
    // Springs stiffening along the chain, so that the diagonal varies.
    const double k_left = stiffness * (1 + i), k_right = stiffness * (2 + i);
    a(i, i) = 1 + k_left + k_right;
    if (i > 0) a(i, i - 1) = a(i - 1, i) = -k_left;
  }
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(m, n);
  s.pattern.cols = n;
  for (int r = 0; r < m; ++r) {
    const int c0 = (r * n) / m, c1 = c0 + 1;
    for (auto [c, v] : {std::pair{c0, 1.0}, std::pair{c1, -0.5}}) {
      s.pattern.col.push_back(c);
      s.pattern.value.push_back(v);
      b(r, c) += v;
    }
    s.pattern.row_start.push_back(static_cast<int>(s.pattern.col.size()));
  }
  s.k = Eigen::MatrixXd::Zero(n + m, n + m);
  s.k.topLeftCorner(n, n) = a;
  s.k.topRightCorner(n, m) = b.transpose();
  s.k.bottomLeftCorner(m, n) = b;
  return s;
}

void Load(const Eigen::MatrixXd& k, int n, SkylineLdlt* s) {
  s->SetZero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j)
      if (s->Slot(i, j) >= 0) s->values()[s->Slot(i, j)] = k(i, j);
}

TEST(PreconditionerTest, EveryPreconditionerSolvesTheSameSystemAndNoneNeedsMoreIterations) {
  const int n = 40, m = 4;
  const System sys = StiffChain(n, m, 1e3);
  const Eigen::VectorXd rhs = Eigen::VectorXd::LinSpaced(n + m, -1, 2);
  const Eigen::VectorXd ref = sys.k.partialPivLu().solve(rhs);
  for (LinearSolverKind kind : {LinearSolverKind::kMinres, LinearSolverKind::kGmres}) {
    int iterations[3] = {0, 0, 0};
    int i = 0;
    for (PreconditionerKind p :
         {PreconditionerKind::kBlock, PreconditionerKind::kJacobi, PreconditionerKind::kNone}) {
      SaddlePointSolver solver;
      solver.Resize(sys.first, sys.pattern);
      solver.Configure(p, false);
      Load(sys.k, n, &solver.a());
      ASSERT_TRUE(solver.Prepare());
      Eigen::VectorXd x(n + m);
      const auto stats = solver.Solve(kind, rhs, 1e-10, 5000, &x);
      // The true residual is what the solver reports (not its estimate):
      // recompute it here. 1e-8: the 1e-10 target (the default
      // solver.linear_tolerance) with a factor 100 for the gap between the
      // solver's estimate and the true residual, which the refinement passes
      // close only to that level; the steppers need 1e-6.
      const double true_residual = (rhs - sys.k * x).norm() / rhs.norm();
      EXPECT_NEAR(stats.relative_residual, true_residual, 1e-12 + 1e-6 * true_residual);
      const std::string what = absl::StrFormat("solver %d preconditioner %d: %d iterations",
                                               static_cast<int>(kind), static_cast<int>(p),
                                               stats.iterations);
      // Restarted GMRES(40) without the block preconditioner stagnates on
      // this system (measured: 7.7e-8 after 15000 iterations): only its
      // iteration count is checked.
      if (kind == LinearSolverKind::kMinres || p == PreconditionerKind::kBlock) {
        EXPECT_LT(true_residual, 1e-8) << what;
        EXPECT_LT((x - ref).norm(), 1e-6 * ref.norm()) << what;
      }
      iterations[i++] = stats.iterations;
    }
    // BLOCK is exact here (A definite): 3 distinct eigenvalues, a handful of
    // iterations (GMRES's estimate needs a refinement pass: 12 measured);
    // the plain method needs far more (a condition number of ~1e5).
    EXPECT_LE(iterations[0], kind == LinearSolverKind::kMinres ? 6 : 15);
    EXPECT_GT(iterations[2], 10 * iterations[0]);
    EXPECT_GT(iterations[1], iterations[0]);
  }
}

std::string Pendulum(const std::string& solver_extra) {
  return absl::StrFormat(R"json({
    "gravity": {"y": -9.81},
    "cables": [{"name": "beam", "length": 1.2, "elements": 6, "direction": {"x": 1},
                "density": 5540, "youngs_modulus": 0.7e6, "area": 0.0018,
                "second_moment": 1.215e-8}],
    "joints": [{"type": "PIN", "a": {"cable": "beam", "s": 0}}],
    "probes": [{"name": "tip", "cable": "beam", "s": 1.2}],
    "solver": {"duration": 0.02, "step": 1e-3, "integrator": "IMPLICIT_EULER",
               "linear_solver": "MINRES", "max_step_halvings": 2 %s}})json",
                         solver_extra);
}

TEST(PreconditionerTest, InexactSolvesAreRefusedUnlessAcceptedAndCounted) {
  CollectingSink sink;
  // BLOCK: a few iterations per solve, none inexact.
  auto block = RunScene(SceneFromJson(Pendulum("")), &sink);
  ASSERT_TRUE(block.ok()) << block.status();
  ASSERT_EQ(block->status, "ok") << block->error;
  EXPECT_EQ(block->inexact_linear_solves, 0);
  ASSERT_GT(block->linear_solves, 0);
  EXPECT_LE(block->linear_iterations, 6 * block->linear_solves);

  // NONE limited to 20 iterations (measured: 40 reach 1e-8) cannot reach
  // 1e-6 on every solve of this stiff cable, but gets close enough for
  // Newton to converge when such solves are accepted.
  const std::string plain = R"(, "preconditioner": "NONE", "max_linear_iterations": 20)";
  auto refused = RunScene(SceneFromJson(Pendulum(plain)), &sink);
  ASSERT_TRUE(refused.ok()) << refused.status();
  EXPECT_EQ(refused->status, "failed");
  EXPECT_NE(refused->error.find("did not converge"), std::string::npos) << refused->error;
  EXPECT_GT(refused->inexact_linear_solves, 0);

  auto accepted = RunScene(
      SceneFromJson(Pendulum(plain + R"(, "accept_inexact_solves": true)")), &sink);
  ASSERT_TRUE(accepted.ok()) << accepted.status();
  EXPECT_EQ(accepted->status, "ok") << accepted->error;
  EXPECT_GT(accepted->inexact_linear_solves, 0);
  EXPECT_LE(accepted->inexact_linear_solves, accepted->linear_solves);
  // Twenty iterations plus at most two refinement passes of twenty.
  EXPECT_LE(accepted->linear_iterations, 60 * accepted->linear_solves);
  EXPECT_GT(accepted->max_linear_residual, 1e-6);
}

TEST(PreconditionerTest, UnknownPreconditionerNamesTheField) {
  auto proto = ParseSceneJson(Pendulum(R"(, "preconditioner": "ILU")"));
  EXPECT_FALSE(proto.ok());
  EXPECT_NE(std::string(proto.status().message()).find("preconditioner"), std::string::npos)
      << proto.status();
}

}  // namespace
}  // namespace cablesim
