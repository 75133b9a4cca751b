#include "engine/model/multibody_model.h"

#include <bit>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "absl/status/status.h"
#include "engine/forces/winch_inertia.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"
#include "engine/linear/rounding.h"

namespace cablesim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

}  // namespace

void MultibodyModel::ScatterSlider(const SlidingJoint::Local& local, VectorXd* full,
                                   VectorXd* roundoff, double scale, SkylineLdlt* a) const {
  ForceOutput out{full, roundoff, a, scale, Map()};
  AddLocalTerms(local, &out);
}

const std::vector<BodyFluidLoad>& MultibodyModel::body_fluid_loads() const {
  static const std::vector<BodyFluidLoad> kNone;
  return body_fluid_ ? body_fluid_->loads() : kNone;
}

const ForceContributor* MultibodyModel::FindContributor(std::string_view name) const {
  for (const auto& c : contributors_)
    if (c->name() == name) return c.get();
  return nullptr;
}

VectorXd MultibodyModel::Reduce(const VectorXd& full) const {
  VectorXd z = VectorXd::Zero(dofs_), norm2 = VectorXd::Zero(dofs_);
  for (int i = 0; i < coordinates(); ++i) {
    if (j_[i] < 0) continue;
    z(j_[i]) += s_(i) * full(i);
    norm2(j_[i]) += s_(i) * s_(i);
  }
  for (int j = 0; j < dofs_; ++j)
    if (norm2(j) > 0) z(j) /= norm2(j);
  return z;
}

void MultibodyModel::RigidVelocity(const VectorXd& q, VectorXd* qdot) const {
  const InitialVelocitySpec& iv = initial_velocity_;
  const Vector3d omega = iv.angular_rad_s;
  const int D = dim_;
  auto vec = [D](const VectorXd& x, int i) {
    Vector3d v = Vector3d::Zero();
    v.head(D) = x.segment(i, D);
    return v;
  };
  // Points move as v + omega x (r - origin); directions (slopes, body axes)
  // as omega x d.
  auto point = [&](int i) {
    qdot->segment(i, D) = (iv.linear_m_s + omega.cross(vec(q, i) - iv.origin_m)).head(D);
  };
  auto direction = [&](int i) { qdot->segment(i, D) = omega.cross(vec(q, i)).head(D); };
  qdot->setZero();
  for (int node = 0; node < num_nodes_; ++node) {
    point(node_stride_ * node);
    direction(node_stride_ * node + D);
  }
  for (const BodyData& b : bodies_) {
    point(b.coord);
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k) direction(b.coord + D + D * k);
  }
}

void MultibodyModel::SetInitialState(const VectorXd& z) {
  z0_ = z;
  VectorXd q(coordinates()), qdot(coordinates());
  ToFull(z, &q);
  RigidVelocity(q, &qdot);
  v0_ = Reduce(qdot);
  initial_velocity_correction_ = 0;
  ProjectInitialVelocity();
}

void MultibodyModel::ProjectInitialVelocity() {
  // The scene's rigid initial motion need not respect the joints (a pin
  // away from the rotation origin, say). Keep the part that does, nearest
  // in kinetic energy: v0 -= M^-1 J^T (J M^-1 J^T)^-1 J v0, the velocity
  // right after a perfectly inelastic impulse at the joints.
  const int nrows = multipliers();
  if (nrows == 0) return;
  VectorXd q0(coordinates()), phi(nrows);
  ToFull(z0_, &q0);
  SparseRows jac = jac_pattern_;
  Constraints(q0, &phi, &jac);
  VectorXd jv(nrows);
  jac.Multiply(v0_.data(), jv.data());
  // Moving and turning supports: Phi_z v + Phi_t = 0.
  for (const ConstraintFamily* f : families_) f->AddRate(q0, &jv);
  if (jv.lpNorm<Eigen::Infinity>() <= 1e-14 * (1 + v0_.lpNorm<Eigen::Infinity>())) return;
  SkylineLdlt mass = mass_;
  if (!mass.Factor()) return;
  Eigen::MatrixXd minv_jt = Eigen::MatrixXd::Zero(dofs_, nrows);
  for (int r = 0; r < nrows; ++r) {
    for (int k = jac.row_start[r]; k < jac.row_start[r + 1]; ++k)
      minv_jt(jac.col[k], r) += jac.value[k];
    mass.Solve(minv_jt.col(r).data());
  }
  Eigen::MatrixXd schur(nrows, nrows);
  for (int r = 0; r < nrows; ++r) jac.Multiply(minv_jt.col(r).data(), schur.col(r).data());
  // Redundant rows make the Schur complement singular: least squares.
  const VectorXd mu = schur.completeOrthogonalDecomposition().solve(jv);
  initial_velocity_correction_ = (minv_jt * mu).lpNorm<Eigen::Infinity>();
  v0_ -= minv_jt * mu;
}

ModelInfo MultibodyModel::Info() const {
  ModelInfo info;
  info.model = dim_ == 2 ? "planar" : "spatial";
  info.coordinates = coordinates();
  info.dofs = dofs();
  info.multipliers = multipliers();
  info.elements = elements();
  info.nodes = nodes();
  info.probe_names = probe_names_;
  for (int p : force_probes_) info.force_probe_names.push_back(probe_names_[p]);
  info.cable_names = cable_names_;
  info.body_names = body_names_;
  info.cable_nodes = cable_nodes_;
  info.node_s = node_s_;
  info.shape = shape_;
  info.contact = has_contact();
  return info;
}

