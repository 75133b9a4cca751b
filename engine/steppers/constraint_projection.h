#ifndef CABLESIM_ENGINE_STEPPERS_CONSTRAINT_PROJECTION_H_
#define CABLESIM_ENGINE_STEPPERS_CONSTRAINT_PROJECTION_H_

// The constraint rows of an explicit step (CENTRAL_DIFFERENCE's RATTLE form,
// central_difference_stepper.h): the three solves with the small matrix
// S = G M^-1 G^T, G = dPhi/dz the constraint Jacobian at one configuration,
// M the constant reduced mass (factored once by ExplicitAcceleration):
//
//  - ProjectPositions: z1 = z_pred - W x with W = M^-1 G_n^T (G at the
//    step's start) and x such that Phi(z1, t1) = 0, by simplified Newton
//    (S_n x_k = Phi(z_k)); the velocity that moved z there, v_half, takes
//    the same correction over h. This is RATTLE's position step (Andersen,
//    J. Comput. Phys. 52:24-34, 1983) with x = (h^2 / 2) lambda_pos.
//  - ProjectVelocity: v1 -= W y, S y = G v1 + Phi_t, so that
//    G v1 + Phi_t = 0 (RATTLE's velocity step, the multiplier mu = 2 y / h).
//  - ConsistentAcceleration: from a_free = M^-1 f, a = a_free - W lambda
//    with S lambda = G a_free - gamma: the solution of
//    [M G^T; G 0][a; lambda] = [f; gamma], the multipliers the implicit
//    steppers report (M a + G^T lambda = f, support reactions and joint
//    forces are read from them).
//
// Rebuild(q) recomputes G and S at a configuration, and the dense LDL^T of S
// (m x m, m the rows: a handful for a body and its joints). S is built as
// Y^T D^-1 Y with Y = L^-1 G^T (M = L D L^T, the skyline factor): a row's
// forward substitution starts at its first coordinate, and the rows of
// bodies and of a cable's end sit late in the ordering, so S costs far less
// than m full solves; W x is applied as M^-1 (G^T x), one solve each time
// (2 to 4 a step). Redundant rows make S singular; Eigen's LDLT with
// pivoting solves it in the least-squares sense (zero pivots skipped).
// Nothing here allocates after construction.

#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "engine/linear/skyline_ldlt.h"
#include "engine/linear/sparse_rows.h"
#include "engine/model/multibody_model.h"

namespace cablesim {

class ConstraintProjection {
 public:
  // `mass`: the factored reduced mass matrix, kept by the caller.
  ConstraintProjection(MultibodyModel* model, const SkylineLdlt* mass);

  int rows() const { return m_; }

  // G, W and S's factor at reduced positions z (time as set on the model).
  // False when S has a non-finite entry.
  bool Rebuild(const Eigen::VectorXd& z);

  // The position step: corrects z1 (and v_half by the same over h) along
  // W (built at the step's start) until |Phi(z1)|_inf <= kTolerance (1 +
  // |z1|_inf) at the model's time, or <= 1e3 kTolerance (1 + |z1|_inf)
  // once an iteration no longer halves it (rounding). False with `reason` when simplified
  // Newton does not get there in kMaxIterations.
  bool ProjectPositions(double h, Eigen::VectorXd* z1, Eigen::VectorXd* v_half,
                        std::string* reason);

  // The velocity step at the configuration of the last Rebuild.
  void ProjectVelocity(Eigen::VectorXd* v);

  // a (holding M^-1 f on entry) becomes the constrained acceleration and
  // lambda the multipliers, at the last Rebuild's configuration with rates v.
  void ConsistentAcceleration(const Eigen::VectorXd& v, Eigen::VectorXd* a,
                              Eigen::VectorXd* lambda);

  // The largest |Phi| after the last ProjectPositions (the drift it left).
  double last_residual() const { return last_residual_; }

  // Relative tolerance on the rows after a position step: a few hundred
  // roundings of coordinates of size 1 + |z|_inf.
  static constexpr double kTolerance = 1e-13;
  static constexpr int kMaxIterations = 12;

 private:
  // dz = W x = M^-1 G^T x (the Jacobian of the last Rebuild).
  void ApplyW(const Eigen::VectorXd& x);

  MultibodyModel* model_;
  const SkylineLdlt* mass_;
  int n_ = 0, m_ = 0;
  SparseRows jac_;
  std::vector<int> from_;  // each row's first coordinate
  Eigen::MatrixXd y_, s_;  // Y = L^-1 G^T (zero above from_), S
  Eigen::LDLT<Eigen::MatrixXd> s_ldlt_;
  Eigen::VectorXd q_, qd_, phi_, x_, gamma_, dz_;
  double last_residual_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STEPPERS_CONSTRAINT_PROJECTION_H_
