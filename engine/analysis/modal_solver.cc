#include "engine/analysis/modal_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Spectra/SymGEigsShiftSolver.h>

#include <functional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/steppers/newton_convergence.h"
#include "engine/linear/skyline_ldlt.h"
#include "engine/linear/sparse_rows.h"
#include "engine/analysis/static_solver.h"

namespace cablesim {
namespace {

constexpr double kTwoPi = 6.28318530717958647692;
// Default number of modes when solver.modes is not given.
constexpr int kDefaultModes = 10;
// A probe displacement below this fraction of the shape's largest
// coordinate is "not moving": the shape is then left mass-normalised.
constexpr double kStillProbe = 1e-8;

// The symmetric matrix held (lower triangle) in a skyline, as a dense one.
Eigen::MatrixXd Dense(const SkylineLdlt& a) {
  const int n = a.size();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j <= i; ++j) {
      const int slot = a.Slot(i, j);
      if (slot < 0) continue;
      d(i, j) = d(j, i) = a.values()[slot];
    }
  }
  return d;
}

Eigen::MatrixXd Dense(const SparseRows& b) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(b.rows(), b.cols);
  for (int r = 0; r < b.rows(); ++r)
    for (int k = b.row_start[r]; k < b.row_start[r + 1]; ++k) d(r, b.col[k]) += b.value[k];
  return d;
}

// The force balance at z under the full loads: f = Q_a - Q_k, the
// constraint values and Jacobian, and the multipliers that best balance f
// (least squares of Phi_z^T lambda = f, exact at an equilibrium).
struct Balance {
  Eigen::VectorXd q, f, phi, lambda;
  SparseRows jac;
  Eigen::MatrixXd b;  // dense Jacobian, multipliers x dofs
  double force_size = 0;
};

Balance ForceBalance(MultibodyModel* model, const Eigen::VectorXd& z, SkylineLdlt* stiffness) {
  Balance bal;
  bal.q.setZero(model->coordinates());
  model->ToFull(z, &bal.q);
  bal.f.setZero(model->dofs());
  bal.force_size = model->NetForce(bal.q, 1.0, &bal.f, stiffness, 1.0);
  bal.phi.setZero(model->multipliers());
  bal.jac = model->jacobian_pattern();
  bal.lambda.setZero(model->multipliers());
  if (model->multipliers() > 0) {
    model->Constraints(bal.q, &bal.phi, &bal.jac);
    bal.b = Dense(bal.jac);
  }
  return bal;
}

// Whether z balances the full loads: every entry of the residual
// f - Phi_z^T lambda is within `tolerance` times the forces' size of its
// rounding floor (NetForce's roundoff; newton_convergence.h).
bool IsEquilibrium(MultibodyModel* model, const Eigen::VectorXd& z, double tolerance) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model->coordinates());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model->dofs());
  Eigen::VectorXd floor = Eigen::VectorXd::Zero(model->dofs());
  model->ToFull(z, &q);
  const double force_size = model->NetForce(q, 1.0, &f, nullptr, 0, &floor);
  Eigen::VectorXd bt_lambda = Eigen::VectorXd::Zero(model->dofs());
  double violation = 0;
  if (model->multipliers() > 0) {
    Eigen::VectorXd phi = Eigen::VectorXd::Zero(model->multipliers());
    SparseRows jac = model->jacobian_pattern();
    model->Constraints(q, &phi, &jac);
    violation = phi.lpNorm<Eigen::Infinity>();
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Dense(jac).transpose());
    const Eigen::VectorXd lambda = qr.solve(f);
    jac.AddTransposeMultiply(lambda.data(), bt_lambda.data());
    jac.AddAbsTransposeMultiply(lambda.data(), floor.data(), kSumRounding);
  }
  NewtonIterate it;
  it.zscale = 1 + z.lpNorm<Eigen::Infinity>();
  it.violation = violation;
  const double scale = std::max({force_size, bt_lambda.lpNorm<Eigen::Infinity>(), 1e-300});
  MeasureResidual(f - bt_lambda, floor, scale, &it);
  return NewtonConverged(it, tolerance);
}

void Fail(RunSummary* s, double at, const std::string& reason) {
  s->status = "failed";
  s->failure_time_s = at;
  s->error = reason;
}

bool StopRequested(const RunControl& control, RunSummary* s) {
  if (control.should_stop && control.should_stop()) {
    s->status = "cancelled";
    s->error = "stopped by the caller during MODAL analysis";
    return true;
  }
  return false;
}