void MultibodyModel::ToFull(const VectorXd& z, VectorXd* q) const {
  const int n = coordinates();
  for (int i = 0; i < n; ++i) (*q)(i) = j_[i] >= 0 ? c_(i) + s_(i) * z(j_[i]) : c_(i);
}

void MultibodyModel::RateToFull(const VectorXd& zdot, VectorXd* qdot) const {
  const int n = coordinates();
  for (int i = 0; i < n; ++i) (*qdot)(i) = j_[i] >= 0 ? s_(i) * zdot(j_[i]) : 0.0;
}

template <int D>
void MultibodyModel::BodySheaveForce(const Sheave& wheel, int first_coord, double length,
                                     const VectorXd& q, VectorXd* full, VectorXd* roundoff,
                                     SkylineLdlt* stiffness, double scale) const {
  constexpr int kN = 4 * D, kX = 5 * D;
  const int centre = bodies_[wheel.body()].coord;
  Eigen::Matrix<double, kX, 1> x, gradient = Eigen::Matrix<double, kX, 1>::Zero(),
                                  rounding = Eigen::Matrix<double, kX, 1>::Zero();
  x << q.segment<kN>(first_coord), q.segment<D>(centre);
  Eigen::Matrix<double, kX, kX> hessian;
  if (stiffness) hessian.setZero();
  if (wheel.AddPotentialOnBody<D>(x, length, &gradient, stiffness ? &hessian : nullptr,
                                  roundoff ? &rounding : nullptr) == 0)
    return;
  SlidingJoint::Local local;
  local.n = kX;
  for (int k = 0; k < kN; ++k) local.coord[k] = first_coord + k;
  for (int k = 0; k < D; ++k) local.coord[kN + k] = centre + k;
  local.force = -gradient;
  if (stiffness) local.matrix = hessian;
  local.rounding = rounding.maxCoeff();
  ScatterSlider(local, full, roundoff, scale, stiffness);
}

template <int D>
double MultibodyModel::BodySheaveDamping(const Sheave& wheel, int first_coord, double length,
                                         const VectorXd& q, const VectorXd& qdot, VectorXd* full,
                                         VectorXd* roundoff, SkylineLdlt* tangent,
                                         double scale) const {
  constexpr int kN = 4 * D, kX = 5 * D;
  const int centre = bodies_[wheel.body()].coord;
  Eigen::Matrix<double, kX, 1> x, xdot, force = Eigen::Matrix<double, kX, 1>::Zero();
  x << q.segment<kN>(first_coord), q.segment<D>(centre);
  xdot << qdot.segment<kN>(first_coord), qdot.segment<D>(centre);
  Eigen::Matrix<double, kX, kX> c;
  if (tangent) c.setZero();
  const double power =
      wheel.AddDissipationOnBody<D>(x, xdot, length, &force, tangent ? &c : nullptr);
  if (full == nullptr || power == 0) return power;
  SlidingJoint::Local local;
  local.n = kX;
  for (int k = 0; k < kN; ++k) local.coord[k] = first_coord + k;
  for (int k = 0; k < D; ++k) local.coord[kN + k] = centre + k;
  local.force = force;
  if (tangent) local.matrix = c;
  local.rounding = kSumRounding * force.cwiseAbs().maxCoeff();
  ScatterSlider(local, full, roundoff, scale, tangent);
  return power;
}

template <int D>
double MultibodyModel::ElementForces(const VectorXd& q, VectorXd* full, SkylineLdlt* stiffness,
                                     double stiffness_scale, VectorXd* roundoff) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Coords fe, re;
  typename AncfCableElement<D>::Matrix ke;
  double size = 0;
  double* values = stiffness ? stiffness->values() : nullptr;
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    fe.setZero();
    if (stiffness) ke.setZero();
    if (roundoff) re.setZero();
    e.element.ElasticForce(q.segment<kN>(e.first_coord), &fe, stiffness ? &ke : nullptr,
                           roundoff ? &re : nullptr);
    // The seabed's force, like the elastic one, is the gradient of an energy.
    if (seabed_)
      seabed_->AddPotential<D>(q.segment<kN>(e.first_coord), e.element.length(), &fe,
                               stiffness ? &ke : nullptr, roundoff ? &re : nullptr);
    if (!sheaves_.empty()) {
      for (uint64_t bits = sheave_mask_[k]; bits != 0; bits &= bits - 1) {
        const Sheave& wheel = sheaves_[std::countr_zero(bits)];
        if (wheel.body() >= 0) {
          BodySheaveForce<D>(wheel, e.first_coord, e.element.length(), q, full, roundoff,
                             stiffness, stiffness_scale);
        } else {
          wheel.AddPotential<D>(q.segment<kN>(e.first_coord), e.element.length(), &fe,
                                stiffness ? &ke : nullptr, roundoff ? &re : nullptr);
        }
      }
    }
    full->segment<kN>(e.first_coord) -= fe;
    // The element's own bound, and the rounding of adding it to the node.
    if (roundoff) roundoff->segment<kN>(e.first_coord) += re + kEps * fe.cwiseAbs();
    size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
    if (!stiffness) continue;
    ScatterElementMatrix<kN2>(k, ke.data(), stiffness_scale, values);
  }
  return size;
}

