#ifndef CABLESIM_ENGINE_ANALYSIS_STATIC_SOLVER_H_
#define CABLESIM_ENGINE_ANALYSIS_STATIC_SOLVER_H_

// Static equilibrium under gravity and loads (analysis STATIC, the
// equilibrium MODAL linearises about, and solver.initial_state STATIC):
//
//   Q_k(z) - alpha Q_a(z) + Phi_z^T lambda = 0,   Phi(z) = 0,
//
// at a load factor alpha, by Newton on the saddle-point system
// [K_T + H_lambda + sigma M, Phi_z^T; Phi_z, 0] (SaddlePointSolver), where
// sigma >= 0 [1/s^2] is a pseudo-transient shift (pseudo-transient
// continuation: Kelley and Keyes, SIAM J. Numer. Anal. 35:508-523, 1998;
// for cables it is dynamic relaxation with the mass matrix).
//
// Why a shift: a pure cable (bending NONE, or a negligible EI) started slack
// has no transverse stiffness (K_T is singular), and one started compressed
// has a negative one; plain Newton then fails at the first iteration. Each
// shifted step is one backward-Euler step of size 1/sqrt(sigma) of the
// cable released from rest, which always exists and moves towards
// equilibrium. sigma starts at 0 (plain Newton, quadratic near an
// equilibrium) and is switched on, at a size that moves the scene by
// kFirstMove of its size in one step, when Newton's matrix is not positive
// definite, its step is larger than kMaxMove of the scene, or the residual
// grew tenfold (that step is taken back). Then sigma follows the residual
// (switched evolution relaxation: sigma_k+1 = sigma_k |r_k+1| / |r_k|), so
// it vanishes as the residual does and the last iterations are Newton's.
//
// Two refinements for pure cables started compressed (laid straight on a
// chord shorter than the cable): a matrix with negative pivots first gives
// the modified Newton step of L |D| L^T (the pivots' signs flipped), which
// descends along the negative curvature without amplifying the short
// wavelengths, so the cable leaves the unstable straight branch in a long
// sag rather than crumpled; and a full step that lowers the merit is
// doubled while the merit keeps falling, since a slack cable's Newton steps
// are short and alike.
//
// Seabed friction (MultibodyModel::StaticFriction) opposes the
// displacement from the configuration the solver was built at (the scene's
// layout): its force joins the residual, its symmetric matrix the Newton
// matrix, and its work from the iterate (trapezoidal rule) the merit.
//
// Convergence is newton_convergence.h's test (per-entry rounding floor).
// A scene with no equilibrium (a mechanism: a body or cable that the joints
// do not hold against the loads) never converges: the solve stops after
// kMaxIterations (kLayoutIterations for the first try from the layout) or
// when the scene has moved kMaxTravel times its size, and
// says that it found no equilibrium.

#include <functional>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "engine/model/multibody_model.h"
#include "engine/linear/saddle_point_solver.h"
#include "engine/scene/scene.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"

namespace cablesim {

class StaticSolver {
 public:
  struct IncrementStats {
    bool converged = false;
    int newton_iterations = 0;
    int linear_iterations = 0;
    double residual = 0;        // relative residual accepted
    double residual_floor = 0;  // its rounding floor, relative
    double max_linear_residual = 0;
    bool stopped = false;  // the stop request of set_should_stop (then !converged)
    std::string reason;
  };

  // Largest Newton iterations of one load increment; the first increment
  // tried from the scene's layout gets kLayoutIterations. Why more: the
  // layout is not an equilibrium at any load factor (a line laid on a
  // polyline kinks at its corners, stretched 0.1 % to have stiffness
  // across), and relaxing it is the first increment's work whatever its
  // size: bisecting the load does not shorten it but weakens the loads
  // that give the lines their stiffness. MoorDyn's seafloor.txt (a neutrally
  // buoyant line of EA 1e9 N laid with a corner from its fixed point to a
  // 10 kg point) relaxes in 1,228 iterations, and failed after 500 at
  // each of 12 bisections. Only the first try: its bisections, and every
  // later increment (from an equilibrium), keep kMaxIterations.
  static constexpr int kMaxIterations = 500;
  static constexpr int kLayoutIterations = 8 * kMaxIterations;
  // First pseudo-transient step, and largest plain Newton step, as
  // fractions of the scene size 1 + |z|_inf.
  static constexpr double kFirstMove = 0.05;
  static constexpr double kMaxMove = 0.25;
  // Travel [scene sizes] beyond which the scene is taken to have no
  // equilibrium.
  static constexpr double kMaxTravel = 100;
  // Halvings of a step's length before the shift is raised instead.
  static constexpr int kLineSearchHalvings = 6;

  StaticSolver(MultibodyModel* model, const SolverSettings& settings);

  // Moves the equilibrium to load factor `alpha`, or leaves it unchanged and
  // returns !converged. `tolerance` overrides settings.newton_tolerance when
  // positive.
  IncrementStats Solve(double alpha, double tolerance = 0);

  const Eigen::VectorXd& z() const { return z_; }
  const Eigen::VectorXd& lambda() const { return lambda_; }

  // Asked before every Newton iteration of Solve (one increment may take
  // hundreds): true ends the increment, not converged and `stopped`.
  void set_should_stop(std::function<bool()> should_stop) {
    should_stop_ = std::move(should_stop);
  }

 private:
  // The pseudo-transient shift that moves the scene by kFirstMove of its
  // size in one step under the residual r.
  double FirstShift(const Eigen::VectorXd& r, double zscale);
  // The merit of a trial state: its potential energy (strain, gravity,
  // loads) plus lambda . Phi + gamma / 2 |Phi|^2; sets merit_size_ to the
  // size of the energy terms (for the rounding of a comparison).
  double Merit(const Eigen::VectorXd& z, const Eigen::VectorXd& lambda, double alpha,
               double gamma);

  MultibodyModel* model_;
  SolverSettings settings_;
  SaddlePointSolver solver_;
  SkylineLdlt mass_factor_;  // M, factored on first use
  bool mass_factored_ = false;
  int n_ = 0, m_ = 0;
  Eigen::VectorXd z_, lambda_, z1_, lambda1_, q_, f_, phi_, rhs_, dx_, bt_l_, floor_, work_;
  Eigen::VectorXd trial_z_, trial_lambda_, qdot_zero_;
  // Full coordinates where the analysis started, for the seabed's static
  // friction (MultibodyModel::StaticFriction); empty without it.
  Eigen::VectorXd q_start_;
  Eigen::VectorXd friction_;  // its force at the iterate z1_
  double merit_size_ = 0;
  // Whether Solve has been called (the first call starts from the layout).
  bool solved_once_ = false;
  std::function<bool()> should_stop_;
};

// Follows the load path 0 -> 1 in settings.load_steps increments (each one
// bisected on failure, at most settings.max_step_halvings times), counting
// steps, iterations and residuals in `summary`. After every accepted
// increment calls on_increment(z_before, z_after, alpha) when set; at every
// target k / load_steps calls on_target(alpha), whose false stops the path
// (the caller has filled in the summary). Returns false when the path
// stopped: the caller's stop request or step limit, on_target, or an
// increment that failed (the summary then says "failed", prefixed by
// `what`, e.g. "MODAL: ").
bool FollowLoadPath(
    StaticSolver* solver, const SolverSettings& settings, const RunControl& control,
    RunSummary* summary, const std::string& what,
    const std::function<void(const Eigen::VectorXd&, const Eigen::VectorXd&, double)>&
        on_increment,
    const std::function<bool(double)>& on_target);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ANALYSIS_STATIC_SOLVER_H_
