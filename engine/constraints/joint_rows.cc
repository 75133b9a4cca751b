#include "engine/constraints/joint_rows.h"

#include <algorithm>
#include <cassert>

#include <Eigen/Geometry>

namespace cablesim {

using Eigen::VectorXd;

void JointRows::AddRow(const QuadraticForm& f, Row::Kind kind, int joint, int body) {
  Row row;
  row.kind = kind;
  row.joint = joint;
  row.body = body;
  row.c = f.c;
  std::vector<int> coords;
  for (const auto& [i, v] : f.linear)
    if (v != 0) coords.push_back(i);
  for (const auto& [ij, v] : f.quadratic) {
    if (v == 0) continue;
    coords.push_back(ij.first);
    coords.push_back(ij.second);
  }
  std::sort(coords.begin(), coords.end());
  coords.erase(std::unique(coords.begin(), coords.end()), coords.end());
  assert(static_cast<int>(coords.size()) <= kMaxRowCoords);
  auto local = [&](int i) {
    return static_cast<int>(std::lower_bound(coords.begin(), coords.end(), i) - coords.begin());
  };
  row.coord_begin = static_cast<int>(row_coord_.size());
  row_coord_.insert(row_coord_.end(), coords.begin(), coords.end());
  row.coord_end = static_cast<int>(row_coord_.size());
  row.lin_begin = static_cast<int>(lin_local_.size());
  for (const auto& [i, v] : f.linear) {
    if (v == 0) continue;
    lin_local_.push_back(local(i));
    lin_value_.push_back(v);
  }
  row.lin_end = static_cast<int>(lin_local_.size());
  row.mono_begin = static_cast<int>(mono_a_.size());
  for (const auto& [ij, v] : f.quadratic) {
    if (v == 0) continue;
    mono_a_.push_back(local(ij.first));
    mono_b_.push_back(local(ij.second));
    mono_w_.push_back(v);
  }
  row.mono_end = static_cast<int>(mono_a_.size());
  rows_.push_back(row);
}

double JointRows::Value(const Row& row, const VectorXd& q) const {
  const int* coord = &row_coord_[row.coord_begin];
  double acc = row.c;
  for (int k = row.lin_begin; k < row.lin_end; ++k) acc += lin_value_[k] * q(coord[lin_local_[k]]);
  for (int k = row.mono_begin; k < row.mono_end; ++k)
    acc += mono_w_[k] * q(coord[mono_a_[k]]) * q(coord[mono_b_[k]]);
  return acc;
}

void JointRows::Gradient(const Row& row, const VectorXd& q, double* grad) const {
  const int* coord = &row_coord_[row.coord_begin];
  const int n = row.coord_end - row.coord_begin;
  for (int k = 0; k < n; ++k) grad[k] = 0;
  for (int k = row.lin_begin; k < row.lin_end; ++k) grad[lin_local_[k]] += lin_value_[k];
  for (int k = row.mono_begin; k < row.mono_end; ++k) {
    grad[mono_a_[k]] += mono_w_[k] * q(coord[mono_b_[k]]);
    grad[mono_b_[k]] += mono_w_[k] * q(coord[mono_a_[k]]);
  }
}

void JointRows::SetLinear(int i, const Eigen::Vector3d& n, int first) {
  const Row& row = rows_[i];
  for (int k = row.lin_begin; k < row.lin_end; ++k)
    lin_value_[k] = n(row_coord_[row.coord_begin + lin_local_[k]] - first);
}

void JointRows::SetupPattern(const CoordinateMap& map, int dofs, SparseRows* jac) {
  jac->cols = dofs;
  for (const Row& row : rows_) {
    for (int k = row.coord_begin; k < row.coord_end; ++k) {
      if (map.j[row_coord_[k]] < 0) continue;
      jac->col.push_back(map.j[row_coord_[k]]);
      jac->value.push_back(0);
    }
    jac->row_start.push_back(static_cast<int>(jac->col.size()));
  }
  mono_row_.assign(mono_a_.size(), -1);
  mono_col_.assign(mono_a_.size(), -1);
  mono_factor_.assign(mono_a_.size(), 0.0);
  for (const Row& row : rows_) {
    const int* coord = &row_coord_[row.coord_begin];
    for (int k = row.mono_begin; k < row.mono_end; ++k) {
      const int a = coord[mono_a_[k]], b = coord[mono_b_[k]];
      const int ja = map.j[a], jb = map.j[b];
      if (ja < 0 || jb < 0) continue;
      // w q_a q_b has Hessian entries (a, b) and (b, a) equal to w; on z
      // they land on (ja, jb) and (jb, ja): stored once off the diagonal,
      // twice (2 w) on it.
      mono_row_[k] = std::max(ja, jb);
      mono_col_[k] = std::min(ja, jb);
      mono_factor_[k] = mono_w_[k] * map.s[a] * map.s[b] * (ja == jb ? 2 : 1);
    }
  }
}

void JointRows::Residual(const VectorXd& q, const CoordinateMap& map, VectorXd* phi,
                         SparseRows* jac) const {
  int slot = 0;
  double grad[kMaxRowCoords];
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    (*phi)(i) = Value(row, q);
    if (!jac) continue;
    Gradient(row, q, grad);
    for (int k = row.coord_begin; k < row.coord_end; ++k) {
      const int coord = row_coord_[k];
      if (map.j[coord] < 0) continue;
      jac->value[slot++] = grad[k - row.coord_begin] * map.s[coord];
    }
  }
}