// The equilibrium under the full loads by the load increments of STATIC
// analysis (FollowLoadPath); false (summary filled in) on failure.
bool FindEquilibrium(MultibodyModel* model, const SolverSettings& settings,
                     const RunControl& control, RunSummary* summary, Eigen::VectorXd* z) {
  StaticSolver solver(model, settings);
  if (!FollowLoadPath(&solver, settings, control, summary, "MODAL: ", nullptr, nullptr)) {
    return false;
  }
  *z = solver.z();
  return true;
}

// y = M x, for the Lanczos iteration's M-inner product.
class MassProduct {
 public:
  using Scalar = double;
  explicit MassProduct(const SkylineLdlt* mass) : mass_(mass) {}
  Eigen::Index rows() const { return mass_->size(); }
  Eigen::Index cols() const { return mass_->size(); }
  void perform_op(const double* x, double* y) const { mass_->Multiply(x, y); }

 private:
  const SkylineLdlt* mass_;
};

// y = Z (Z^T (K - sigma M) Z)^{-1} Z^T x: the constrained shift-invert
// operator, from the KKT system [A B^T; B 0] [y; mu] = [x; 0] with
// A = K - sigma M in skyline LDL^T and the m x m Schur complement
// S = B A^{-1} B^T (dense: few constraint equations). Also counts, by
// Sylvester's law of inertia, the constrained eigenvalues below sigma:
// neg(KKT) = neg(A) + pos(S) = (eigenvalues below sigma) + m.
// Thrown out of the Lanczos iteration when the caller asks to stop.
struct StopLanczos {};

class ConstrainedShiftInvert {
 public:
  using Scalar = double;
  ConstrainedShiftInvert(const SkylineLdlt& k, const SkylineLdlt& mass, const Eigen::MatrixXd& b,
                         const std::function<bool()>* should_stop)
      : k_(k), mass_(mass), b_(b), should_stop_(should_stop) {
    a_ = k;
  }
  Eigen::Index rows() const { return k_.size(); }
  Eigen::Index cols() const { return k_.size(); }

  void set_shift(double sigma) {
    const int slots = k_.stored();
    for (int i = 0; i < slots; ++i) a_.values()[i] = k_.values()[i] - sigma * mass_.values()[i];
    ok_ = a_.Factor();
    const int m = static_cast<int>(b_.rows());
    if (m == 0 || !ok_) return;
    y_ = b_.transpose();
    for (int c = 0; c < m; ++c) a_.Solve(y_.col(c).data());
    schur_ = b_ * y_;
    schur_ = 0.5 * (schur_ + schur_.transpose()).eval();
    lu_.compute(schur_);
  }

  void perform_op(const double* x, double* y) const {
    // The caller's stop request, once per solve (a solve costs far more
    // than the check): a deadline, a cancelled job or shutdown stops the
    // iteration within one solve.
    if (should_stop_ != nullptr && *should_stop_ && (*should_stop_)()) throw StopLanczos{};
    const int n = k_.size();
    Eigen::Map<Eigen::VectorXd> out(y, n);
    out = Eigen::Map<const Eigen::VectorXd>(x, n);
    a_.Solve(y);
    if (b_.rows() > 0) out -= y_ * lu_.solve(b_ * out);
  }