double MultibodyModel::NetForce(const VectorXd& q, double load_factor, VectorXd* f,
                                SkylineLdlt* stiffness, double stiffness_scale,
                                VectorXd* roundoff) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  VectorXd& full = scratch_full_;
  full = load_factor * constant_force_;
  // Contributors' applied loads (time-varying loads, torques, body
  // buoyancy), scaled as gravity.
  const ForceState state = StateAt(q, nullptr, load_factor);
  ForceOutput out{&full, nullptr, stiffness, stiffness_scale, Map()};
  for (const auto& c : contributors_) c->AddAppliedLoad(state, &out);
  // The size of the applied terms counts only coordinates that move: a
  // heavy body welded to ground must not loosen the tolerance elsewhere.
  double size = 0;
  const int n = coordinates();
  for (int i = 0; i < n; ++i)
    if (j_[i] >= 0) size = std::max(size, std::abs(full(i)));
  // Rounding of the applied terms (torques included, through |full|).
  VectorXd* full_roundoff = nullptr;
  if (roundoff) {
    full_roundoff = &scratch_roundoff_;
    *full_roundoff = kEps * full.cwiseAbs();
  }
  size = std::max(size, dim_ == 2 ? ElementForces<2>(q, &full, stiffness, stiffness_scale,
                                                     full_roundoff)
                                  : ElementForces<3>(q, &full, stiffness, stiffness_scale,
                                                     full_roundoff));
  // Contributors' conservative forces (contact, penalties).
  out.roundoff = full_roundoff;
  out.size = 0;
  for (const auto& c : contributors_) c->AddConservative(state, &out);
  size = std::max(size, out.size);
  f->setZero();
  for (int i = 0; i < n; ++i)
    if (j_[i] >= 0) (*f)(j_[i]) += s_(i) * full(i);
  if (roundoff) {
    roundoff->setZero();
    for (int i = 0; i < n; ++i)
      if (j_[i] >= 0)
        (*roundoff)(j_[i]) += std::abs(s_(i)) * ((*full_roundoff)(i) + kEps * std::abs(full(i)));
  }
  return size;
}

template <int D>
void MultibodyModel::ElementDiscreteGradientCorrection(const VectorXd& q0, const VectorXd& q1,
                                                       VectorXd* full) const {
  constexpr int kN = 4 * D;
  typename AncfCableElement<D>::Coords ce;
  for (const ElementData<D>& e : Elements<D>()) {
    ce.setZero();
    e.element.AddDiscreteGradientCorrection(q0.segment<kN>(e.first_coord),
                                            q1.segment<kN>(e.first_coord), &ce);
    full->segment<kN>(e.first_coord) += ce;
  }
}

void MultibodyModel::SubtractDiscreteGradientCorrection(const VectorXd& q0, const VectorXd& q1,
                                                        VectorXd* f) {
  VectorXd& full = scratch_full_;
  full.setZero(c_.size());
  if (dim_ == 2) {
    ElementDiscreteGradientCorrection<2>(q0, q1, &full);
  } else {
    ElementDiscreteGradientCorrection<3>(q0, q1, &full);
  }
  for (int i = 0; i < full.size(); ++i)
    if (j_[i] >= 0) (*f)(j_[i]) -= s_(i) * full(i);
}

template <int D>
double MultibodyModel::ElementDamping(const VectorXd& q, const VectorXd& qdot, VectorXd* full,
                                      SkylineLdlt* tangent, double tangent_scale,
                                      VectorXd* roundoff, double* power) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Matrix ce;
  typename AncfCableElement<D>::Coords fe;
  double size = 0;
  double* values = tangent ? tangent->values() : nullptr;
  const bool bed = seabed_ && seabed_->dissipates();
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    const uint64_t wheels = sheaves_dissipate_ ? sheave_mask_[k] : 0;
    if (!e.damped() && !bed && e.fluid_inertia == 0 && wheels == 0) continue;
    ce.setZero();
    if (e.axial_damping_s != 0 || e.bending_damping_s != 0)
      e.element.AddDampingMatrix(q.segment<kN>(e.first_coord), e.axial_damping_s,
                                 e.bending_damping_s, &ce);
    if (e.alpha_1_s != 0) ce += e.alpha_1_s * e.element.MassMatrix(e.mass_per_length);
    const auto ve = qdot.segment<kN>(e.first_coord);
    // fe: the damping force -C ve, plus the drag (which adds its own
    // velocity derivative to ce).
    fe.noalias() = -ce * ve;
    if (wave_load_) {
      if (e.drag_n != 0 || e.drag_t != 0 || e.fluid_inertia != 0)
        wave_load_->Add<D>(e.element, q.segment<kN>(e.first_coord), ve, time_, e.drag_n, e.drag_t,
                           e.fluid_inertia, &fe, &ce);
    } else if (e.drag_n != 0 || e.drag_t != 0) {
      e.element.AddDrag(q.segment<kN>(e.first_coord), ve, current_.head<D>(), e.drag_n, e.drag_t,
                        &fe, &ce);
    }
    if (bed)
      seabed_->AddDissipation<D>(q.segment<kN>(e.first_coord), ve, e.element.length(), &fe, &ce);
    for (uint64_t bits = wheels; bits != 0; bits &= bits - 1) {
      const Sheave& wheel = sheaves_[std::countr_zero(bits)];
      if (wheel.body() >= 0) {
        const double p = BodySheaveDamping<D>(wheel, e.first_coord, e.element.length(), q, qdot,
                                              full, roundoff, tangent, tangent_scale);
        if (power) *power += p;
      } else {
        wheel.AddDissipation<D>(q.segment<kN>(e.first_coord), ve, e.element.length(), &fe, &ce);
      }
    }
    if (power) *power -= ve.dot(fe);
    if (full) full->segment<kN>(e.first_coord) += fe;
    size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
    if (roundoff)
      roundoff->segment<kN>(e.first_coord).noalias() +=
          kSumRounding * (ce.cwiseAbs() * ve.cwiseAbs() + fe.cwiseAbs());
    if (!tangent) continue;
    ScatterElementMatrix<kN2>(k, ce.data(), tangent_scale, values);
  }
  return size;
}

