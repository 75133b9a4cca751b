#include "engine/linear/saddle_point_solver.h"

#include <algorithm>
#include <cmath>

namespace cablesim {
namespace {
// Beyond this many entries in (L|D|L^T)^{-1} B^T the Schur complement is
// approximated by its diagonal.
constexpr long kMaxDenseSchurEntries = 20'000'000;
}  // namespace

void SaddlePointSolver::Resize(const std::vector<int>& envelope,
                               const SparseRows& jacobian_pattern) {
  a_.SetPattern(envelope);
  b_ = jacobian_pattern;
  const int n = a_.size(), m = b_.rows();
  schur_dense_ = static_cast<long>(n) * m <= kMaxDenseSchurEntries;
  if (schur_dense_) {
    y_.setZero(n, m);
    y_lo_.assign(m, 0);
    y_hi_.assign(m, 0);
    schur_.setZero(m, m);
    schur_l_.setZero(m, m);
  }
  schur_diag_.setZero(m);
  jacobi_.setZero(n);
  col_.setZero(n);
  tmp_.setZero(n + m);
  residual_.setZero(n + m);
  correction_.setZero(n + m);
  augmented_rhs_.setZero(n + m);
  minres_.Resize(n + m);
  gmres_.Resize(n + m);
}

void SaddlePointSolver::Augment(double gamma) {
  gamma_ = gamma;
  double* values = a_.values();
  for (int r = 0; r < b_.rows(); ++r) {
    for (int x = b_.row_start[r]; x < b_.row_start[r + 1]; ++x) {
      for (int y = b_.row_start[r]; y < b_.row_start[r + 1]; ++y) {
        const int cx = b_.col[x], cy = b_.col[y];
        // Lower triangle; a diagonal entry takes both orders of x != y.
        if (cy > cx) continue;
        values[a_.Slot(cx, cy)] += gamma * b_.value[x] * b_.value[y];
      }
    }
  }
}

namespace {
// In-place Cholesky of the lower triangle; false unless positive definite.
bool CholeskyInPlace(Eigen::MatrixXd& s) {
  const int m = static_cast<int>(s.rows());
  for (int j = 0; j < m; ++j) {
    double d = s(j, j);
    for (int k = 0; k < j; ++k) d -= s(j, k) * s(j, k);
    if (!(d > 0)) return false;
    d = std::sqrt(d);
    s(j, j) = d;
    for (int i = j + 1; i < m; ++i) {
      double v = s(i, j);
      for (int k = 0; k < j; ++k) v -= s(i, k) * s(j, k);
      s(i, j) = v / d;
    }
  }
  return true;
}
}  // namespace

LinearSolverKind SaddlePointSolver::Resolve(LinearSolverKind kind, int n, int m) {
  if (kind != LinearSolverKind::kAuto) return kind;
  return static_cast<long>(n) * m <= kMaxDenseSchurEntries ? LinearSolverKind::kDirect
                                                           : LinearSolverKind::kMinres;
}

bool SaddlePointSolver::Prepare() {
  direct_ready_ = false;
  if (!a_.Factor()) return false;
  // With positive pivots, (L|D|L^T)^{-1} = A^{-1}: the preconditioner's
  // blocks are the exact elimination's.
  const bool definite = a_.negative_pivots() == 0 && a_.small_pivots() == 0;
  if (preconditioner_ == PreconditionerKind::kJacobi) {
    for (int j = 0; j < a_.size(); ++j) {
      const double d = std::abs(a_.values()[a_.Slot(j, j)]);
      jacobi_(j) = d > 0 ? 1 / d : 1;
    }
  }
  const int m = b_.rows();
  if (m == 0) {
    direct_ready_ = definite;
    return true;
  }
  if (schur_dense_) {
    const int n = a_.size();
    // Y = L^{-1} B^T column by column; S = Y^T |D|^{-1} Y (= B A^{-1} B^T
    // when every pivot is positive, the preconditioner's block otherwise).
    for (int r = 0; r < m; ++r) {
      double* y = y_.col(r).data();
      std::fill(y + y_lo_[r], y + y_hi_[r], 0.0);
      int lo = n;
      for (int k = b_.row_start[r]; k < b_.row_start[r + 1]; ++k) {
        y[b_.col[k]] += b_.value[k];
        lo = std::min(lo, b_.col[k]);
      }
      y_lo_[r] = lo < n ? lo : 0;
      y_hi_[r] = lo < n ? a_.ForwardSolve(y, lo) : 0;
    }
    for (int r = 0; r < m; ++r) {
      const double* yr = y_.col(r).data();
      for (int c = 0; c <= r; ++c) {
        const double* yc = y_.col(c).data();
        double acc = 0;
        const int hi = std::min(y_hi_[r], y_hi_[c]);
        for (int k = std::max(y_lo_[r], y_lo_[c]); k < hi; ++k)
          acc += yr[k] * yc[k] / std::abs(a_.pivot(k));
        schur_(r, c) = acc;
        schur_(c, r) = acc;
      }
    }
    // Redundant constraints make S singular: a relative shift keeps the
    // preconditioner positive definite without changing the system solved.
    const double shift = 1e-12 * schur_.diagonal().cwiseAbs().maxCoeff() + 1e-300;
    schur_.diagonal().array() += shift;
    schur_l_ = schur_;
    if (!CholeskyInPlace(schur_l_)) return false;
    direct_ready_ = definite;
  }
  if (!schur_dense_ || preconditioner_ == PreconditionerKind::kJacobi) {
    // diag(B diag(|A|)^{-1} B^T) as a cheap positive approximation.
    for (int r = 0; r < m; ++r) {
      double acc = 0;
      for (int k = b_.row_start[r]; k < b_.row_start[r + 1]; ++k) {
        const int j = b_.col[k];
        acc += b_.value[k] * b_.value[k] / std::abs(a_.values()[a_.Slot(j, j)]);
      }
      schur_diag_(r) = acc > 0 ? acc : 1;
    }
  }
  return true;
}

void SaddlePointSolver::Multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const int n = a_.size();
  a_.Multiply(x.data(), y.data());
  if (b_.rows() == 0) return;
  b_.AddTransposeMultiply(x.data() + n, y.data());
  b_.Multiply(x.data(), y.data() + n);
}

