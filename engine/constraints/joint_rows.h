#ifndef CABLESIM_ENGINE_CONSTRAINTS_JOINT_ROWS_H_
#define CABLESIM_ENGINE_CONSTRAINTS_JOINT_ROWS_H_

// Every joint's and body axis constraint's rows as one ConstraintFamily:
// flat quadratic forms over local coordinate lists (MuJoCo-like flat data,
// a fixed pattern),
//
//   phi = c + sum lin_value * q[coord[lin_local]] + sum w q[coord[a]] q[coord[b]],
//
// so the Jacobian is linear in q and the Hessians are constant. Built row
// by row (AddRow, ModelBuilder::KeepMovableRows), then laid onto the
// unknowns once the coordinate map is final (SetupPattern).

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/constraints/constraint.h"
#include "engine/constraints/quadratic_form.h"

namespace cablesim {

class JointRows : public ConstraintFamily {
 public:
  struct Row {
    int joint = -1;  // scene joint, or -1 for a body's own axis constraint
    int body = -1;   // the body of an axis constraint
    enum Kind { kPosition, kDirection, kSlope, kAxes } kind = kPosition;
    double c = 0;
    int coord_begin = 0, coord_end = 0;  // into row_coord_
    int lin_begin = 0, lin_end = 0;      // into lin_local_, lin_value_
    int mono_begin = 0, mono_end = 0;    // into mono_a_, mono_b_, mono_w_
    // For the joint's reaction (AddReactions): a position row's axis
    // (Phi = p_a - p_b along it, so the force on side a is -lambda e_axis),
    // or -1; a direction or slope row's full coordinates of side a's
    // direction vectors (D each: a cable node's slope, a body's axes),
    // [side_begin, side_end).
    int axis = -1;
    int side_begin = 0, side_end = 0;
  };
  // The widest row, two welded spatial bodies, touches 24 coordinates.
  static constexpr int kMaxRowCoords = 48;

  void AddRow(const QuadraticForm& f, Row::Kind kind, int joint, int body);
  // The last row's reaction data (Row::axis, side_begin, side_end) and the
  // dimension D of the coordinates' vectors.
  void SetReactionData(int axis, int side_begin, int side_end, int dim) {
    rows_.back().axis = axis;
    rows_.back().side_begin = side_begin;
    rows_.back().side_end = side_end;
    dim_ = dim;
  }
  int size() const { return static_cast<int>(rows_.size()); }
  const Row& row(int i) const { return rows_[i]; }
  // The full coordinates row `r` touches.
  const int* coords(const Row& r) const { return &row_coord_[r.coord_begin]; }
  int coord_count(const Row& r) const { return r.coord_end - r.coord_begin; }

  double Value(const Row& row, const Eigen::VectorXd& q) const;
  // Local gradient of a row: grad[k] for coordinate coords(row)[k].
  void Gradient(const Row& row, const Eigen::VectorXd& q, double* grad) const;

  // For PrescribedMotion: row i's constant, and its linear coefficients
  // n(coord - first) (every coordinate of x from `first` has a slot).
  void SetConstant(int i, double c) { rows_[i].c = c; }
  void SetLinear(int i, const Eigen::Vector3d& n, int first);

  // Once the map is final: the Jacobian's pattern on z (appended to
  // `jac`), and each monomial's Hessian slot on z and factor.
  void SetupPattern(const CoordinateMap& map, int dofs, SparseRows* jac);

  std::string_view name() const override { return "joint_rows"; }
  void Residual(const Eigen::VectorXd& q, const CoordinateMap& map, Eigen::VectorXd* phi,
                SparseRows* jac) const override;
  void AddHessian(const Eigen::VectorXd& lambda, double scale, SkylineLdlt* a) const override;
  // -qdot^T Phi_qq qdot (the Hessians are constant).
  void AddGamma(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                Eigen::VectorXd* gamma) const override;
  // Position rows: force -lambda e_axis on side a. Direction and slope
  // rows (FIXED): the couple of the virtual work -lambda dPhi/dx . (dtheta
  // x x) over side a's direction vectors x, moment -lambda sum x x dPhi/dx
  // (planar: its z component). Body axis rows (joint -1) are not joints'.
  void AddReactions(const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                    std::vector<Eigen::Vector3d>* forces,
                    std::vector<Eigen::Vector3d>* moments) const override;

 private:
  int dim_ = 3;
  std::vector<Row> rows_;
  std::vector<int> row_coord_;
  std::vector<int> lin_local_;
  std::vector<double> lin_value_;
  std::vector<int> mono_a_, mono_b_;
  std::vector<double> mono_w_;
  // Per monomial: the (row >= col) entry of its Hessian on z (or -1) and
  // its factor.
  std::vector<int> mono_row_, mono_col_;
  std::vector<double> mono_factor_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_CONSTRAINTS_JOINT_ROWS_H_
