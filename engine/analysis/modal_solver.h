#ifndef CABLESIM_ENGINE_ANALYSIS_MODAL_SOLVER_H_
#define CABLESIM_ENGINE_ANALYSIS_MODAL_SOLVER_H_

// MODAL analysis: natural frequencies and mode shapes of small vibrations
// about a static equilibrium z* (docs/model.md section 3, linearised).
//
// Linearising M z'' - f(z) + Phi_z^T lambda = 0, Phi(z) = 0 about z* (where
// f(z*) = Phi_z^T lambda*) gives the constrained generalized symmetric
// eigenproblem
//
//   (K_T + H_lambda*) x = omega^2 M x,   Phi_z x = 0,
//
// K_T = -df/dz the tangent stiffness (geometric stiffness of the tension
// included), H_lambda* = sum_i lambda*_i d^2 Phi_i / dz^2 the constraint
// Hessian, M the constant mass matrix, omega [rad/s]. With Z an orthonormal
// basis of the null space of Phi_z (from a column-pivoted QR of Phi_z^T) it
// becomes (Z^T K Z) y = omega^2 (Z^T M Z) y, x = Z y, solved densely by
// Eigen's GeneralizedSelfAdjointEigenSolver (Cholesky of Z^T M Z, then a
// symmetric tridiagonal QR): every eigenvalue, repeated ones included, to
// rounding. Its cost is O(n^3) in the unknowns n, so above kDenseDofs
// unknowns the lowest modes come instead from shift-invert Lanczos (Spectra's
// SymGEigsShiftSolver in the M-inner product) on the operator
// y = Z (Z^T (K - sigma M) Z)^{-1} Z^T M x, applied through the KKT system
// with K - sigma M in the banded SkylineLdlt and the dense Schur complement
// of the constraint rows (so at most kMaxLanczosMultipliers of them); a
// Sturm count (Sylvester's inertia of the KKT matrix) checks that no
// eigenvalue below the highest one found was missed (a repeated one), and
// more are asked for when one was. README, "Modal analysis", gives measured
// times.
//
// lambda* is recovered from the equilibrium itself, as the least-squares
// solution of Phi_z^T lambda = f(z*) (exact at an equilibrium), so any
// static solver may provide z*.

#include <string>

#include <Eigen/Core>

#include "absl/status/status.h"
#include <functional>

#include "absl/status/statusor.h"
#include "engine/model/multibody_model.h"
#include "engine/scene/scene.h"
#include "engine/output/results.h"
#include "engine/scene/run_control.h"

namespace cablesim {

class ModalSolver {
 public:
  // Up to this many unknowns (dofs) the dense solver is used: the O(n^3)
  // solve measured 1.4 s at 1001 and 21 s at 2001 unknowns.
  static constexpr int kDenseDofs = 600;
  // The Lanczos path keeps the constraint Jacobian dense (with the Schur
  // complement): this bounds its rows (200 x 40,000 unknowns: 64 MB).
  static constexpr int kMaxLanczosMultipliers = 200;

  enum class Method { kAuto, kDense, kLanczos };

  struct Result {
    bool ok = false;
    std::string reason;  // when !ok
    // omega^2 [1/s^2], ascending, and the matching shapes on the unknowns
    // (dofs x modes), M-orthonormal (x^T M x = 1).
    Eigen::VectorXd omega2;
    Eigen::MatrixXd shapes;
    int free_dofs = 0;  // dofs minus the rank of the constraint Jacobian
    bool stopped = false;  // `should_stop` returned true (then !ok)
  };

  // The number of modes a MODAL run of `settings` computes on `model`
  // (settings.modes, or the default), or InvalidArgument naming
  // solver.modes (more modes than degrees of freedom) or solver.analysis
  // (a large scene with too many constraint equations).
  static absl::StatusOr<int> ModeCount(const MultibodyModel& model,
                                       const SolverSettings& settings);

  // The `modes` lowest modes about the equilibrium `z_eq` of `model` under
  // its full loads. kAuto: dense up to kDenseDofs unknowns, else Lanczos.
  // `should_stop` (empty: never) is checked at every operator application
  // of the Lanczos iteration, so a caller's stop request ends it within
  // one linear solve, and before and after the dense solve (at most
  // kDenseDofs unknowns).
  static Result Solve(MultibodyModel* model, const Eigen::VectorXd& z_eq, int modes,
                      Method method = Method::kAuto,
                      const std::function<bool()>& should_stop = {});
};

// Runs a MODAL analysis: finds the equilibrium (load increments of the
// STATIC analysis unless the initial configuration already is one), solves
// the modes and delivers frames to `sink`: frame 0 (t = 0) is the
// equilibrium, frame k (t = k) mode k, whose probe positions are the mode
// shape at the probes (scaled so that the largest probe displacement
// component is +1 m), velocities, accelerations and energies 0, and
// constraint_violation |Phi_z x|_inf of the shape. Fills
// summary->frequencies_hz (omega / 2 pi, ascending; negative, -sqrt(-omega^2)
// / 2 pi, for a mode whose omega^2 < 0: an unstable equilibrium, or a rigid
// mode at rounding level). `modes` comes from ModalSolver::ModeCount.
void RunModalAnalysis(MultibodyModel* model, const SolverSettings& settings, int modes,
                      const RunControl& control, FrameSink* sink, RunSummary* summary);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ANALYSIS_MODAL_SOLVER_H_
