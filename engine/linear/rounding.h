#ifndef CABLESIM_ENGINE_LINEAR_ROUNDING_H_
#define CABLESIM_ENGINE_LINEAR_ROUNDING_H_

// The rounding of floating-point sums, for the rounding floors that the
// forces, the constraint Jacobians and the residuals carry (see
// engine/steppers/newton_convergence.h for how Newton uses them).

namespace cablesim {

// Rounding of a sum, per term: a few machine epsilons of each term's size.
constexpr double kSumRounding = 4 * 2.220446049250313e-16;

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_ROUNDING_H_
