#ifndef CABLESIM_ENGINE_FORCES_SLIDING_JOINT_H_
#define CABLESIM_ENGINE_FORCES_SLIDING_JOINT_H_

// A body point x kept on a cable but free to slide along it (a bead, a
// trolley, a ring), planar or spatial, frictionless or with Coulomb
// friction.
//
// Formulation: a penalty on the distance to the nearest cable point. Let
// r(s) be the cable's ANCF interpolation (MODEL.md section 1) at arc
// length s of the undeformed cable, on the element that contains s, and
//   s*(q) = argmin_s |r(s) - x|^2 / 2      (the slider's material place),
//   d = r(s*) - x,   V = (k / 2) |d|^2      [J], k the stiffness [N/m].
// Because s* minimizes, dV/ds = 0 there and the generalized force is
// -dV/dq = -k G^T d with G = [N_a(s*) I ... | -P] (the Hermite shape
// functions on the element's 4 D coordinates, then minus the map x = P q_b
// from the body's natural coordinates): a force along d only, normal to
// the cable (r'(s*) . d = 0), so the slider slides freely. Its tangent
// stiffness is the Schur complement of the minimization,
//   H = k G^T G - g g^T / f_ss,  g = k (G_s^T d + G^T r'),
//   f_ss = k (r'.r' + r''.d),
// (G_s = dG/ds) which removes the stiffness along the cable.
// s* is found by Newton on s from the last value (a warm start only),
// switching element when s passes a node. r and r' are continuous across a
// node (shared node coordinates), so s* and the force move continuously:
// no jolt. (A split C0 node of a bending-free cable, ModelBuilder::
// MeshCables, has a kink: the slider jumps there; not meshed for sliders.)
// At the cable's ends s* is clamped to [0, L]: the end holds the slider.
//
// Why a penalty, not an extra unknown s with rows r(s) - x = 0: the rows
// would be cubic in s and their coordinate set would change whenever s
// crosses a node, while every constraint of the model is a QuadraticForm
// row with a fixed pattern (multibody_model.h); the penalty is a force
// like the elastic ones and needs no new unknown, no new multiplier, and no
// change to the steppers, statics or modal analysis. The cost: the slider
// sits d = F_n / k off the cable (the normal force over k: default k =
// EA / l_e, the axial stiffness of one element, so the gap is the
// stretch of one element under the same load), and a normal mode of
// frequency sqrt(k / m) that the implicit steppers damp; per evaluation,
// a few Newton steps on s (one element lookup each) and a (4D + B)^2
// scatter into the Newton matrix. The Newton matrix gains the coupling of
// the body's unknowns with the whole cable (a bordered band when the body
// is ordered last, which OrderUnknowns does for a body without other
// joints).
//
// Friction: the regularized Coulomb force on the slider
//   F = -mu |k d| tanh(v_t / v_s) t,  t = r'/|r'|,  v_t = t . (xdot - rdot(s*))
// (the cable's material point under the slider feels -F), v_s the stick
// velocity [m/s]: sliding faster than a few v_s sees the full mu N. Its
// velocity derivative mu N tanh'(v_t / v_s) / v_s w w^T (w the map from
// local rates to v_t) is symmetric positive semi-definite; the derivative
// in q is left out (as for damping, MultibodyModel::DampingForce). It
// dissipates mu N tanh(v_t / v_s) v_t >= 0 [W].

#include <array>
#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "engine/forces/force_contributor.h"
#include "engine/scene/scene.h"

namespace cablesim {

class SlidingJoint {
 public:
  // The cable's elements in order: full index of the element's first
  // coordinate, arc length where it starts [m], and its length [m].
  struct Segment {
    int first_coord = 0;
    double s0 = 0;
    double length = 0;
  };
  static constexpr int kMaxLocal = 24;  // 4 D + body stride, spatial
  // Local terms over the coordinates the slider touches now: the element
  // under it, then the body.
  struct Local {
    int n = 0;
    std::array<int, kMaxLocal> coord{};
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxLocal, 1> force;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxLocal, kMaxLocal> matrix;
    // A bound on the rounding of each force entry [N]: d = r - x is known
    // only to eps (|r| + |x|) per component, amplified by k (and s* only to
    // its last bits, which moves r by |r'| eps L).
    double rounding = 0;
  };