double MultibodyModel::DampingForce(const VectorXd& q, const VectorXd& qdot, VectorXd* f,
                                    SkylineLdlt* tangent, double tangent_scale,
                                    VectorXd* roundoff) {
  if (!has_damping_) return 0;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  VectorXd& full = scratch_damping_;
  full.setZero();
  VectorXd* full_roundoff = nullptr;
  if (roundoff) {
    full_roundoff = &scratch_damping_roundoff_;
    full_roundoff->setZero();
  }
  double size = dim_ == 2 ? ElementDamping<2>(q, qdot, &full, tangent, tangent_scale,
                                              full_roundoff, nullptr)
                          : ElementDamping<3>(q, qdot, &full, tangent, tangent_scale,
                                              full_roundoff, nullptr);
  // Contributors' velocity-dependent forces.
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, 1.0);
    ForceOutput out{&full, full_roundoff, tangent, tangent_scale, Map()};
    for (const auto& c : contributors_) c->AddDissipative(state, &out);
    size = std::max(size, out.size);
  }
  if (!winches_.empty()) {
    size = std::max(size, dim_ == 2 ? WinchForces<2>(q, qdot, &full, tangent, tangent_scale,
                                                     full_roundoff)
                                    : WinchForces<3>(q, qdot, &full, tangent, tangent_scale,
                                                     full_roundoff));
  }
  const int n = coordinates();
  for (int i = 0; i < n; ++i) {
    if (j_[i] < 0) continue;
    (*f)(j_[i]) += s_(i) * full(i);
    if (roundoff)
      (*roundoff)(j_[i]) += std::abs(s_(i)) * ((*full_roundoff)(i) + kEps * std::abs(full(i)));
  }
  return size;
}

double MultibodyModel::DampingPower(const VectorXd& q, const VectorXd& qdot) const {
  if (!has_damping_) return 0;
  double power = 0;  // -Q_d . qdot
  if (dim_ == 2) {
    ElementDamping<2>(q, qdot, nullptr, nullptr, 0, nullptr, &power);
  } else {
    ElementDamping<3>(q, qdot, nullptr, nullptr, 0, nullptr, &power);
  }
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, 1.0);
    for (const auto& c : contributors_) c->AddDissipatedPower(state, &power);
  }
  // A winch cable's damping (not its convective inertia, which dissipates
  // nothing).
  for (const WinchData& w : winches_) {
    for (int index = w.element_begin; index < w.element_end; ++index) {
      power += dim_ == 2 ? WinchDamping<2>(w, index, q, qdot, nullptr, nullptr)
                         : WinchDamping<3>(w, index, q, qdot, nullptr, nullptr);
    }
  }
  return power;
}

bool MultibodyModel::has_static_friction() const {
  if (!seabed_) return false;
  if (seabed_->has_friction() && (!elements2_.empty() || !elements3_.empty())) return true;
  for (const auto& c : contributors_)
    if (c->has_static_friction()) return true;
  return false;
}

void MultibodyModel::StaticFriction(const VectorXd& q, const VectorXd& q_start, VectorXd* f,
                                    SkylineLdlt* matrix, double scale) {
  if (!has_static_friction()) return;
  VectorXd& full = scratch_static_;
  full.setZero(c_.size());
  auto cables = [&](const auto& elements, auto dim) {
    constexpr int D = decltype(dim)::value, kN = 4 * D, kN2 = kN * kN;
    if (!seabed_->has_friction()) return;
    typename AncfCableElement<D>::Coords fe;
    typename AncfCableElement<D>::Matrix me;
    double* values = matrix ? matrix->values() : nullptr;
    for (size_t k = 0; k < elements.size(); ++k) {
      const ElementData<D>& e = elements[k];
      fe.setZero();
      if (matrix) me.setZero();
      seabed_->AddStaticFriction<D>(q.segment<kN>(e.first_coord),
                                              q_start.segment<kN>(e.first_coord),
                                              e.element.length(), &fe, matrix ? &me : nullptr);
      full.segment<kN>(e.first_coord) += fe;
      if (!matrix) continue;
      ScatterElementMatrix<kN2>(k, me.data(), scale, values);
    }
  };
  if (dim_ == 2) {
    cables(elements2_, std::integral_constant<int, 2>());
  } else {
    cables(elements3_, std::integral_constant<int, 3>());
  }
  ForceOutput out{&full, nullptr, matrix, scale, Map()};
  for (const auto& c : contributors_) c->AddStaticFriction(q, q_start, &out);
  if (f) {
    const int n = coordinates();
    for (int i = 0; i < n; ++i)
      if (j_[i] >= 0) (*f)(j_[i]) += s_(i) * full(i);
  }
}

