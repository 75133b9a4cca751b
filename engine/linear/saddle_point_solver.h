#ifndef CABLESIM_ENGINE_LINEAR_SADDLE_POINT_SOLVER_H_
#define CABLESIM_ENGINE_LINEAR_SADDLE_POINT_SOLVER_H_

// Solves the symmetric saddle-point (KKT) systems of the steppers and of
// statics,
//
//   [ A   B^T ] [x1]   [r1]
//   [ B   0   ] [x2] = [r2],
//
// A = M + h^2 (K_T + H_lambda) (dynamics) or K_T + H_lambda (statics) on the
// unknowns, B = Phi_q (docs/model.md section 5), with MINRES or GMRES under the
// block-diagonal preconditioner
//
//   P = diag( L|D|L^T , B (L|D|L^T)^{-1} B^T ),
//
// where A = L D L^T is A's skyline factorization. P is symmetric positive
// definite, as MINRES requires; when A is positive definite the
// preconditioned matrix has only three distinct eigenvalues (Murphy, Golub
// and Wathen, SIAM J. Sci. Comput. 21, 2000), so MINRES converges in a few
// iterations whatever the step and the stiffness. After every solve the
// true residual is computed and returned, never only the estimate.
//
// Preconditioner JACOBI replaces P by diag(|A_ii|, diag(B diag(|A|)^{-1}
// B^T)), and NONE by the identity (plain MINRES or GMRES, as the paper ran
// them); A is still factored (DIRECT needs it). Without the block
// preconditioner a stiff system may need far more iterations than allowed:
// Stats::accept_inexact tells the caller whether such a solve may be used.
//
// DIRECT is exact block elimination with the same two factorizations: when
// A = L D L^T has only positive pivots (A positive definite, the usual case
// for M + h^2 K_T) and the Schur complement S = B A^{-1} B^T is dense
// (n m <= kMaxDenseSchurEntries),
//
//   S x2 = B A^{-1} r1 - r2,   x1 = A^{-1} r1 - (A^{-1} B^T) x2,
//
// with Y = L^{-1} B^T (forward solves only, each starting at the first
// coordinate its row touches), S = Y^T D^{-1} Y, B A^{-1} r1 = Y^T D^{-1} w
// and x1 = L^{-T} D^{-1} (w - Y x2) for w = L^{-1} r1: one skyline solve
// split around the Schur step and two dense triangular solves of size m, followed by
// one refinement pass if the true residual is above the tolerance (the
// Schur complement carries a 1e-12 relative shift against redundant
// constraints). Otherwise (a negative pivot, or too many constraints for a
// dense S) the solve falls back to preconditioned MINRES and says so in
// Stats::fallback. AUTO is DIRECT when S is dense, MINRES otherwise.
//
// Nothing here allocates after Resize().

#include <vector>

#include <Eigen/Core>

#include "engine/linear/krylov.h"
#include "engine/scene/scene.h"
#include "engine/linear/skyline_ldlt.h"
#include "engine/linear/sparse_rows.h"

namespace cablesim {

class SaddlePointSolver {
 public:
  struct Stats {
    int iterations = 0;
    double relative_residual = 0;  // true: |r - K x| / |r|
    bool converged = false;
    bool fallback = false;  // DIRECT/AUTO could not eliminate: MINRES ran
    bool direct = false;    // solved by block elimination
    bool accept_inexact = false;  // as configured (newton_convergence.h)
  };

  // MINRES and GMRES preconditioner, and whether callers may accept a solve
  // that stopped above their residual bound. Default BLOCK, false.
  void Configure(PreconditionerKind preconditioner, bool accept_inexact) {
    preconditioner_ = preconditioner;
    accept_inexact_ = accept_inexact;
  }

  void Resize(const std::vector<int>& envelope, const SparseRows& jacobian_pattern);

  int n() const { return a_.size(); }
  int m() const { return b_.rows(); }
  SkylineLdlt& a() { return a_; }
  SparseRows& b() { return b_; }

  // Adds gamma B^T B to the assembled A (call after assembling A and B,
  // before Prepare). Solve() then adds gamma B^T r2 to r1, so the solution
  // is unchanged: an augmented Lagrangian that makes A definite where only
  // the constraints hold the unknowns (a body in statics has no stiffness).
  void Augment(double gamma);

  // Factors A and forms the Schur-complement preconditioner. False when a
  // pivot is not finite.
  bool Prepare();

  // Solves K x = rhs (sizes n + m). `tolerance` is relative.
  Stats Solve(LinearSolverKind kind, const Eigen::VectorXd& rhs, double tolerance,
              int max_iterations, Eigen::VectorXd* x);

  // The modified step of an indefinite A (its pivots' signs flipped, as
  // SkylineLdlt::SolveAbs): block elimination with (L|D|L^T)^{-1} in place
  // of A^{-1}, so that B x1 = r2 still holds exactly. False (x untouched)
  // without the dense Schur complement Prepare forms when it fits.
  bool SolveAbs(const Eigen::VectorXd& rhs, Eigen::VectorXd* x);

  // y = K x.
  void Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;

  // What AUTO resolves to for this system (after Resize), or for a system
  // of n unknowns and m multipliers.
  LinearSolverKind Resolve(LinearSolverKind kind) const { return Resolve(kind, n(), m()); }
  static LinearSolverKind Resolve(LinearSolverKind kind, int n, int m);
  // True when the last Prepare() allows exact block elimination.
  bool direct_ready() const { return direct_ready_; }

 private:
  // Block elimination (see the class comment); x must not alias rhs.
  void SolveDirect(const Eigen::VectorXd& rhs, Eigen::VectorXd* x, bool abs = false);

  void Precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  // x <- S^{-1} x (size m) with the Cholesky factor schur_l_.
  void SchurSolve(double* x) const;

  SkylineLdlt a_;
  SparseRows b_;
  // L^{-1} B^T, n x m (A = L D L^T). Column r is non-zero only in rows
  // [y_lo_[r], y_hi_[r]): from the first coordinate constraint r touches to
  // where the forward solve stops filling in, a few rows for a joint on a
  // cable's last node.
  Eigen::MatrixXd y_;
  std::vector<int> y_lo_, y_hi_;
  Eigen::MatrixXd schur_;  // m x m
  // Cholesky factor of the Schur complement, in place (lower triangle):
  // Eigen's LLT allocates a workspace for large matrices.
  Eigen::MatrixXd schur_l_;
  double gamma_ = 0;
  PreconditionerKind preconditioner_ = PreconditionerKind::kBlock;
  bool accept_inexact_ = false;
  Eigen::VectorXd jacobi_;  // 1 / |A_ii| (JACOBI)
  Eigen::VectorXd augmented_rhs_;
  bool schur_dense_ = true;
  bool direct_ready_ = false;
  Eigen::VectorXd schur_diag_;
  mutable Eigen::VectorXd col_, tmp_;
  Eigen::VectorXd residual_, correction_;
  Minres minres_;
  Gmres gmres_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_SADDLE_POINT_SOLVER_H_