  // dim 2 or 3; body_coord the body's first full coordinate, body_stride
  // 4 or 12; point on the body in body axes [m]; stiffness k [N/m];
  // friction mu [-]; stick_velocity v_s [m/s]; s_start the slider's arc
  // length at t = 0 [m].
  SlidingJoint(int dim, std::vector<Segment> segments, int body_coord, int body_stride,
               const Eigen::Vector3d& point, double stiffness, double friction,
               double stick_velocity, double s_start);

  bool has_friction() const { return friction_ > 0; }
  double stiffness() const { return stiffness_; }
  // The arc length [m] where the slider was last found (Locate).
  double s() const { return s_; }

  // Finds s*(q) (updates the warm start; a cache, hence const).
  void Locate(const Eigen::VectorXd& q) const;

  // At s*(q): the penalty energy V [J]; `out` (if not null) receives the
  // force -dV/dq on out->coord and, when `tangent`, the stiffness H.
  double Penalty(const Eigen::VectorXd& q, Local* out, bool tangent) const;

  // At s*(q): the friction force on out->coord and, when `tangent`, its
  // velocity derivative -dQ/dqdot. Returns the dissipated power [W].
  double Friction(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Local* out,
                  bool tangent) const;

  // The distance |d| [m] from the slider's point to the cable.
  double Gap(const Eigen::VectorXd& q) const;

 private:
  // Hermite shape functions of the element under s and their first and
  // second derivatives in s; fills element_ (the segment index).
  struct Shape {
    int seg = 0;
    double n[4], n1[4], n2[4];
  };
  void ShapeAt(double s, Shape* sh) const;
  Eigen::Vector3d Interpolate(const Eigen::VectorXd& q, const Shape& sh,
                              const double* w) const;
  Eigen::Vector3d Point(const Eigen::VectorXd& q) const;
  // Fills out->coord, out->n and G (D x n) at the current s_.
  void Jacobian(const Shape& sh, Local* out,
                Eigen::Matrix<double, 3, kMaxLocal>* g) const;

  int dim_;
  std::vector<Segment> segments_;
  int body_coord_, body_stride_;
  Eigen::Matrix<double, 3, 12> p_ = Eigen::Matrix<double, 3, 12>::Zero();  // x = P q_b
  double stiffness_, friction_, stick_velocity_;
  double length_;
  mutable double s_;
  mutable int seg_ = 0;
};

// Every sliding joint of a scene as one ForceContributor: the penalty as
// the conservative part (its energy with the loads'), friction as the
// dissipative part.
class SlidingJoints : public ForceContributor {
 public:
  explicit SlidingJoints(std::vector<SlidingJoint> sliders) : sliders_(std::move(sliders)) {}

  int count() const { return static_cast<int>(sliders_.size()); }
  const SlidingJoint& slider(int i) const { return sliders_[i]; }

  std::string_view name() const override { return "sliding_joints"; }
  void AddConservative(const ForceState& s, ForceOutput* out) const override;
  void AddDissipative(const ForceState& s, ForceOutput* out) const override;
  double StoredEnergy(const ForceState& s) const override;
  void AddDissipatedPower(const ForceState& s, double* power) const override;
  bool dissipates() const override;

 private:
  std::vector<SlidingJoint> sliders_;
};

// Adds a slider's local terms (force, its rounding, scale times its
// matrix when out->matrix) to `out`, and raises out->size.
void AddLocalTerms(const SlidingJoint::Local& local, ForceOutput* out);

// The contributor for the scene's SLIDE joints, or null without any.
// `segments[c]`: cable c's elements in order; `body_coord[b]`: body b's
// first full coordinate; `q0` the full configuration at t = 0, where each
// body point must lie on its cable (InvalidArgument naming the joint).
absl::StatusOr<std::unique_ptr<SlidingJoints>> MakeSlidingJoints(
    const Scene& scene, const std::vector<std::vector<SlidingJoint::Segment>>& segments,
    const std::vector<int>& body_coord, int dim, int body_stride, const Eigen::VectorXd& q0);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_SLIDING_JOINT_H_
