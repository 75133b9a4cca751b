#ifndef CABLESIM_ENGINE_MULTIBODY_MODEL_H_
#define CABLESIM_ENGINE_MULTIBODY_MODEL_H_

// The planar multibody model of a scene: ANCF cable elements (8 coordinates
// each, MODEL.md sections 1-3), rigid bodies (x, y, theta) (section 6),
// joints, gravity and constant loads (section 4).
//
// Coordinates. The full coordinate vector q holds, cable by cable and node
// by node, [x, y, x', y'] (position [m] and slope [-]), then [x, y, theta]
// ([m], [m], [rad]) per body. Coordinates that a joint to ground fixes are
// removed: q = c + S z, where z are the unknowns (dofs) and each full
// coordinate is either a constant or a multiple of one unknown. A pinned node
// loses its position; a clamped (FIXED to ground) node also keeps its slope
// along its initial direction d0, r_x = alpha d0 with alpha unknown (the
// cable may still stretch there); a body welded to ground loses all three.
// Every other joint is a constraint Phi(q) = 0 with a Lagrange multiplier.
//
// The unknowns are ordered along each cable, and a body's right after the
// first cable node it is joined to, so the Newton matrix on z is banded
// (see SkylineLdlt).
//
// All vectors of size dofs() are "reduced"; of size coordinates() "full".

#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "engine/ancf_cable_element.h"
#include "engine/scene.h"
#include "engine/simulation.h"
#include "engine/skyline_ldlt.h"
#include "engine/sparse_rows.h"

namespace cablesim {

class MultibodyModel {
 public:
  using Element = AncfCableElement<2>;

  // Builds the mesh (a node wherever a joint, load or probe sits), the
  // coordinate map, and the constraint pattern. InvalidArgument names the
  // scene field when the scene cannot be assembled (for example joint sides
  // that do not coincide at t = 0).
  static absl::StatusOr<MultibodyModel> Build(const Scene& scene);

  int coordinates() const { return static_cast<int>(c_.size()); }
  int dofs() const { return dofs_; }
  int multipliers() const { return static_cast<int>(rows_.size()); }
  int elements() const { return static_cast<int>(elements_.size()); }
  int nodes() const { return num_nodes_; }
  ModelInfo Info() const;

  // Initial unknowns and their rates (the scene's rigid initial motion).
  const Eigen::VectorXd& initial_z() const { return z0_; }
  const Eigen::VectorXd& initial_v() const { return v0_; }

  // q = c + S z, and qdot = S zdot.
  void ToFull(const Eigen::VectorXd& z, Eigen::VectorXd* q) const;
  void RateToFull(const Eigen::VectorXd& zdot, Eigen::VectorXd* qdot) const;

  // The skyline envelope of the Newton matrix on z (mass, stiffness and
  // constraint Hessians all fit in it).
  const std::vector<int>& envelope() const { return envelope_; }

  // The constant reduced mass matrix S^T M S, in the layout of envelope().
  const SkylineLdlt& mass() const { return mass_; }

  // f = load_factor * Q_a(q) - Q_k(q) on the unknowns: gravity and applied
  // loads (scaled) minus elastic forces. `q` is the full configuration.
  // When `stiffness` is not null, also adds stiffness_scale * d(-f)/dz (the
  // tangent stiffness K_T, with the configuration-dependent body loads) to
  // it; its pattern is envelope(). One pass over the elements does both.
  // Returns the size of the terms that were added, max(|Q_a|_inf, |Q_k|_inf)
  // over the full coordinates: the scale against which Newton residuals are
  // small (the two nearly cancel at equilibrium).
  double NetForce(const Eigen::VectorXd& q, double load_factor, Eigen::VectorXd* f,
                  SkylineLdlt* stiffness = nullptr, double stiffness_scale = 0);

  // The level below which force residuals are rounding error: 100 machine
  // epsilons of the stiffest element's EA or EI / l^2 [N]. Newton cannot
  // drive a residual below it, so it is added to the convergence threshold.
  double force_roundoff() const { return force_roundoff_; }

  // Constraint values Phi(q) [multipliers()] and Jacobian dPhi/dz.
  void Constraints(const Eigen::VectorXd& q, Eigen::VectorXd* phi, SparseRows* jac) const;
  // An empty Jacobian with the constraint pattern (values to be filled).
  const SparseRows& jacobian_pattern() const { return jac_pattern_; }

