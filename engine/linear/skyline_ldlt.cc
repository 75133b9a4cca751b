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
}

void SkylineLdlt::Multiply(const double* x, double* y) const {
  for (int i = 0; i < n_; ++i) y[i] = 0;
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
  // Zeros are skipped, not multiplied: a right-hand side with few non-zero
  // entries (a constraint row's column of B^T, touching one node) costs only
  // the rows its solution reaches, the block of the cable that holds that
  // node, instead of the whole matrix twice. Every non-zero value is the one
  // the full loops give (they would only add products with exact zeros).
  // L y = b. `last`: the last non-zero entry of y so far; a row whose
  // envelope starts after it sees only zeros and keeps b's entry.
  int last = -1;
  for (int i = 0; i < n_; ++i) {
    const int fi = first_[i];
    if (fi > last) {
      if (x[i] != 0) last = i;
      continue;
    }
    const double* row = &factor_[start_[i]];
    double acc = x[i];
    for (int k = fi; k < i; ++k) acc -= row[k - fi] * x[k];
    x[i] = acc;
    if (acc != 0) last = i;
  }
  for (int i = 0; i < n_; ++i) x[i] /= abs ? std::abs(d_[i]) : d_[i];
  // L^T x = y: a zero x_i changes nothing above it.
  for (int i = n_ - 1; i >= 0; --i) {
    const double xi = x[i];
    if (xi == 0) continue;
    const double* row = &factor_[start_[i]];
    const int fi = first_[i];
    for (int k = fi; k < i; ++k) x[k] -= row[k - fi] * xi;
  }
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