void SaddlePointSolver::Precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const int n = a_.size(), m = b_.rows();
  z = r;
  if (preconditioner_ == PreconditionerKind::kNone) return;
  if (preconditioner_ == PreconditionerKind::kJacobi) {
    z.head(n).array() *= jacobi_.array();
    if (m > 0) z.segment(n, m).array() /= schur_diag_.array();
    return;
  }
  a_.SolveAbs(z.data());
  if (m == 0) return;
  auto z2 = z.segment(n, m);
  if (schur_dense_) {
    SchurSolve(z2.data());
  } else {
    z2.array() /= schur_diag_.array();
  }
}

void SaddlePointSolver::SchurSolve(double* x) const {
  const int m = b_.rows();
  for (int i = 0; i < m; ++i) {  // L y = x
    double v = x[i];
    for (int k = 0; k < i; ++k) v -= schur_l_(i, k) * x[k];
    x[i] = v / schur_l_(i, i);
  }
  for (int i = m - 1; i >= 0; --i) {  // L^T x = y
    double v = x[i];
    for (int k = i + 1; k < m; ++k) v -= schur_l_(k, i) * x[k];
    x[i] = v / schur_l_(i, i);
  }
}

void SaddlePointSolver::SolveDirect(const Eigen::VectorXd& rhs, Eigen::VectorXd* x, bool abs) {
  const int n = a_.size(), m = b_.rows();
  // w = L^{-1} r1 (y_ and the Schur complement are formed with |D|, the
  // same as D when every pivot is positive).
  x->head(n) = rhs.head(n);
  double* w = x->data();
  a_.ForwardSolve(w, 0);
  auto divide = [&](int i) { return abs ? std::abs(a_.pivot(i)) : a_.pivot(i); };
  if (m > 0) {
    // x2 <- S^{-1} (B A^{-1} r1 - r2), B A^{-1} r1 = Y^T D^{-1} w.
    auto x2 = x->segment(n, m);
    for (int r = 0; r < m; ++r) {
      const double* y = y_.col(r).data();
      double acc = 0;
      for (int k = y_lo_[r]; k < y_hi_[r]; ++k) acc += y[k] * w[k] / divide(k);
      x2(r) = acc - rhs(n + r);
    }
    SchurSolve(x2.data());
    // w <- w - Y x2 = L^{-1} (r1 - B^T x2).
    for (int r = 0; r < m; ++r) {
      const double* y = y_.col(r).data();
      const double xr = x2(r);
      for (int k = y_lo_[r]; k < y_hi_[r]; ++k) w[k] -= y[k] * xr;
    }
  }
  // x1 <- L^{-T} D^{-1} w.
  for (int i = 0; i < n; ++i) w[i] /= divide(i);
  a_.BackwardSolve(w);
}