void MultibodyModel::Constraints(const VectorXd& q, VectorXd* phi, SparseRows* jac) const {
  const CoordinateMap map = Map();
  for (const ConstraintFamily* f : families_) f->Residual(q, map, phi, jac);
}

void MultibodyModel::AddConstraintHessian(const VectorXd& q, const VectorXd& lambda, double scale,
                                          SkylineLdlt* a) const {
  // The Hessians are constant; `q` is kept for the interface.
  (void)q;
  for (const ConstraintFamily* f : families_) f->AddHessian(lambda, scale, a);
}

void MultibodyModel::ConstraintGamma(const VectorXd& q, const VectorXd& qdot,
                                     VectorXd* gamma) const {
  gamma->setZero();
  for (const ConstraintFamily* f : families_) f->AddGamma(q, qdot, gamma);
}

void MultibodyModel::SetTime(double t) {
  time_ = t;
  if (!time_dependent_) return;
  for (ConstraintFamily* f : families_) f->SetTime(t);
  for (const auto& c : contributors_) c->SetTime(t);
  if (!winches_.empty()) {
    if (dim_ == 2) {
      UpdateWinches<2>();
    } else {
      UpdateWinches<3>();
    }
  }
}

template <int D>
void MultibodyModel::UpdateWinches() {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  std::vector<ElementData<D>>* elements_ptr;
  if constexpr (D == 2) {
    elements_ptr = &elements2_;
  } else {
    elements_ptr = &elements3_;
  }
  std::vector<ElementData<D>>& elements = *elements_ptr;
  std::copy(mass_base_.begin(), mass_base_.end(), mass_.values());
  constant_force_ = constant_force_base_;
  const Eigen::Matrix<double, D, 1> g = gravity_.head<D>();
  size_t slot = 0;
  for (WinchData& w : winches_) {
    const TimeFunction::Value v = w.speed.Evaluate(time_);
    w.length = w.length0 + w.speed.Integral(time_);
    w.rate = v.f;
    w.accel = v.df;
    const int n = w.element_end - w.element_begin;
    const double l = w.length / n, ldot = w.rate / n, lddot = w.accel / n;
    for (int k = 0; k < n; ++k, ++slot) {
      const int index = w.element_begin + k;
      ElementData<D>& e = elements[index];
      e.element.set_length(l);
      const auto me = e.element.MassMatrix(w.mass_per_length);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(D * a, D * b);
      e.gravity = e.element.GravityForce(w.mass_per_length, g);
      constant_force_.segment<kN>(e.first_coord) += e.gravity;
      ScatterElementMatrix<kN2>(index, me.data(), 1.0, mass_.values());
      const WinchElementInertia in = ComputeWinchElementInertia(w.mass_per_length, l, k);
      WinchConvectiveCoefficients(in, ldot, lddot, &winch_cv_[slot], &winch_ce_[slot]);
      winch_mdot_[slot] = ldot * in.m_l;
      winch_g_[slot] = in.g;
      winch_h_[slot] = in.h;
    }
  }
}

