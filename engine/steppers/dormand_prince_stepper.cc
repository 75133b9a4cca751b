#include "engine/steppers/dormand_prince_stepper.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace cablesim {
namespace {

// Dormand and Prince (1980), the 5(4) pair: nodes c, the lower triangle a
// (row i holds a_i1 .. a_i,i-1), and e = b - bhat (b is the row a_7).
constexpr double kC[DormandPrinceStepper::kStages] = {0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1, 1};
constexpr double kA[DormandPrinceStepper::kStages][DormandPrinceStepper::kStages - 1] = {
    {},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
constexpr double kE[DormandPrinceStepper::kStages] = {
    71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525, -1.0 / 40};

}  // namespace

DormandPrinceStepper::DormandPrinceStepper(MultibodyModel* model,
                                           const SolverSettings& settings)
    : ExplicitStepper(model, settings) {
  for (int i = 0; i < kStages; ++i) {
    vs_[i].setZero(n_);
    as_[i].setZero(n_);
  }
  zs_.setZero(n_);
  err_z_.setZero(n_);
  err_v_.setZero(n_);
}

bool DormandPrinceStepper::Initialize(std::string* reason) {
  // |R(i omega h)| = 1.01 at omega h = 1.725 (R the stability polynomial,
  // dormand_prince_stepper.h): beyond, the stiffest undamped mode grows by
  // more than 1 % a step.
  if (!Start("DORMAND_PRINCE", 1.725,
             "1.725 / omega_max, where its stiffest undamped mode grows by 1 % a step",
             /*takes_rows=*/false, &omega_max_, reason))
    return false;
  stable_step_ = omega_max_ > 0 ? 0.99 / omega_max_ : stable_step_;
  return true;
}

Stepper::StepStats DormandPrinceStepper::Step(double h) {
  StepStats st;
  vs_[0] = v_;
  as_[0] = a_;  // first same as last
  for (int i = 1; i < kStages; ++i) {
    zs_ = z_;
    vs_[i] = v_;
    for (int j = 0; j < i; ++j) {
      const double w = h * kA[i][j];
      if (w == 0) continue;
      zs_ += w * vs_[j];
      vs_[i] += w * as_[j];
    }
    if (!acceleration_.Evaluate(t_ + kC[i] * h, zs_, vs_[i], &as_[i])) {
      st.reason = absl::StrFormat(
          "the acceleration at stage %d of the explicit step is not finite (h = %.3g s: likely "
          "beyond DORMAND_PRINCE's stability limit, 1 to 1.7 / omega_max for undamped modes)%s",
          i + 1, h, acceleration_.NotFiniteSource());
      model_->SetTime(t_);
      return st;
    }
  }
  err_z_.setZero();
  err_v_.setZero();
  for (int i = 0; i < kStages; ++i) {
    if (kE[i] == 0) continue;
    err_z_ += (h * kE[i]) * vs_[i];
    err_v_ += (h * h * kE[i]) * as_[i];  // h times the velocity's error: metres
  }
  // Stiffness estimate: stages 6 and 7 are both at t + h; y6 = (Z_6, V_6)
  // with Z_6 = zs_ - h sum_j (a_7j - a_6j) V_j, so y7 - y6 and f(y7) - f(y6)
  // come from the stages without storing Z_6.
  {
    double dz2 = 0, dv2 = 0, da2 = 0;
    for (int k = 0; k < n_; ++k) {
      double dz = 0;
      for (int j = 0; j < kStages - 1; ++j) dz += (kA[6][j] - kA[5][j]) * vs_[j](k);
      dz *= h;
      const double dv = vs_[6](k) - vs_[5](k), da = as_[6](k) - as_[5](k);
      dz2 += dz * dz;
      dv2 += dv * dv;
      da2 += da * da;
    }
    const double den = dz2 + dv2;
    const double rho = den > 0 ? std::sqrt((dv2 + da2) / den) : 0;
    if (++steps_ % 50 == 0) omega_max_ = acceleration_.StiffestFrequency(zs_, 20);
    const double stiffest = std::max(rho, omega_max_);
    stable_step_ = stiffest > 0 ? 0.99 / stiffest : std::numeric_limits<double>::infinity();
  }
  // The end is the last stage (Z_7: the row a_7 is b); its acceleration is
  // the next step's first stage.
  Accept(h, &zs_, &vs_[kStages - 1], &as_[kStages - 1]);
  st.converged = true;
  return st;
}

double DormandPrinceStepper::LocalErrorNorm(double /*h*/, double atol, double rtol) const {
  double worst = 0;
  for (int i = 0; i < n_; ++i)
    worst = std::max(worst, std::max(std::abs(err_z_(i)), std::abs(err_v_(i))) /
                                (atol + rtol * std::abs(z_(i))));
  return worst;
}

}  // namespace cablesim