bool SaddlePointSolver::SolveAbs(const Eigen::VectorXd& rhs, Eigen::VectorXd* x) {
  if (b_.rows() > 0 && !schur_dense_) return false;
  if (gamma_ != 0 && b_.rows() > 0) {
    augmented_rhs_ = rhs;
    tmp_.head(b_.rows()) = gamma_ * rhs.tail(b_.rows());
    b_.AddTransposeMultiply(tmp_.data(), augmented_rhs_.data());
    SolveDirect(augmented_rhs_, x, true);
  } else {
    SolveDirect(rhs, x, true);
  }
  return true;
}

SaddlePointSolver::Stats SaddlePointSolver::Solve(LinearSolverKind kind_in,
                                                  const Eigen::VectorXd& rhs_in, double tolerance,
                                                  int max_iterations, Eigen::VectorXd* x) {
  LinearSolverKind kind = Resolve(kind_in);
  Stats stats;
  stats.accept_inexact = accept_inexact_;
  if (kind == LinearSolverKind::kDirect && !direct_ready_) {
    kind = LinearSolverKind::kMinres;
    stats.fallback = true;
  }
  const Eigen::VectorXd* rhs_ptr = &rhs_in;
  if (gamma_ != 0 && b_.rows() > 0) {
    // [A + gamma B^T B, B^T; B, 0] x = [r1 + gamma B^T r2; r2] has the
    // solution of the original system.
    augmented_rhs_ = rhs_in;
    tmp_.head(b_.rows()) = gamma_ * rhs_in.tail(b_.rows());
    b_.AddTransposeMultiply(tmp_.data(), augmented_rhs_.data());
    rhs_ptr = &augmented_rhs_;
  }
  const Eigen::VectorXd& rhs = *rhs_ptr;
  const double bn = rhs.norm();
  auto true_residual = [&] {
    Multiply(*x, residual_);
    residual_ = rhs - residual_;
    return bn > 0 ? residual_.norm() / bn : residual_.norm();
  };
  if (kind == LinearSolverKind::kDirect) {
    stats.direct = true;
    SolveDirect(rhs, x);
    stats.relative_residual = true_residual();
    // One refinement pass removes the effect of the Schur shift and of
    // rounding in badly scaled systems.
    if (stats.relative_residual > tolerance && std::isfinite(stats.relative_residual)) {
      tmp_ = residual_;
      SolveDirect(tmp_, &correction_);
      *x += correction_;
      stats.relative_residual = true_residual();
    }
    stats.converged = std::isfinite(stats.relative_residual);
    return stats;
  }
  auto op = [this](const Eigen::VectorXd& in, Eigen::VectorXd& out) { Multiply(in, out); };
  auto prec = [this](const Eigen::VectorXd& in, Eigen::VectorXd& out) { Precondition(in, out); };
  auto krylov = [&](const Eigen::VectorXd& b, Eigen::VectorXd& out) {
    return kind == LinearSolverKind::kGmres
               ? gmres_.Solve(op, prec, b, tolerance, max_iterations, out)
               : minres_.Solve(op, prec, b, tolerance, max_iterations, out);
  };
  KrylovResult kr = krylov(rhs, *x);
  stats.iterations = kr.iterations;
  stats.relative_residual = true_residual();
  // MINRES stops on its residual estimate in the P^{-1} norm, which can sit
  // orders of magnitude below the true Euclidean residual when P is badly
  // scaled. Up to two refinement passes solve for the correction.
  for (int pass = 0; pass < 2 && stats.relative_residual > 100 * tolerance &&
                     std::isfinite(stats.relative_residual);
       ++pass) {
    tmp_ = residual_;
    const KrylovResult kc = krylov(tmp_, correction_);
    stats.iterations += kc.iterations;
    *x += correction_;
    stats.relative_residual = true_residual();
    kr.converged = kc.converged;
  }
  stats.converged = std::isfinite(stats.relative_residual) && kr.converged;
  return stats;
}

}  // namespace cablesim
