#include "engine/analysis/static_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/steppers/newton_convergence.h"

namespace cablesim {
namespace {
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
// Newton iterations of a load increment after which a matrix with
// negative pivots under constraint rows gets the flipped step rather than
// only the shift (see Solve).
constexpr int kShiftOnlyIterations = 100;
}  // namespace

StaticSolver::StaticSolver(MultibodyModel* model, const SolverSettings& settings)
    : model_(model), settings_(settings) {
  n_ = model->dofs();
  m_ = model->multipliers();
  solver_.Resize(model->envelope(), model->jacobian_pattern());
  z_ = model->initial_z();
  // Static friction opposes the displacement from here (where the scene
  // laid its cables and bodies).
  if (model->has_static_friction()) {
    q_start_.setZero(model->coordinates());
    model->ToFull(z_, &q_start_);
  }
  lambda_.setZero(m_);
  z1_.setZero(n_);
  lambda1_.setZero(m_);
  q_.setZero(model->coordinates());
  f_.setZero(n_);
  phi_.setZero(m_);
  rhs_.setZero(n_ + m_);
  dx_.setZero(n_ + m_);
  bt_l_.setZero(n_);
  floor_.setZero(n_);
  work_.setZero(n_);
  qdot_zero_.setZero(model->coordinates());
}

double StaticSolver::FirstShift(const Eigen::VectorXd& r, double zscale) {
  // sigma M dz = r moves the scene by |M^-1 r|_inf / sigma.
  if (!mass_factored_) {
    mass_factor_ = model_->mass();
    mass_factored_ = mass_factor_.Factor();
  }
  work_ = r;
  // Without a usable mass matrix (it always has one: every cable and body
  // has mass), the residual itself.
  if (mass_factored_) mass_factor_.Solve(work_.data());
  const double move = work_.lpNorm<Eigen::Infinity>();
  return std::max(move / (kFirstMove * zscale), std::numeric_limits<double>::min());
}

double StaticSolver::Merit(const Eigen::VectorXd& z, const Eigen::VectorXd& lambda, double alpha,
                           double gamma) {
  model_->ToFull(z, &q_);
  const EnergySample e = model_->Energy(q_, qdot_zero_, alpha);
  double merit = e.total;
  if (q_start_.size() > 0) {
    // Friction is not a potential's force: its work from the iterate z1_
    // by the trapezoidal rule, -(f(z1) + f(z)) / 2 . (z - z1), second
    // order along the step (z = z1_ adds nothing).
    work_.setZero();
    model_->StaticFriction(q_, q_start_, &work_, nullptr, 0);
    work_ += friction_;
    merit -= 0.5 * work_.dot(z - z1_);
  }
  if (m_ > 0) {
    model_->Constraints(q_, &phi_, nullptr);
    merit += lambda.dot(phi_) + 0.5 * gamma * phi_.squaredNorm();
  }
  merit_size_ = std::abs(e.potential) + e.axial + e.bending;
  return merit;
}

StaticSolver::IncrementStats StaticSolver::Solve(double alpha, double tolerance) {
  IncrementStats st;
  const double tol = tolerance > 0 ? tolerance : settings_.newton_tolerance;
  z1_ = z_;
  lambda1_ = lambda_;
  const double zscale0 = 1 + z_.lpNorm<Eigen::Infinity>();
  double last_increment = 0, previous_increment = 0;
  double sigma = 0;       // shift [1/s^2]; 0: plain Newton
  double first_sigma = 0; // the first shift switched on
  double travel = 0;      // sum of the steps' |dz|_inf
  NewtonIterate iterate;
  const SkylineLdlt& mass = model_->mass();
  const int max_iterations = solved_once_ ? kMaxIterations : kLayoutIterations;
  solved_once_ = true;
  for (int it = 0; it <= max_iterations; ++it) {
    if (should_stop_ && should_stop_()) {
      st.stopped = true;
      st.reason = "stopped by the caller";
      return st;
    }
    model_->ToFull(z1_, &q_);
    SkylineLdlt& a = solver_.a();
    a.SetZero();
    const double force_size = model_->NetForce(q_, alpha, &f_, &a, 1.0, &floor_);
    if (q_start_.size() > 0) {
      friction_.setZero(n_);
      model_->StaticFriction(q_, q_start_, &friction_, &a, 1.0, &floor_);
      f_ += friction_;
    }
    model_->Constraints(q_, &phi_, &solver_.b());
    bt_l_.setZero();
    solver_.b().AddTransposeMultiply(lambda1_.data(), bt_l_.data());
    // R = -f + Phi_z^T lambda.
    auto r = rhs_.head(n_);
    const double scale = std::max({force_size, bt_l_.lpNorm<Eigen::Infinity>(), 1e-300});
    r = bt_l_ - f_;
    if (m_ > 0) rhs_.tail(m_) = phi_;
    solver_.b().AddAbsTransposeMultiply(lambda1_.data(), floor_.data(), kSumRounding);
    iterate.last_increment = last_increment;
    iterate.previous_increment = previous_increment;
    iterate.zscale = 1 + z1_.lpNorm<Eigen::Infinity>();
    iterate.violation = m_ > 0 ? phi_.lpNorm<Eigen::Infinity>() : 0.0;
    MeasureResidual(r, floor_, scale, &iterate);
    if (!std::isfinite(iterate.residual) || !std::isfinite(iterate.violation)) {
      const std::string where = model_->DescribeNonFinite(q_, nullptr, alpha);
      st.reason = where.empty() ? std::string("the residual is not finite")
                                : absl::StrCat("the residual is not finite: ", where);
      return st;
    }
    if (it > 0 && last_increment <= tol * iterate.zscale && NewtonConverged(iterate, tol)) {
      st.converged = true;
      st.residual = iterate.residual;
      st.residual_floor = iterate.floor;
      break;
    }
    if (it == max_iterations || travel > kMaxTravel * zscale0) {
      st.reason = absl::StrFormat(
          "no static equilibrium found: %s (position increment %.3g m, relative residual %.3g "
          "with a rounding floor of %.3g, constraint violation %.3g); the loads may have none: "
          "is a body or cable not held by the joints (a mechanism)?",
          it == max_iterations
              ? absl::StrFormat("Newton did not converge in %d iterations", it)
              : absl::StrFormat("the scene moved %.3g times its size", travel / zscale0),
          last_increment, iterate.residual, iterate.floor, iterate.violation);
      return st;
    }
    double gamma = 0;
    if (m_ > 0) {
      model_->AddConstraintHessian(q_, lambda1_, 1.0, &a);
      // Bodies have no stiffness: only the constraints hold them, so A
      // alone is singular. The augmented Lagrangian gamma B^T B, with
      // gamma the size of A's diagonal, makes it definite without
      // changing the answer.
      double diag = 0;
      for (int j = 0; j < n_; ++j) diag = std::max(diag, std::abs(a.values()[a.Slot(j, j)]));
      gamma = diag > 0 ? diag : 1.0;
      solver_.Augment(gamma);
    }
    // The step: shifted until its matrix is positive definite, the step is
    // not longer than kMaxMove of the scene, and (away from the solution)
    // it lowers the merit, the energy plus the augmented constraint terms.
    double* values = a.values();
    // A floor of the shift, 1e-12 of the stiffness over the mass: it keeps
    // a motion that nothing resists and nothing drives (a body pinned at its
    // centre of mass turning about the pin) out of the step, and changes
    // nothing else measurably.
    double kdiag = 0, mdiag = 0;
    for (int j = 0; j < n_; ++j) {
      kdiag = std::max(kdiag, std::abs(values[a.Slot(j, j)]));
      mdiag = std::max(mdiag, std::abs(mass.values()[mass.Slot(j, j)]));
    }
    const double sigma_floor = mdiag > 0 ? 1e-12 * kdiag / mdiag : 0;
    double added = 0;  // shift already in `a`
    bool accepted = false;
    double length = 1;  // of the accepted step, as a fraction of dx
    const double rnorm = r.lpNorm<Eigen::Infinity>();
    for (int attempt = 0; attempt < 60 && !accepted; ++attempt) {
      if (attempt > 0) {
        if (sigma == 0) {
          sigma = first_sigma > 0 ? first_sigma : FirstShift(r, iterate.zscale);
          if (first_sigma == 0) first_sigma = sigma;
        } else {
          sigma *= 4;
        }
      }
      const double shift = std::max(sigma, sigma_floor);
      if (shift != added) {
        const double ds = shift - added;
        for (int k = 0; k < mass.stored(); ++k) values[k] += ds * mass.values()[k];
        added = shift;
      }
      ++st.newton_iterations;
      if (!solver_.Prepare() || a.small_pivots() > 0) continue;
      // A matrix with negative pivots (a compressed cable: its geometric
      // stiffness is negative, most of all for the shortest wavelengths)
      // gives the step of L |D| L^T instead (the pivots' signs flipped: a
      // modified Newton step, Nocedal and Wright 2006, section 3.4). It
      // descends along every direction of negative curvature but by
      // r / |k|, so the short wavelengths that the shift would amplify
      // most (sigma M - |K| is smallest for them) move least, and the cable
      // leaves the unstable straight branch in its long, sagging shape
      // rather than crumpled. With constraints left (m_ > 0) the same by
      // block elimination with (L|D|L^T)^{-1} (SaddlePointSolver::SolveAbs:
      // the constraints' linearisation still met): without it the shift
      // alone stays at about the most negative curvature up to the
      // solution and Newton converges only linearly there (a compressed
      // line lying exactly in a coordinate plane, held by coupled
      // supports' rows, took over 500 iterations). Only after
      // kShiftOnlyIterations of the shift: the scenes that converge with
      // it take the path (and reach the digits) they always did.
      const bool flipped = a.negative_pivots() > 0;
      if (flipped) {
        if (m_ > 0 && it < kShiftOnlyIterations) continue;
        if (m_ == 0) {
          dx_.head(n_) = -r;
          a.SolveAbs(dx_.data());
        } else {
          rhs_ = -rhs_;
          const bool solved = solver_.SolveAbs(rhs_, &dx_);
          rhs_ = -rhs_;
          if (!solved) continue;
        }
      } else {
        rhs_ = -rhs_;
        const auto ls = solver_.Solve(settings_.linear_solver, rhs_, settings_.linear_tolerance,
                                      std::max(settings_.max_linear_iterations, 1000), &dx_);
        rhs_ = -rhs_;
        st.linear_iterations += ls.iterations;
        st.max_linear_residual = std::max(st.max_linear_residual, ls.relative_residual);
        if (!(ls.relative_residual <= kMaxLinearResidual)) continue;
      }
      const double step = dx_.head(n_).lpNorm<Eigen::Infinity>();
      if (!std::isfinite(step)) continue;
      // Near the solution (a short step from a small residual) Newton's
      // step needs no check, and the merit's change would be rounding.
      if (!flipped && step <= 1e-3 * iterate.zscale && rnorm <= std::sqrt(tol) * scale) {
        accepted = true;
        break;
      }
      // Backtracking along the step, at most kMaxMove of the scene long,
      // until the merit falls; a shift (a shorter, more gradient-like step)
      // only when no length of this one does.
      trial_lambda_ = lambda1_;
      if (m_ > 0) trial_lambda_ += dx_.tail(m_);
      const double before = Merit(z1_, trial_lambda_, alpha, gamma);
      const double size = merit_size_;
      length = std::min(1.0, kMaxMove * iterate.zscale / step);
      for (int halving = 0; halving < kLineSearchHalvings && !accepted; ++halving) {
        trial_z_ = z1_ + length * dx_.head(n_);
        const double after = Merit(trial_z_, trial_lambda_, alpha, gamma);
        accepted = after <= before + 64 * kEpsilon * std::max(size, merit_size_);
        if (!accepted) {
          length /= 2;
        } else if (length == 1) {
          // A full step that lowers the merit is lengthened (doubled, up
          // to kMaxMove of the scene) while the merit keeps falling: a
          // slack cable's Newton steps are short and all alike, as its
          // stiffness changes over the step, and it drifts towards the
          // catenary in many of them (from a compressed straight start,
          // over 1,000 iterations at the first load increment).
          double best = after;
          const double cap = kMaxMove * iterate.zscale / step;
          while (2 * length <= cap) {
            trial_z_ = z1_ + 2 * length * dx_.head(n_);
            const double further = Merit(trial_z_, trial_lambda_, alpha, gamma);
            if (!(further < best - 64 * kEpsilon * std::max(size, merit_size_))) break;
            best = further;
            length *= 2;
          }
        }
      }
    }
    if (!accepted) {
      st.reason = "no shift of the tangent stiffness gave a step that lowers the energy";
      return st;
    }
    // A full step that lowered the merit: trust the model more next time.
    if (length >= 1) sigma = sigma / 4 < 1e-8 * first_sigma ? 0 : sigma / 4;
    z1_ += length * dx_.head(n_);
    if (m_ > 0) lambda1_ += length * dx_.tail(m_);
    previous_increment = last_increment;
    last_increment = length * dx_.head(n_).lpNorm<Eigen::Infinity>();
    travel += last_increment;
  }
  z_ = z1_;
  lambda_ = lambda1_;
  return st;
}

bool FollowLoadPath(
    StaticSolver* solver, const SolverSettings& settings, const RunControl& control,
    RunSummary* summary, const std::string& what,
    const std::function<void(const Eigen::VectorXd&, const Eigen::VectorXd&, double)>&
        on_increment,
    const std::function<bool(double)>& on_target) {
  auto fail = [&](double at, const std::string& reason) {
    summary->status = "failed";
    summary->failure_time_s = at;
    summary->error = what + reason;
  };
  solver->set_should_stop(control.should_stop);
  const int n = settings.load_steps;
  const double min_increment = std::ldexp(1.0 / n, -settings.max_step_halvings);
  Eigen::VectorXd before;
  double alpha = 0;
  for (int k = 1; k <= n; ++k) {
    const double target = static_cast<double>(k) / n;
    double d = target - alpha;
    while (target - alpha > 1e-12) {
      if (control.should_stop && control.should_stop()) {
        summary->status = "cancelled";
        summary->error = absl::StrFormat("%sstopped by the caller at load factor %.6g", what, alpha);
        return false;
      }
      if (control.max_steps > 0 && summary->steps + summary->rejected_steps >= control.max_steps) {
        fail(alpha, absl::StrFormat("step limit of %d load increments reached at load factor %.6g",
                                    control.max_steps, alpha));
        return false;
      }
      d = std::min(d, target - alpha);
      if (on_increment) before = solver->z();
      const auto st = solver->Solve(alpha + d);
      summary->newton_iterations += st.newton_iterations;
      summary->linear_iterations += st.linear_iterations;
      summary->max_linear_residual = std::max(summary->max_linear_residual, st.max_linear_residual);
      if (st.stopped) {
        summary->status = "cancelled";
        summary->error = absl::StrFormat("%sstopped by the caller at load factor %.6g", what, alpha);
        return false;
      }
      if (st.converged) {
        alpha += d;
        if (on_increment) on_increment(before, solver->z(), alpha);
        ++summary->steps;
        summary->max_newton_residual = std::max(summary->max_newton_residual, st.residual);
        summary->max_residual_floor = std::max(summary->max_residual_floor, st.residual_floor);
        summary->end_time_s = alpha;
        continue;
      }
      ++summary->rejected_steps;
      d /= 2;
      if (d < min_increment * (1 - 1e-12)) {
        fail(alpha, absl::StrFormat("load increment from load factor %.6g failed after %d "
                                    "bisections: %s",
                                    alpha, settings.max_step_halvings, st.reason));
        return false;
      }
    }
    alpha = target;
    if (on_target && !on_target(alpha)) return false;
  }
  return true;
}

}  // namespace cablesim