  bool factored() const { return ok_ && a_.small_pivots() == 0; }
  int negative_pivots() const { return a_.negative_pivots(); }
  // Constrained eigenvalues below the current shift.
  int CountBelowShift() const {
    int count = a_.negative_pivots();
    if (b_.rows() > 0) {
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(schur_, Eigen::EigenvaluesOnly);
      count += static_cast<int>((eig.eigenvalues().array() > 0).count()) - static_cast<int>(b_.rows());
    }
    return count;
  }
 private:
  const SkylineLdlt& k_;
  const SkylineLdlt& mass_;
  const Eigen::MatrixXd& b_;
  const std::function<bool()>* should_stop_;
  SkylineLdlt a_;
  bool ok_ = false;
  Eigen::MatrixXd y_, schur_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

double MaxDiagonal(const SkylineLdlt& a) {
  double d = 0;
  for (int j = 0; j < a.size(); ++j) d = std::max(d, std::abs(a.values()[a.Slot(j, j)]));
  return d;
}

// The `modes` lowest constrained eigenpairs by shift-invert Lanczos
// (Spectra's SymGEigsShiftSolver, M-inner product), checked by a Sturm
// count: a single-vector Lanczos can miss a copy of a repeated eigenvalue,
// so when the inertia at the highest one found counts more eigenvalues below
// it than were found, more are asked for and the solve repeated.
bool LanczosModes(const SkylineLdlt& k, const SkylineLdlt& mass, const Eigen::MatrixXd& b,
                  int free_dofs, int modes, const std::function<bool()>* should_stop,
                  Eigen::VectorXd* omega2, Eigen::MatrixXd* shapes, std::string* reason) {
  const int n = k.size();
  ConstrainedShiftInvert op(k, mass, b, should_stop);
  MassProduct mop(&mass);
  // Shift: 0 (inverse iteration, best separated) when K_T is positive
  // definite on the unknowns; otherwise (rigid modes, bodies held only by
  // constraints, an unstable equilibrium) slightly below 0, where K - sigma M
  // is definite but only ~1e10 times worse conditioned than K's scale.
  double sigma = 0;
  op.set_shift(0);
  if (!op.factored() || op.negative_pivots() > 0) {
    sigma = -1e-10 * MaxDiagonal(k) / std::max(MaxDiagonal(mass), 1e-300);
  }
  int nev = std::min(modes + 2, free_dofs - 1);
  if (nev < modes) nev = modes;
  for (int attempt = 0; attempt < 4; ++attempt) {
    const int ncv = std::min(n, std::max(2 * nev + 1, nev + 30));
    Spectra::SymGEigsShiftSolver<ConstrainedShiftInvert, MassProduct, Spectra::GEigsMode::ShiftInvert>
        eigs(op, mop, nev, ncv, sigma);
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
    if (eigs.info() != Spectra::CompInfo::Successful) {
      *reason = absl::StrFormat("shift-invert Lanczos did not converge (%d of %d eigenvalues)",
                                static_cast<int>(eigs.eigenvalues().size()), nev);
      return false;
    }
    Eigen::VectorXd values = eigs.eigenvalues();
    Eigen::MatrixXd vectors = eigs.eigenvectors();
    std::vector<int> order(values.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::sort(order.begin(), order.end(), [&](int i, int j) { return values[i] < values[j]; });
    if (static_cast<int>(order.size()) < modes) {
      *reason = "shift-invert Lanczos returned too few eigenvalues";
      return false;
    }
    const double top = values[order[modes - 1]];
    const double s = top + 1e-6 * std::abs(top) + 1e-9 * std::abs(sigma) + 1e-300;
    op.set_shift(s);
    const int below = op.CountBelowShift();
    int found = 0;
    for (int i : order) found += values[i] <= s ? 1 : 0;
    if (below <= found) {
      omega2->resize(modes);
      shapes->resize(n, modes);
      for (int c = 0; c < modes; ++c) {
        (*omega2)[c] = values[order[c]];
        Eigen::VectorXd x = vectors.col(order[c]);
        Eigen::VectorXd mx(n);
        mass.Multiply(x.data(), mx.data());
        shapes->col(c) = x / std::sqrt(x.dot(mx));
      }
      return true;
    }
    nev = std::min(free_dofs - 1, nev + (below - found) + 2);
  }
  *reason = "shift-invert Lanczos kept missing repeated eigenvalues (Sturm count)";
  return false;
}

}  // namespace

absl::StatusOr<int> ModalSolver::ModeCount(const MultibodyModel& model,
                                           const SolverSettings& settings) {
  const int n = model.dofs();
  if (n > kDenseDofs && model.multipliers() > kMaxLanczosMultipliers) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "solver.analysis: MODAL of a scene with more than %d unknowns is limited to %d "
        "constraint equations; this scene has %d unknowns and %d equations",
        kDenseDofs, kMaxLanczosMultipliers, n, model.multipliers()));
  }
  // Independent constraints each remove one degree of freedom.
  const int free = std::max(0, n - model.multipliers());
  if (free < 1) {
    return absl::InvalidArgumentError(
        "solver.analysis: MODAL needs a scene that can move (it has no degrees of freedom)");
  }
  if (settings.modes > free) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "solver.modes: must be <= %d, the scene's degrees of freedom (%d unknowns minus %d "
        "constraint equations) (got %d)",
        free, n, model.multipliers(), settings.modes));
  }
  return settings.modes > 0 ? settings.modes : std::min(kDefaultModes, free);
}

