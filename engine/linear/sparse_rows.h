#ifndef CABLESIM_ENGINE_LINEAR_SPARSE_ROWS_H_
#define CABLESIM_ENGINE_LINEAR_SPARSE_ROWS_H_

// A matrix with a fixed sparsity pattern stored row by row (compressed
// rows): the constraint Jacobian Phi_q, whose pattern is known when the
// model is built and whose values change every Newton iteration. Repeated
// column indices in a row are allowed and add up.

#include <cmath>
#include <vector>

#include <Eigen/Core>

namespace cablesim {

struct SparseRows {
  int cols = 0;
  std::vector<int> row_start{0};  // size rows() + 1
  std::vector<int> col;
  std::vector<double> value;

  int rows() const { return static_cast<int>(row_start.size()) - 1; }

  // y = J x
  void Multiply(const double* x, double* y) const {
    for (int r = 0; r < rows(); ++r) {
      double acc = 0;
      for (int k = row_start[r]; k < row_start[r + 1]; ++k) acc += value[k] * x[col[k]];
      y[r] = acc;
    }
  }
  // y += J^T x
  void AddTransposeMultiply(const double* x, double* y) const {
    for (int r = 0; r < rows(); ++r)
      for (int k = row_start[r]; k < row_start[r + 1]; ++k) y[col[k]] += value[k] * x[r];
  }
  // y += s |J|^T |x| (entrywise absolute values): a bound on the terms
  // summed into s J^T x, for rounding estimates.
  void AddAbsTransposeMultiply(const double* x, double* y, double s = 1.0) const {
    for (int r = 0; r < rows(); ++r)
      for (int k = row_start[r]; k < row_start[r + 1]; ++k)
        y[col[k]] += std::abs(s * value[k] * x[r]);
  }
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_SPARSE_ROWS_H_