void JointRows::AddHessian(const VectorXd& lambda, double scale, SkylineLdlt* a) const {
  double* values = a->values();
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    const double f = scale * lambda(i);
    // Slots are looked up in `a` (any pattern containing the envelope).
    for (int k = row.mono_begin; k < row.mono_end; ++k)
      if (mono_row_[k] >= 0) values[a->Slot(mono_row_[k], mono_col_[k])] += f * mono_factor_[k];
  }
}

void JointRows::AddGamma(const VectorXd& q, const VectorXd& qdot, VectorXd* gamma) const {
  (void)q;
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    const int* coord = &row_coord_[row.coord_begin];
    double acc = 0;
    for (int k = row.mono_begin; k < row.mono_end; ++k)
      acc += mono_w_[k] * qdot(coord[mono_a_[k]]) * qdot(coord[mono_b_[k]]);
    (*gamma)(i) += -2 * acc;
  }
}

void JointRows::AddReactions(const VectorXd& q, const VectorXd& lambda,
                             std::vector<Eigen::Vector3d>* forces,
                             std::vector<Eigen::Vector3d>* moments) const {
  double grad[kMaxRowCoords];
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    if (row.joint < 0) continue;
    if (row.kind == Row::kPosition) {
      if (row.axis >= 0) (*forces)[row.joint](row.axis) -= lambda(i);
      continue;
    }
    if (row.side_end <= row.side_begin) continue;
    // dPhi/dx for each of side a's vectors x, then -lambda x x dPhi/dx.
    Gradient(row, q, grad);
    const int vectors = (row.side_end - row.side_begin) / dim_;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (int v = 0; v < vectors; ++v) {
      const int first = row.side_begin + v * dim_;
      Eigen::Vector3d x = Eigen::Vector3d::Zero(), g = Eigen::Vector3d::Zero();
      x.head(dim_) = q.segment(first, dim_);
      for (int k = row.coord_begin; k < row.coord_end; ++k) {
        const int c = row_coord_[k];
        if (c >= first && c < first + dim_) g(c - first) = grad[k - row.coord_begin];
      }
      moment += x.cross(g);
    }
    (*moments)[row.joint] -= lambda(i) * moment;
  }
}

}  // namespace cablesim