ModalSolver::Result ModalSolver::Solve(MultibodyModel* model, const Eigen::VectorXd& z_eq,
                                       int modes, Method method,
                                       const std::function<bool()>& should_stop) {
  Result result;
  const int n = model->dofs();
  const int m = model->multipliers();
  SkylineLdlt stiffness;
  stiffness.SetPattern(model->envelope());
  stiffness.SetZero();
  Balance bal = ForceBalance(model, z_eq, &stiffness);
  if (method == Method::kAuto) method = n > kDenseDofs ? Method::kLanczos : Method::kDense;
  Eigen::MatrixXd basis;  // Z, orthonormal basis of the null space of Phi_z
  result.free_dofs = n;
  if (m > 0) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(bal.b.transpose());
    bal.lambda = qr.solve(bal.f);
    model->AddConstraintHessian(bal.q, bal.lambda, 1.0, &stiffness);
    const int rank = static_cast<int>(qr.rank());
    result.free_dofs = n - rank;
    if (method == Method::kDense) {
      basis = Eigen::MatrixXd::Identity(n, n).rightCols(n - rank);
      basis.applyOnTheLeft(qr.householderQ());
    }
  }
  if (modes > result.free_dofs) {
    result.reason = absl::StrFormat(
        "%d modes asked for but the constraints leave %d degrees of freedom", modes,
        result.free_dofs);
    return result;
  }
  if (method == Method::kLanczos) {
    for (int i = 0; i < stiffness.stored(); ++i) {
      if (!std::isfinite(stiffness.values()[i])) {
        result.reason = "the tangent stiffness at the equilibrium is not finite";
        return result;
      }
    }
    if (result.free_dofs - 1 < modes) {
      result.reason = absl::StrFormat(
          "shift-invert Lanczos finds at most %d modes here (degrees of freedom minus 1)",
          result.free_dofs - 1);
      return result;
    }
    try {
      result.ok = LanczosModes(stiffness, model->mass(), bal.b, result.free_dofs, modes,
                               &should_stop, &result.omega2, &result.shapes, &result.reason);
    } catch (const StopLanczos&) {
      result.ok = false;
      result.stopped = true;
      result.reason = "stopped by the caller during the eigensolver";
    }
    return result;
  }
  Eigen::MatrixXd k = Dense(stiffness);
  Eigen::MatrixXd mass = Dense(model->mass());
  if (!k.allFinite()) {
    result.reason = "the tangent stiffness at the equilibrium is not finite";
    return result;
  }
  if (m > 0) {
    k = basis.transpose() * k * basis;
    mass = basis.transpose() * mass * basis;
  }
  // Symmetric up to rounding; the solver reads one triangle.
  k = 0.5 * (k + k.transpose()).eval();
  mass = 0.5 * (mass + mass.transpose()).eval();
  // The caller's stop request before and after the one dense solve, which
  // cannot be interrupted; at most kDenseDofs unknowns bound it (a whole
  // MODAL run of 560 unknowns took 0.18 s).
  auto stop = [&] {
    if (!should_stop || !should_stop()) return false;
    result.stopped = true;
    result.reason = "stopped by the caller during the eigensolver";
    return true;
  };
  if (stop()) return result;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(
      k, mass, Eigen::ComputeEigenvectors | Eigen::Ax_lBx);
  if (stop()) return result;
  if (eig.info() != Eigen::Success) {
    result.reason =
        "the eigen solver failed (the mass matrix on the free motions is not positive definite)";
    return result;
  }
  result.omega2 = eig.eigenvalues().head(modes);
  result.shapes = eig.eigenvectors().leftCols(modes);
  if (m > 0) result.shapes = (basis * result.shapes).eval();
  result.ok = true;
  return result;
}

