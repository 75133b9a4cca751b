#include "engine/linear/skyline_ldlt.h"

#include <algorithm>
#include <cmath>

namespace cablesim {

void SkylineLdlt::SetPattern(const std::vector<int>& first_col) {
  n_ = static_cast<int>(first_col.size());
  first_ = first_col;
  start_.assign(n_ + 1, 0);
  for (int i = 0; i < n_; ++i) {
    first_[i] = std::clamp(first_[i], 0, i);
    start_[i + 1] = start_[i] + (i - first_[i] + 1);
  }
  values_.assign(start_[n_], 0.0);
  factor_.assign(start_[n_], 0.0);
  d_.assign(n_, 0.0);
  compressed_ = false;
}

void SkylineLdlt::CompressForMultiply() {
  nz_start_.resize(n_ + 1);
  // Capacity for the whole envelope: a later call (winches, every step)
  // never allocates, even where an entry that was zero becomes non-zero.
  nz_col_.reserve(values_.size());
  nz_value_.reserve(values_.size());
  nz_col_.clear();
  nz_value_.clear();
  for (int i = 0; i < n_; ++i) {
    nz_start_[i] = static_cast<int>(nz_col_.size());
    const double* row = &values_[start_[i]];
    const int f = first_[i];
    for (int j = f; j < i; ++j) {
      if (row[j - f] == 0) continue;
      nz_col_.push_back(j);
      nz_value_.push_back(row[j - f]);
    }
  }
  nz_start_[n_] = static_cast<int>(nz_col_.size());
  compressed_ = true;
}

void SkylineLdlt::Multiply(const double* x, double* y) const {
  for (int i = 0; i < n_; ++i) y[i] = 0;
  if (compressed_) {
    // The loop below without its products with exact zeros.
    for (int i = 0; i < n_; ++i) {
      const double xi = x[i];
      double acc = 0;
      for (int k = nz_start_[i]; k < nz_start_[i + 1]; ++k) {
        const double a = nz_value_[k];
        const int j = nz_col_[k];
        acc += a * x[j];
        y[j] += a * xi;
      }
      y[i] += acc + values_[start_[i] + i - first_[i]] * xi;
    }
    return;
  }
  for (int i = 0; i < n_; ++i) {
    const double* row = &values_[start_[i]];
    const int f = first_[i];
    double acc = 0;
    for (int j = f; j < i; ++j) {
      const double a = row[j - f];
      acc += a * x[j];
      y[j] += a * x[i];
    }
    y[i] += acc + row[i - f] * x[i];
  }
}

void SkylineLdlt::AddAbsMultiply(const double* x, double* y) const {
  for (int i = 0; i < n_; ++i) {
    const double* row = &values_[start_[i]];
    const int f = first_[i];
    double acc = 0;
    for (int j = f; j < i; ++j) {
      const double a = std::abs(row[j - f]);
      acc += a * std::abs(x[j]);
      y[j] += a * std::abs(x[i]);
    }
    y[i] += acc + std::abs(row[i - f] * x[i]);
  }
}

void SkylineLdlt::MultiplyWithAbs(const double* x, double* y, double* abs_y) const {
  for (int i = 0; i < n_; ++i) y[i] = 0;
  for (int i = 0; i < n_; ++i) {
    const double* row = &values_[start_[i]];
    const int f = first_[i];
    const double xi = x[i], axi = std::abs(xi);
    double acc = 0, abs_acc = 0;
    for (int j = f; j < i; ++j) {
      const double a = row[j - f], aa = std::abs(a);
      acc += a * x[j];
      abs_acc += aa * std::abs(x[j]);
      y[j] += a * xi;
      abs_y[j] += aa * axi;
    }
    y[i] += acc + row[i - f] * xi;
    abs_y[i] += abs_acc + std::abs(row[i - f]) * axi;
  }
}

bool SkylineLdlt::Factor(double tiny) {
  small_pivots_ = 0;
  negative_pivots_ = 0;
  std::copy(values_.begin(), values_.end(), factor_.begin());
  for (int i = 0; i < n_; ++i) {
    double* row = &factor_[start_[i]];
    const int fi = first_[i];
    // Pass 1: row[j] <- w_j = A_ij - sum_k w_k L_jk  (w_k = L_ik D_k).
    for (int j = fi; j < i; ++j) {
      const int fj = first_[j];
      const int k0 = std::max(fi, fj);
      const double* rowj = &factor_[start_[j]];
      double acc = row[j - fi];
      for (int k = k0; k < j; ++k) acc -= row[k - fi] * rowj[k - fj];
      row[j - fi] = acc;
    }
    // Pass 2: L_ij = w_j / D_j and D_i = A_ii - sum_j w_j L_ij.
    double di = row[i - fi];
    for (int j = fi; j < i; ++j) {
      const double w = row[j - fi];
      const double l = w / d_[j];
      row[j - fi] = l;
      di -= w * l;
    }
    if (!std::isfinite(di)) return false;
    if (std::abs(di) < tiny) {
      di = di < 0 ? -tiny : tiny;
      ++small_pivots_;
    }
    if (di < 0) ++negative_pivots_;
    d_[i] = di;
    row[i - fi] = 1;
  }
  return true;
}

void SkylineLdlt::SolveImpl(double* x, bool abs) const {
  // L y = b, then D (or |D|), then L^T x = y. Zeros are skipped, not
  // multiplied: a right-hand side with few non-zero entries (a constraint
  // row's column of B^T, touching one node) costs only the rows its
  // solution reaches, the block of the cable that holds that node, instead
  // of the whole matrix twice. Every non-zero value is the one the full
  // loops give (they would only add products with exact zeros).
  ForwardSolve(x, 0);
  for (int i = 0; i < n_; ++i) x[i] /= abs ? std::abs(d_[i]) : d_[i];
  BackwardSolve(x);
}

int SkylineLdlt::ForwardSolve(double* x, int from) const {
  int last = from - 1;
  for (int i = from; i < n_; ++i) {
    const int fi = std::max(first_[i], from);
    if (fi > last) {
      if (x[i] != 0) last = i;
      continue;
    }
    const double* row = &factor_[start_[i]];
    const int f = first_[i];
    double acc = x[i];
    for (int k = fi; k < i; ++k) acc -= row[k - f] * x[k];
    x[i] = acc;
    if (acc != 0) last = i;
  }
  return last + 1;
}

void SkylineLdlt::BackwardSolve(double* x) const {
  for (int i = n_ - 1; i >= 0; --i) {
    const double xi = x[i];
    if (xi == 0) continue;
    const double* row = &factor_[start_[i]];
    const int fi = first_[i];
    for (int k = fi; k < i; ++k) x[k] -= row[k - fi] * xi;
  }
}

void SkylineLdlt::Solve(double* x) const { SolveImpl(x, false); }
void SkylineLdlt::SolveAbs(double* x) const { SolveImpl(x, true); }

}  // namespace cablesim