template <int D>
double MultibodyModel::WinchDamping(const WinchData& w, int index, const VectorXd& q,
                                   const VectorXd& qdot,
                                   typename AncfCableElement<D>::Coords* fe,
                                   typename AncfCableElement<D>::Matrix* ce) const {
  constexpr int kN = 4 * D;
  if (w.alpha_1_s == 0 && w.axial_damping_s == 0) return 0;
  const ElementData<D>& e = Elements<D>()[index];
  const auto qe = q.segment<kN>(e.first_coord);
  const auto ve = qdot.segment<kN>(e.first_coord);
  const int n = w.element_end - w.element_begin, k = index - w.element_begin;
  const double l = w.length / n, ldot = w.rate / n;
  double power = 0;
  if (w.alpha_1_s != 0) {
    // -alpha int mu S^T v dx with the material velocity v = S edot + ldot W e.
    const Eigen::Matrix4d& g = winch_g_[winch_slot_[index]];
    for (int a = 0; a < 4; ++a) {
      for (int d = 0; d < D; ++d) {
        double p = 0;
        for (int b = 0; b < 4; ++b) p += e.mbar(a, b) * ve(D * b + d) + ldot * g(a, b) * qe(D * b + d);
        if (fe) (*fe)(D * a + d) -= w.alpha_1_s * p;
        power += w.alpha_1_s * p * ve(D * a + d);
        if (ce)
          for (int b = 0; b < 4; ++b) (*ce)(D * a + d, D * b + d) += w.alpha_1_s * e.mbar(a, b);
      }
    }
    // The power is alpha int mu |v|^2 = 2 alpha T: add ldot e^T G^T edot +
    // ldot^2 e^T H e to the edot . (M edot + ldot G e) summed above.
    const Eigen::Matrix4d& h = winch_h_[winch_slot_[index]];
    for (int d = 0; d < D; ++d) {
      for (int a = 0; a < 4; ++a) {
        for (int b = 0; b < 4; ++b) {
          power += w.alpha_1_s * ldot * qe(D * a + d) *
                   (g(b, a) * ve(D * b + d) + ldot * h(a, b) * qe(D * b + d));
        }
      }
    }
  }
  if (w.axial_damping_s != 0) {
    // Kelvin-Voigt on the material strain rate u . d(r_s)/dt|_s.
    static const GaussRule rule = MakeGaussRule(AncfCableElement<D>::kDefaultGaussPoints);
    const double c = w.ea * w.axial_damping_s;
    for (int gp = 0; gp < rule.n; ++gp) {
      double d1[4], wd[4];
      HermiteShapeD1(rule.xi[gp], l, d1);
      WinchSlopeRateShape(rule.xi[gp], l, k, wd);
      Eigen::Matrix<double, D, 1> u = Eigen::Matrix<double, D, 1>::Zero(), udot = u;
      for (int a = 0; a < 4; ++a) {
        u += d1[a] * qe.template segment<D>(D * a);
        udot += d1[a] * ve.template segment<D>(D * a) + ldot * wd[a] * qe.template segment<D>(D * a);
      }
      const double wl = rule.weight[gp] * l, rate = u.dot(udot);
      power += wl * c * rate * rate;
      if (fe)
        for (int a = 0; a < 4; ++a) fe->template segment<D>(D * a) -= (wl * c * rate * d1[a]) * u;
      if (ce) {
        const Eigen::Matrix<double, D, D> uu = u * u.transpose();
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            ce->template block<D, D>(D * a, D * b) += (wl * c * d1[a] * d1[b]) * uu;
      }
    }
  }
  return power;
}

template <int D>
double MultibodyModel::WinchForces(const VectorXd& q, const VectorXd& qdot, VectorXd* full,
                                   SkylineLdlt* tangent, double tangent_scale,
                                   VectorXd* roundoff) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Coords fe;
  typename AncfCableElement<D>::Matrix ce;
  double size = 0;
  for (const WinchData& w : winches_) {
    for (int index = w.element_begin; index < w.element_end; ++index) {
      const int slot = winch_slot_[index];
      const ElementData<D>& e = elements[index];
      const auto qe = q.segment<kN>(e.first_coord);
      const auto ve = qdot.segment<kN>(e.first_coord);
      const Eigen::Matrix4d& cv = winch_cv_[slot];
      const Eigen::Matrix4d& cx = winch_ce_[slot];
      // The convective force -cv edot - ce e; Newton takes Mdot (the
      // symmetric part of cv).
      fe.setZero();
      ce.setZero();
      for (int a = 0; a < 4; ++a) {
        for (int d = 0; d < D; ++d) {
          double f = 0, abs_sum = 0;
          for (int b = 0; b < 4; ++b) {
            const double tv = cv(a, b) * ve(D * b + d), te = cx(a, b) * qe(D * b + d);
            f -= tv + te;
            abs_sum += std::abs(tv) + std::abs(te);
            ce(D * a + d, D * b + d) = winch_mdot_[slot](a, b);
          }
          fe(D * a + d) = f;
          if (roundoff) (*roundoff)(e.first_coord + D * a + d) += kSumRounding * abs_sum;
        }
      }
      WinchDamping<D>(w, index, q, qdot, &fe, tangent ? &ce : nullptr);
      full->segment<kN>(e.first_coord) += fe;
      size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
      if (roundoff)
        roundoff->segment<kN>(e.first_coord).noalias() += kSumRounding * fe.cwiseAbs();
      if (!tangent) continue;
      const int* slots = &element_slots_[kN2 * index];
      const double* factors = &element_factors_[kN2 * index];
      for (int t = 0; t < kN2; ++t)
        if (slots[t] >= 0) tangent->values()[slots[t]] += tangent_scale * factors[t] * ce(t / kN, t % kN);
    }
  }
  return size;
}

double MultibodyModel::CableMass(int cable) const {
  double mass = 0;
  auto sum = [&](const auto& elements) {
    for (int k = cable_element_begin_[cable]; k < cable_element_begin_[cable + 1]; ++k) {
      const Eigen::Matrix4d& m = elements[k].mbar;
      mass += m(0, 0) + m(0, 2) + m(2, 0) + m(2, 2);
    }
  };
  if (dim_ == 2) {
    sum(elements2_);
  } else {
    sum(elements3_);
  }
  return mass;
}

template <int D>
Eigen::Vector3d MultibodyModel::WinchTension(const VectorXd& q, int w) const {
  const ElementData<D>& e = Elements<D>()[winches_[w].element_end - 1];
  const Eigen::Matrix<double, D, 1> u =
      e.element.Slope(q.segment<4 * D>(e.first_coord), 1.0);
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  f.head<D>() = winches_[w].ea * 0.5 * (u.squaredNorm() - 1) * u;
  return f;
}