void RunModalAnalysis(MultibodyModel* model, const SolverSettings& settings, int modes,
                      const RunControl& control, FrameSink* sink, RunSummary* summary) {
  Eigen::VectorXd z = model->initial_z();
  if (!IsEquilibrium(model, z, settings.newton_tolerance)) {
    if (!FindEquilibrium(model, settings, control, summary, &z)) return;
  }
  summary->end_time_s = 1;  // the equilibrium is at the full load
  if (StopRequested(control, summary)) return;
  const ModalSolver::Result modal = ModalSolver::Solve(
      model, z, modes, ModalSolver::Method::kAuto,
      control.should_stop ? control.should_stop : std::function<bool()>());
  if (modal.stopped) {
    summary->status = "cancelled";
    summary->error = "stopped by the caller during MODAL analysis (eigensolver)";
    return;
  }
  if (!modal.ok) {
    Fail(summary, 1, absl::StrCat("MODAL: ", modal.reason));
    return;
  }
  if (!modal.omega2.allFinite() || !modal.shapes.allFinite()) {
    Fail(summary, 1, "MODAL: the eigen solver returned non-finite values");
    return;
  }
  for (int k = 0; k < modes; ++k) {
    const double w2 = modal.omega2[k];
    summary->frequencies_hz.push_back((w2 < 0 ? -1 : 1) * std::sqrt(std::abs(w2)) / kTwoPi);
  }

  // Frame 0: the equilibrium.
  const int nq = model->coordinates();
  Eigen::VectorXd q(nq), zero = Eigen::VectorXd::Zero(nq), shape_q(nq);
  model->ToFull(z, &q);
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(model->multipliers());
  SparseRows jac = model->jacobian_pattern();
  model->Constraints(q, &phi, &jac);
  Frame frame;
  frame.t = 0;
  model->Probes(q, zero, zero, &frame.probes);
  if (model->shape()) model->NodePositions(q, &frame.nodes);
  frame.energy = model->Energy(q, zero, 1.0, &frame.energy_parts);
  // MODAL reports no support forces: their columns hold 0.
  frame.support_forces.assign(model->force_probe_count(), Eigen::Vector3d::Zero());
  if (model->reactions()) model->Reactions(q, nullptr, &frame.reactions);
  if (model->tension()) model->Tensions(q, 1.0, &frame.probe_tensions, &frame.node_tensions);
  if (model->orientation()) model->Orientations(q, zero, &frame.body_orientation);
  if (model->bending_moment()) model->BendingMoments(q, 1.0, &frame.probe_bending_moments);
  frame.joint_released = model->joint_released();
  frame.has_contact = model->has_contact();
  frame.constraint_violation = phi.size() ? phi.lpNorm<Eigen::Infinity>() : 0.0;
  summary->energy_initial = summary->energy_final = frame.energy.total;
  summary->max_constraint_violation = frame.constraint_violation;
  auto emit = [&](const Frame& f) {
    ++summary->frames;
    if (absl::Status s = sink->OnFrame(f); !s.ok()) {
      summary->status = "cancelled";
      summary->error = std::string(s.message());
      return false;
    }
    return true;
  };
  if (!emit(frame)) return;

  // Frames 1..modes: the shapes at the probes. A probe's velocity for the
  // rate x is its displacement in the linearised motion z* + x.
  Eigen::VectorXd shape(model->dofs()), jx = Eigen::VectorXd::Zero(model->multipliers());
  for (int k = 0; k < modes; ++k) {
    shape = modal.shapes.col(k);
    model->RateToFull(shape, &shape_q);
    std::vector<ProbeSample> samples;
    model->Probes(q, shape_q, zero, &samples);
    double largest = 0, sign = 1;
    for (const ProbeSample& p : samples) {
      for (int c = 0; c < 3; ++c) {
        if (std::abs(p.velocity_m_s[c]) > largest) {
          largest = std::abs(p.velocity_m_s[c]);
          sign = p.velocity_m_s[c] < 0 ? -1 : 1;
        }
      }
    }
    double scale = 1;
    if (largest > kStillProbe * shape_q.lpNorm<Eigen::Infinity>()) scale = sign / largest;
    Frame mode;
    mode.t = k + 1;
    // A shape has no energy: every part 0, as the totals.
    mode.energy_parts.cables.resize(frame.energy_parts.cables.size());
    mode.energy_parts.bodies.resize(frame.energy_parts.bodies.size());
    mode.support_forces.assign(model->force_probe_count(), Eigen::Vector3d::Zero());
    mode.has_contact = frame.has_contact;
    mode.reactions = frame.reactions;
    mode.probe_tensions.assign(frame.probe_tensions.size(), 0.0);
    mode.node_tensions.assign(frame.node_tensions.size(), 0.0);
    mode.body_orientation.assign(frame.body_orientation.size(), 0.0);
    mode.probe_bending_moments.assign(frame.probe_bending_moments.size(), 0.0);
    mode.joint_released = frame.joint_released;
    mode.probes.resize(samples.size());
    for (size_t p = 0; p < samples.size(); ++p)
      mode.probes[p].position_m = scale * samples[p].velocity_m_s;
    if (model->shape()) {
      // The nodes' displacement in the mode, scaled as the probes'.
      model->NodePositions(shape_q, &mode.nodes);
      for (Eigen::Vector3d& r : mode.nodes) r *= scale;
    }
    if (jx.size() > 0) {
      jac.Multiply(shape.data(), jx.data());
      mode.constraint_violation = std::abs(scale) * jx.lpNorm<Eigen::Infinity>();
    }
    if (!emit(mode)) return;
  }
}

}  // namespace cablesim