  // Adds scale * sum_i lambda_i d^2 Phi_i / dz^2 to `a`.
  void AddConstraintHessian(const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                            double scale, SkylineLdlt* a) const;

  // gamma_i = -qdot^T (d^2 Phi_i / dq^2) qdot, the right-hand side of the
  // acceleration-level constraints (eq. 30 without time dependence).
  void ConstraintGamma(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                       Eigen::VectorXd* gamma) const;

  // Energy of a full state; potential includes the constant loads.
  EnergySample Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                      double load_factor) const;

  // Probes from full position, velocity and acceleration.
  void Probes(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
              const Eigen::VectorXd& qddot, std::vector<ProbeSample>* out) const;

  // Which joint a constraint row belongs to (for messages).
  int RowJoint(int row) const { return rows_[row].joint; }

 private:
  struct ElementData {
    Element element;
    int first_coord = 0;     // full index of its first node's x
    double mass_per_length = 0;
    Eigen::Matrix<double, 8, 1> gravity;
  };
  struct BodyData {
    int coord = 0;  // full index of x
    double mass = 0;
    double inertia = 0;
  };
  // A point or a direction on one side of a joint.
  struct Side {
    enum Kind { kGround, kNode, kBody } kind = kGround;
    int coord = 0;                              // node's x or body's x (full)
    Eigen::Vector2d local = Eigen::Vector2d::Zero();  // body point (body frame)
    Eigen::Vector2d ground = Eigen::Vector2d::Zero(); // ground point or direction
  };
  struct Row {
    enum Kind { kPositionX, kPositionY, kParallel } kind = kPositionX;
    int joint = 0;
    Side a, b;
  };
  // Evaluation of one side: value, derivatives with respect to up to three
  // full coordinates, and the second derivative along theta (bodies).
  struct SideEval {
    int n = 0;
    int idx[3] = {0, 0, 0};
    Eigen::Vector2d value = Eigen::Vector2d::Zero();
    Eigen::Matrix<double, 2, 3> jac = Eigen::Matrix<double, 2, 3>::Zero();
    int theta = -1;  // local index of theta, or -1
    Eigen::Vector2d second = Eigen::Vector2d::Zero();
  };
  struct RowEval {
    int n = 0;
    int idx[6] = {};
    double value = 0;
    Eigen::Matrix<double, 6, 1> grad = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Matrix<double, 6, 6> hess = Eigen::Matrix<double, 6, 6>::Zero();
  };
  struct BodyLoad {
    int body = 0;
    Eigen::Vector2d local = Eigen::Vector2d::Zero();
    Eigen::Vector2d force = Eigen::Vector2d::Zero();
    double torque = 0;
  };
  struct ProbeData {
    bool body = false;
    int coord = 0;
    Eigen::Vector2d local = Eigen::Vector2d::Zero();
  };

  SideEval EvalPoint(const Side& s, const Eigen::VectorXd& q) const;
  SideEval EvalDirection(const Side& s, const Eigen::VectorXd& q) const;
  RowEval EvalRow(const Row& row, const Eigen::VectorXd& q) const;

  // Coordinate map: q_i = c_i + s_i z_{j_i} (j_i = -1: constant).
  Eigen::VectorXd c_, s_;
  std::vector<int> j_;
  int dofs_ = 0;
  int num_nodes_ = 0;
  Eigen::VectorXd z0_, v0_;

  std::vector<ElementData> elements_;
  std::vector<BodyData> bodies_;
  std::vector<Row> rows_;
  std::vector<BodyLoad> body_loads_;
  std::vector<ProbeData> probes_;
  std::vector<std::string> probe_names_;
  Eigen::VectorXd constant_force_;  // full: gravity and node loads
  Eigen::Vector2d gravity_ = Eigen::Vector2d::Zero();
  double force_roundoff_ = 0;

  std::vector<int> envelope_;
  SkylineLdlt mass_;
  // Per element, the 64 skyline slots (or -1) and factors s_a s_b.
  std::vector<int> element_slots_;
  std::vector<double> element_factors_;
  SparseRows jac_pattern_;
  // Scratch (full size) for NetForce.
  Eigen::VectorXd scratch_full_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_MULTIBODY_MODEL_H_
