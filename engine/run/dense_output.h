#ifndef CABLESIM_ENGINE_RUN_DENSE_OUTPUT_H_
#define CABLESIM_ENGINE_RUN_DENSE_OUTPUT_H_

// Frames between step ends (dense output), so that asking for frames never
// changes the steps. Over a step from (z0, v0, a0, lambda0) to (z1, v1, a1,
// lambda1) of length d, at theta = (t - t0) / d in [0, 1]:
//   z(theta) = h00 z0 + d h10 v0 + h01 z1 + d h11 v1      (cubic Hermite)
//   v(theta) = dz/dt, its derivative
//   a(theta) = (1 - theta) a0 + theta a1, lambda likewise (linear),
// with h00 = 2 th^3 - 3 th^2 + 1, h10 = th^3 - 2 th^2 + th,
// h01 = -2 th^3 + 3 th^2, h11 = th^3 - th^2. The interpolant's position
// error is O(d^4), below the second-order steppers' O(d^2) (and it caps the
// fifth-order Dormand-Prince's frames at fourth order:
// IntegratorTraits::frame_order). Allocation-free once sized.

#include <Eigen/Core>

#include "engine/steppers/stepper.h"

namespace cablesim {

class DenseOutput {
 public:
  // Sizes the buffers and takes the stepper's state as a step's start.
  explicit DenseOutput(const Stepper& s)
      : z0_(s.z()), v0_(s.v()), a0_(s.a()), lambda0_(s.lambda()), z_(s.z().size()),
        v_(s.v().size()), a_(s.a().size()), lambda_(s.lambda().size()) {}

  // The stepper's current state is the start of the next step.
  void BeginStep(const Stepper& s) {
    z0_ = s.z();
    v0_ = s.v();
    a0_ = s.a();
    lambda0_ = s.lambda();
  }

  // The state at theta of a step of length d [s] that ended at s's state.
  void Interpolate(double th, double d, const Stepper& s) {
    const double th2 = th * th, th3 = th2 * th;
    const double h00 = 2 * th3 - 3 * th2 + 1, h10 = th3 - 2 * th2 + th, h01 = -2 * th3 + 3 * th2,
                 h11 = th3 - th2;
    const double d00 = 6 * th2 - 6 * th, d10 = 3 * th2 - 4 * th + 1, d01 = -d00,
                 d11 = 3 * th2 - 2 * th;
    z_ = h00 * z0_ + (h10 * d) * v0_ + h01 * s.z() + (h11 * d) * s.v();
    v_ = (d00 / d) * z0_ + d10 * v0_ + (d01 / d) * s.z() + d11 * s.v();
    a_ = (1 - th) * a0_ + th * s.a();
    lambda_ = (1 - th) * lambda0_ + th * s.lambda();
  }

  const Eigen::VectorXd& z() const { return z_; }
  const Eigen::VectorXd& v() const { return v_; }
  const Eigen::VectorXd& a() const { return a_; }
  const Eigen::VectorXd& lambda() const { return lambda_; }

 private:
  Eigen::VectorXd z0_, v0_, a0_, lambda0_;  // the step's start
  Eigen::VectorXd z_, v_, a_, lambda_;      // the interpolated state
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_RUN_DENSE_OUTPUT_H_