template <int D>
void MultibodyModel::ElementEnergy(const VectorXd& q, const VectorXd& qdot, EnergySample* en,
                                   EnergyParts* parts) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  // The totals are summed element by element, the parts apart (so the
  // parts' sums check the totals, and the totals are those of a run
  // without parts, bit for bit).
  size_t cable = 0;
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    const auto qe = q.segment<kN>(e.first_coord);
    const auto ve = qdot.segment<kN>(e.first_coord);
    // T = 1/2 ve^T (mbar (x) I_D) ve, from the element's 4 x 4 scalar mass
    // matrix (not its full mass matrix, rebuilt by quadrature each call).
    double kinetic = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        kinetic += e.mbar(a, b) * ve.template segment<D>(D * a).dot(ve.template segment<D>(D * b));
    kinetic *= 0.5;
    const auto se = e.element.StrainEnergy(qe);
    en->kinetic += kinetic;
    en->axial += se.axial;
    en->bending += se.bending;
    if (seabed_) en->contact += seabed_->Energy<D>(qe, e.element.length());
    if (!sheaves_.empty()) {
      for (uint64_t bits = sheave_mask_[k]; bits != 0; bits &= bits - 1) {
        const Sheave& wheel = sheaves_[std::countr_zero(bits)];
        if (wheel.body() >= 0) {
          Eigen::Matrix<double, 5 * D, 1> x;
          x << qe, q.segment<D>(bodies_[wheel.body()].coord);
          en->contact += wheel.AddPotentialOnBody<D>(x, e.element.length(), nullptr, nullptr);
        } else {
          en->contact += wheel.Energy<D>(qe, e.element.length());
        }
      }
    }
    if (parts == nullptr) continue;
    while (static_cast<int>(k) >= cable_element_begin_[cable + 1]) ++cable;
    PartEnergy* part = &parts->cables[cable];
    part->kinetic += kinetic;
    part->axial += se.axial;
    part->bending += se.bending;
    // Element gravity is exactly -Q_g . e (MODEL.md section 2).
    part->gravity -= e.gravity.dot(qe);
  }
}

EnergySample MultibodyModel::Energy(const VectorXd& q, const VectorXd& qdot, double load_factor,
                                    EnergyParts* parts) const {
  EnergySample en;
  if (parts != nullptr) {
    parts->cables.assign(cable_names_.size(), PartEnergy());
    parts->bodies.assign(bodies_.size(), PartEnergy());
  }
  if (dim_ == 2) {
    ElementEnergy<2>(q, qdot, &en, parts);
  } else {
    ElementEnergy<3>(q, qdot, &en, parts);
  }
  const int D = dim_;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const BodyData& b = bodies_[i];
    double translation = 0.5 * b.mass * qdot.segment(b.coord, D).squaredNorm();
    if (b.has_added_mass) {
      for (int i = 0; i < D; ++i)
        for (int k = 0; k < D; ++k)
          translation += 0.5 * b.added_mass(i, k) * qdot(b.coord + i) * qdot(b.coord + k);
    }
    en.kinetic += translation;
    double kinetic = translation;
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k) {
      const double rotation = 0.5 * b.jbar(k) * qdot.segment(b.coord + D + D * k, D).squaredNorm();
      en.kinetic += rotation;
      kinetic += rotation;
    }
    if (parts != nullptr) {
      PartEnergy& part = parts->bodies[i];
      part.kinetic = kinetic;
      part.gravity = -load_factor * b.mass * gravity_.head(D).dot(q.segment(b.coord, D));
    }
  }
  // Gravity and point loads are constant forces on q: V = -F . q. Element
  // gravity is exactly -Q_g . e (MODEL.md section 2).
  en.potential = -load_factor * constant_force_.dot(q);
  // Torques, time-varying loads, moving supports: their work so far
  // (AccumulateExternalWork).
  en.potential -= external_work_;
  // Contributors' stored energies, each in its bucket (the loads' part or
  // contact).
  double loads_energy = 0;
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, load_factor);
    for (const auto& c : contributors_) {
      const double u = c->StoredEnergy(state);
      if (c->bucket() == EnergyBucket::kContact) {
        en.contact += u;
      } else {
        en.potential += u;
        loads_energy += u;
      }
    }
  }
  en.total = en.kinetic + en.potential + en.axial + en.bending + en.contact;
  if (parts != nullptr) {
    // The element gravity above is at load factor 1 (statics scales it).
    for (PartEnergy& part : parts->cables) part.gravity *= load_factor;
    parts->loads = loads_energy - external_work_;
    if (load_force_.size() > 0) parts->loads -= load_factor * load_force_.dot(q);
  }
  return en;
}

void MultibodyModel::AccumulateExternalWork(const VectorXd& q_before, const VectorXd& q_after,
                                            double t_before, double t_after,
                                            const VectorXd& lambda_before,
                                            const VectorXd& lambda_after, double load_factor) {
  // Contributors' work (torques, time-varying loads).
  if (has_step_work_) {
    const StepEnds ends{&q_before, &q_after, t_before, t_after, load_factor};
    for (const auto& c : contributors_) c->AddStepWork(ends, &external_work_);
  }
  // Rheonomic rows' work (moving and turning supports).
  const ConstraintStep step{&q_before, &q_after, t_before, t_after, &lambda_before, &lambda_after};
  for (const ConstraintFamily* f : families_) f->AddStepWork(step, &external_work_);
}

