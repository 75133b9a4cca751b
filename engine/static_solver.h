#ifndef CABLESIM_ENGINE_STATIC_SOLVER_H_
#define CABLESIM_ENGINE_STATIC_SOLVER_H_

// Static equilibrium under gravity and loads (analysis STATIC):
//
//   Q_k(z) - alpha Q_a(z) + Phi_z^T lambda = 0,   Phi(z) = 0,
//
// for load factors alpha = 1/N, 2/N, ..., 1 (N = solver.load_steps), each by
// Newton from the previous equilibrium on the saddle-point system
// [K_T + H_lambda, Phi_z^T; Phi_z, 0] (SaddlePointSolver). An increment that
// does not converge is bisected, at most solver.max_step_halvings times.
// A mechanism (a scene with a free rigid motion, whose K_T is singular) has
// no unique equilibrium path from its start and is reported as a failure.

#include <string>

#include <Eigen/Core>

#include "engine/multibody_model.h"
#include "engine/saddle_point_solver.h"
#include "engine/scene.h"

namespace cablesim {

class StaticSolver {
 public:
  struct IncrementStats {
    bool converged = false;
    int newton_iterations = 0;
    int linear_iterations = 0;
    double residual = 0;
    double max_linear_residual = 0;
    std::string reason;
  };

  StaticSolver(MultibodyModel* model, const SolverSettings& settings);

  // Moves the equilibrium to load factor `alpha`, or leaves it unchanged and
  // returns !converged.
  IncrementStats Solve(double alpha);

  const Eigen::VectorXd& z() const { return z_; }

 private:
  MultibodyModel* model_;
  SolverSettings settings_;
  SaddlePointSolver solver_;
  int n_ = 0, m_ = 0;
  Eigen::VectorXd z_, lambda_, z1_, lambda1_, q_, f_, phi_, rhs_, dx_, bt_l_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_STATIC_SOLVER_H_
