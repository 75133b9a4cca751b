#ifndef CABLESIM_ENGINE_LINEAR_SKYLINE_LDLT_H_
#define CABLESIM_ENGINE_LINEAR_SKYLINE_LDLT_H_

// A symmetric matrix in skyline (variable-band, row envelope) storage with an
// in-place LDL^T factorization, for the block of the Newton matrix that acts
// on the coordinates, M + h^2 (K_T + H_lambda).
//
// Why hand-written: a cable orders its coordinates node by node, so this
// block is banded (bandwidth 2 D - 1 plus what joints add) and the envelope
// holds all of its fill-in. Eigen's SimplicialLDLT allocates on every
// factorize() (a permuted copy and work arrays), and the stepping loop must
// not allocate; this class allocates only in SetPattern().
//
// Row i stores columns first(i)..i. Factor() computes A = L D L^T (L unit
// lower, no pivoting). SolveAbs() applies (L |D| L^T)^{-1}: the symmetric
// positive definite operator MINRES needs as a preconditioner, exact
// whenever A is positive definite.

#include <algorithm>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace cablesim {

class SkylineLdlt {
 public:
  // `first_col[i]` <= i is the first stored column of row i.
  void SetPattern(const std::vector<int>& first_col);

  int size() const { return n_; }
  int stored() const { return static_cast<int>(values_.size()); }
  // Index into values() of entry (i, j), j <= i; -1 outside the envelope.
  int Slot(int i, int j) const {
    if (j > i) std::swap(i, j);
    return j < first_[i] ? -1 : start_[i] + (j - first_[i]);
  }
  void SetZero() {
    std::fill(values_.begin(), values_.end(), 0.0);
    compressed_ = false;
  }
  // Writable values: forgets CompressForMultiply's record.
  double* values() {
    compressed_ = false;
    return values_.data();
  }
  const double* values() const { return values_.data(); }

  // y = A x (the matrix as assembled, not the factor).
  void Multiply(const double* x, double* y) const;
  // Records where the assembled values are non-zero, for a matrix
  // multiplied many times between changes (the mass matrix: a cable's is
  // mbar (x) I, so two thirds of its envelope are zeros between directions).
  // Multiply then visits only those entries, in the same order, so its sums
  // are the same. Only the first call allocates (room for the whole
  // envelope); writing through values() drops the record.
  void CompressForMultiply();
  // y += |A| |x| (entrywise absolute values): a bound on the terms summed
  // into A x, for rounding estimates.
  void AddAbsMultiply(const double* x, double* y) const;
  // Both in one pass over the matrix: y = A x and abs_y += |A| |x|.
  void MultiplyWithAbs(const double* x, double* y, double* abs_y) const;

  // Factorizes a copy of the assembled values. Returns false if a pivot is
  // not finite. Pivots smaller than `tiny` in magnitude are replaced by
  // `tiny` (counted in small_pivots()).
  bool Factor(double tiny = 1e-300);
  int small_pivots() const { return small_pivots_; }
  int negative_pivots() const { return negative_pivots_; }

  // x = (L D L^T)^{-1} b, in place.
  void Solve(double* x) const;
  // x = (L |D| L^T)^{-1} b, in place.
  void SolveAbs(double* x) const;
  // The first half of Solve: x = L^{-1} b in place, for b (and so x) zero
  // before index `from` (entries there are neither read nor written): a
  // right-hand side that starts late in the ordering costs only the rows
  // after it. With pivot(i) = D_ii, b^T A^{-1} c = sum_i x_b[i] x_c[i] / D_ii.
  // Rows whose envelope starts after the last non-zero entry so far keep
  // b's entry (they would only subtract products with exact zeros). Returns
  // one past the last non-zero entry of x (`from` if there is none): a
  // constraint row's column of B^T on a cable's last node stays within the
  // few rows after that node.
  int ForwardSolve(double* x, int from) const;
  // The second half of Solve: x = L^{-T} y in place (zero entries of y are
  // skipped).
  void BackwardSolve(double* x) const;
  double pivot(int i) const { return d_[i]; }

 private:
  void SolveImpl(double* x, bool abs) const;

  int n_ = 0;
  std::vector<int> first_, start_;
  std::vector<double> values_;  // the assembled matrix
  std::vector<double> factor_;  // L (strict lower) in the same layout
  std::vector<double> d_;
  // CompressForMultiply: row i's non-zero strictly lower entries are
  // nz_col_/nz_value_[nz_start_[i] .. nz_start_[i + 1]) (its diagonal stays
  // in values_).
  bool compressed_ = false;
  std::vector<int> nz_start_, nz_col_;
  std::vector<double> nz_value_;
  int small_pivots_ = 0;
  int negative_pivots_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_SKYLINE_LDLT_H_