template <int D>
Eigen::Vector3d MultibodyModel::ElementAngularMomentum(const VectorXd& q,
                                                      const VectorXd& qdot) const {
  Vector3d l = Vector3d::Zero();
  for (const ElementData<D>& e : Elements<D>()) {
    for (int a = 0; a < 4; ++a) {
      Vector3d ra = Vector3d::Zero();
      ra.head<D>() = q.segment<D>(e.first_coord + D * a);
      for (int b = 0; b < 4; ++b) {
        Vector3d vb = Vector3d::Zero();
        vb.head<D>() = qdot.segment<D>(e.first_coord + D * b);
        l += e.mbar(a, b) * ra.cross(vb);
      }
    }
  }
  return l;
}

Eigen::Vector3d MultibodyModel::AngularMomentum(const VectorXd& q, const VectorXd& qdot) const {
  Vector3d l = dim_ == 2 ? ElementAngularMomentum<2>(q, qdot) : ElementAngularMomentum<3>(q, qdot);
  const int D = dim_;
  auto vec = [D](const VectorXd& x, int i) {
    Vector3d v = Vector3d::Zero();
    v.head(D) = x.segment(i, D);
    return v;
  };
  for (const BodyData& b : bodies_) {
    l += b.mass * vec(q, b.coord).cross(vec(qdot, b.coord));
    if (D == 2) {
      // Both axes u and perp(u) carry Jb_x + Jb_y = I_z: I_z u x udot.
      l += b.jbar(0) * vec(q, b.coord + 2).cross(vec(qdot, b.coord + 2));
    } else {
      for (int k = 0; k < 3; ++k)
        l += b.jbar(k) * vec(q, b.coord + 3 + 3 * k).cross(vec(qdot, b.coord + 3 + 3 * k));
    }
  }
  return l;
}

template <int D>
Eigen::Vector3d MultibodyModel::CablePositionOf(const VectorXd& q, int cable, double s,
                                                Vector3d* slope) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  Vector3d r = Vector3d::Zero();
  const int begin = cable_element_begin_[cable], end = cable_element_begin_[cable + 1];
  double start = 0;
  for (int k = begin; k < end; ++k) {
    const ElementData<D>& e = elements[k];
    const double l = e.element.length();
    if (s <= start + l || k + 1 == end) {
      const double xi = std::clamp((s - start) / l, 0.0, 1.0);
      r.head<D>() = e.element.Position(q.segment<kN>(e.first_coord), xi);
      if (slope) {
        slope->setZero();
        slope->head<D>() = e.element.Slope(q.segment<kN>(e.first_coord), xi);
      }
      return r;
    }
    start += l;
  }
  return r;
}

Eigen::Vector3d MultibodyModel::CablePosition(const VectorXd& q, int cable, double s,
                                              Vector3d* slope) const {
  return dim_ == 2 ? CablePositionOf<2>(q, cable, s, slope)
                   : CablePositionOf<3>(q, cable, s, slope);
}

void MultibodyModel::NodePositions(const VectorXd& q, std::vector<Vector3d>* out) const {
  out->resize(shape_coord_.size());
  for (size_t k = 0; k < shape_coord_.size(); ++k) {
    Vector3d& r = (*out)[k];
    r.setZero();
    r.head(dim_) = q.segment(shape_coord_[k], dim_);
  }
}

void MultibodyModel::Probes(const VectorXd& q, const VectorXd& qdot, const VectorXd& qddot,
                            std::vector<ProbeSample>* out) const {
  out->resize(probe_names_.size());
  for (size_t p = 0; p < probe_names_.size(); ++p) {
    ProbeSample& s = (*out)[p];
    for (int d = 0; d < 3; ++d) {
      const int r = 3 * static_cast<int>(p) + d;
      double x = probe_const_[r], v = 0, a = 0;
      for (int k = probe_term_begin_[r]; k < probe_term_begin_[r + 1]; ++k) {
        const ProbeTerm& t = probe_terms_[k];
        x += t.coeff * q(t.coord);
        v += t.coeff * qdot(t.coord);
        a += t.coeff * qddot(t.coord);
      }
      s.position_m(d) = x;
      s.velocity_m_s(d) = v;
      s.acceleration_m_s2(d) = a;
    }
  }
}

}  // namespace cablesim

namespace cablesim {

void MultibodyModel::ProbeForces(const VectorXd& q, const VectorXd& lambda,
                                 std::vector<Eigen::Vector3d>* out) const {
  out->resize(force_probes_.size());
  for (size_t k = 0; k < force_probes_.size(); ++k) {
    Eigen::Vector3d& force = (*out)[k];
    force.setZero();
    if (!probe_winch_.empty() && probe_winch_[force_probes_[k]] >= 0) {
      const int w = probe_winch_[force_probes_[k]];
      force = dim_ == 2 ? WinchTension<2>(q, w) : WinchTension<3>(q, w);
      continue;
    }
    for (int d = 0; d < 3; ++d) {
      const int row = probe_force_rows_[force_probes_[k]][d];
      if (row >= 0) force(d) = -lambda(row);
    }
  }
}

}  // namespace cablesim
