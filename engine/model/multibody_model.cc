#include "engine/model/multibody_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "absl/status/status.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/elements/hermite_shape.h"
#include "engine/linear/rounding.h"

namespace cablesim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

}  // namespace

const std::vector<Sheave>& MultibodyModel::sheaves() const {
  static const std::vector<Sheave> kNone;
  return sheaves_ ? sheaves_->wheels() : kNone;
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

void MultibodyModel::AddContributor(std::unique_ptr<ForceContributor> c) {
  if (c->dissipates()) has_damping_ = true;
  if (c->time_dependent()) time_dependent_ = true;
  contributors_.push_back(std::move(c));
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
  info.joint_names = joint_names_;
  info.joint_reaction_values = joint_reaction_values_;
  info.release_joints = release_joints_;
  if (tension_) {
    for (int p : tension_probe_) info.tension_probe_names.push_back(probe_names_[p]);
  }
  info.node_tension = tension_ && shape_;
  info.body_orientation = orientation_;
  if (bending_moment_) {
    for (int p : tension_probe_) info.bending_moment_probe_names.push_back(probe_names_[p]);
  }
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
double MultibodyModel::ElementForces(const VectorXd& q, VectorXd* full, SkylineLdlt* stiffness,
                                     double stiffness_scale, VectorXd* roundoff) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Coords fe, re;
  typename AncfCableElement<D>::Matrix ke;
  double size = 0;
  double* values = stiffness ? stiffness->values() : nullptr;
  // Where terms that couple an element with other coordinates add those.
  ForceOutput coupled{full, roundoff, stiffness, stiffness_scale, Map()};
  // The stop poll once per `chunk` elements, counting their Gauss points
  // (set_stop_poll): a check per element cost 0.5 % on small cables. With
  // element terms (seabed, sheaves) every element asks. A countdown, not a
  // division per element.
  const size_t count = elements.size();
  const size_t chunk = potential_terms_.empty() ? kPollElements : 1;
  size_t until_poll = 0;
  for (size_t k = 0; k < count; ++k) {
    const ElementData<D>& e = elements[k];
    if (until_poll == 0) {
      until_poll = chunk;
      if (StopNow(static_cast<int64_t>(std::min(chunk, count - k)) * e.element.gauss_points())) {
        full->setConstant(std::numeric_limits<double>::quiet_NaN());
        return std::numeric_limits<double>::quiet_NaN();
      }
    }
    --until_poll;
    fe.setZero();
    if (stiffness) ke.setZero();
    if (roundoff) re.setZero();
    e.element.ElasticForce(q.segment<kN>(e.first_coord), &fe, stiffness ? &ke : nullptr,
                           roundoff ? &re : nullptr);
    // Element terms' forces (the seabed's, the sheaves'), like the elastic
    // one, are gradients of energies.
    if (!potential_terms_.empty()) {
      const ElementAt<D> at{e.element, static_cast<int>(k), time_, e.first_coord, &q, nullptr,
                            &coupled};
      for (const ElementTerm* t : potential_terms_)
        t->AddElementPotential(at, q.segment<kN>(e.first_coord), &fe, stiffness ? &ke : nullptr,
                               roundoff ? &re : nullptr);
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
  // Contributors' applied loads (gravity and constant loads first, in one
  // pass, then time-varying loads, torques, body buoyancy), scaled by the
  // load factor.
  if (constant_applied_.size() > 0) {
    full = load_factor * constant_applied_;
  } else {
    full.setZero();
  }
  const ForceState state = StateAt(q, nullptr, load_factor);
  // Rounding of the applied terms: the varying contributors add their own
  // (a term that nearly cancels another in the same entry, a floating
  // body's buoyancy against its weight, leaves its rounding behind), then
  // eps times the sum (torques included, through |full|).
  VectorXd* full_roundoff = nullptr;
  if (roundoff) {
    full_roundoff = &scratch_roundoff_;
    full_roundoff->setZero();
  }
  ForceOutput out{&full, full_roundoff, stiffness, stiffness_scale, Map()};
  for (const ForceContributor* c : varying_applied_) c->AddAppliedLoad(state, &out);
  // The size of the applied terms counts only coordinates that move: a
  // heavy body welded to ground must not loosen the tolerance elsewhere.
  // It is also at least the largest term a varying contributor added
  // (out.size): where buoyancy balances weight the sum is rounding, and
  // measured against the sum alone Newton's residual never looked small
  // (a floating body at its draft, MoorDyn's rod_tests/AddedMass.txt).
  double size = out.size;
  const int n = coordinates();
  for (int i = 0; i < n; ++i)
    if (j_[i] >= 0) size = std::max(size, std::abs(full(i)));
  if (roundoff) *full_roundoff += kEps * full.cwiseAbs();
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
                                      VectorXd* roundoff, double* power,
                                      double position_scale) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Matrix ce, ke;
  const bool position = tangent && position_scale != 0;
  typename AncfCableElement<D>::Coords fe;
  double size = 0;
  double* values = tangent ? tangent->values() : nullptr;
  const bool terms = !element_dissipates_.empty();
  // The velocity tangent ce is read only for Newton's matrix and the
  // rounding bound: without either (the residual alone, DampingPower's
  // power) the terms are not asked for it, which skips their 12 x 12
  // block sums (a third of the OC4 mooring's run time was there).
  const bool velocity_tangent = tangent || roundoff;
  // Where terms that couple an element with other coordinates add those.
  ForceOutput coupled{full, roundoff, tangent, tangent_scale, Map()};
  // Work per element for the stop poll: its Gauss points, each at the
  // builder's cost per point.
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    // One poll per element here: with waves an element's drag can cost a
    // second (thousands of components at each Gauss point).
    if (StopNow(e.element.gauss_points() * damping_point_cost_)) {  // set_stop_poll
      if (full) full->setConstant(std::numeric_limits<double>::quiet_NaN());
      if (power) *power = std::numeric_limits<double>::quiet_NaN();
      return std::numeric_limits<double>::quiet_NaN();
    }
    if (!terms || !element_dissipates_[k]) continue;
    const auto ve = qdot.segment<kN>(e.first_coord);
    // fe: the velocity-dependent force, ce its velocity derivative, summed
    // over the element terms (damping, the fluid's load, the seabed's, the
    // sheaves').
    fe.setZero();
    if (velocity_tangent) ce.setZero();
    if (position) ke.setZero();
    const ElementAt<D> at{e.element,  static_cast<int>(k), time_, e.first_coord, &q, &qdot,
                          &coupled,   power,           position ? &ke : nullptr};
    for (const ElementTerm* t : dissipative_terms_)
      t->AddElementDissipation(at, q.segment<kN>(e.first_coord), ve, &fe,
                               velocity_tangent ? &ce : nullptr);
    if (power) *power -= ve.dot(fe);
    if (full) full->segment<kN>(e.first_coord) += fe;
    size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
    if (roundoff)
      roundoff->segment<kN>(e.first_coord).noalias() +=
          kSumRounding * (ce.cwiseAbs() * ve.cwiseAbs() + fe.cwiseAbs());
    if (!tangent) continue;
    ScatterElementMatrix<kN2>(k, ce.data(), tangent_scale, values);
    if (position) ScatterElementMatrix<kN2>(k, ke.data(), position_scale, values);
  }
  return size;
}

double MultibodyModel::DampingForce(const VectorXd& q, const VectorXd& qdot, VectorXd* f,
                                    SkylineLdlt* tangent, double tangent_scale,
                                    VectorXd* roundoff, double position_scale) {
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
                                              full_roundoff, nullptr, position_scale)
                          : ElementDamping<3>(q, qdot, &full, tangent, tangent_scale,
                                              full_roundoff, nullptr, position_scale);
  // Contributors' velocity-dependent forces.
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, 1.0);
    ForceOutput out{&full, full_roundoff, tangent, tangent_scale, Map()};
    for (const auto& c : contributors_) c->AddDissipative(state, &out);
    size = std::max(size, out.size);
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

template <int D>
double MultibodyModel::ElementAddedMass(const VectorXd& q, const VectorXd& qdd, VectorXd* full,
                                        SkylineLdlt* matrix, double scale) const {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  const auto& elements = Elements<D>();
  typename AncfCableElement<D>::Matrix me;
  typename AncfCableElement<D>::Coords fe;
  double* values = matrix ? matrix->values() : nullptr;
  double size = 0;
  for (size_t k = 0; k < elements.size(); ++k) {
    if (!cable_added_mass_->ActsOn(static_cast<int>(k))) continue;
    const ElementData<D>& e = elements[k];
    fe.setZero();
    if (matrix) me.setZero();
    cable_added_mass_->Add<D>(e.element, static_cast<int>(k), q.segment<kN>(e.first_coord),
                              qdd.segment<kN>(e.first_coord), time_, &fe,
                              matrix ? &me : nullptr);
    full->segment<kN>(e.first_coord) += fe;
    size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
    if (matrix) ScatterElementMatrix<kN2>(static_cast<int>(k), me.data(), scale, values);
  }
  return size;
}

double MultibodyModel::AddedMassCorrection(const VectorXd& q, const VectorXd& zdd, VectorXd* f,
                                           SkylineLdlt* matrix, double scale) {
  if (!cable_added_mass_) return 0;
  // Accelerations map as rates do: qdd = S zdd (c is constant).
  scratch_qdd_.resize(coordinates());
  RateToFull(zdd, &scratch_qdd_);
  VectorXd& full = scratch_added_;
  full.setZero(coordinates());
  const double size = dim_ == 2 ? ElementAddedMass<2>(q, scratch_qdd_, &full, matrix, scale)
                                : ElementAddedMass<3>(q, scratch_qdd_, &full, matrix, scale);
  const int n = coordinates();
  for (int i = 0; i < n; ++i)
    if (j_[i] >= 0) (*f)(j_[i]) += s_(i) * full(i);
  return size;
}

template <int D>
void MultibodyModel::ViscoelasticStrains(const VectorXd& z) {
  VectorXd q(c_.size());  // once per accepted step, viscoelastic scenes only
  ToFull(z, &q);
  visco_strains_.resize(visco_->points());
  double* out = visco_strains_.data();
  for (int k : visco_elements_) {
    const ElementData<D>& e = Elements<D>()[k];
    e.element.AxialStrains(q.segment<4 * D>(e.first_coord), out);
    out += e.element.gauss_points();
  }
}

template <int D>
double MultibodyModel::ViscoelasticPower(const VectorXd& q) const {
  double power = 0;
  int point = 0;
  double strains[GaussRule::kMaxPoints];
  for (int k : visco_elements_) {
    const ElementData<D>& e = Elements<D>()[k];
    e.element.AxialStrains(q.segment<4 * D>(e.first_coord), strains);
    for (int g = 0; g < e.element.gauss_points(); ++g, ++point)
      power += e.element.GaussLength(g) * visco_->DissipatedPower(point, strains[g]);
  }
  return power;
}

void MultibodyModel::StartViscoelastic(const VectorXd& z, double t) {
  if (!visco_) return;
  dim_ == 2 ? ViscoelasticStrains<2>(z) : ViscoelasticStrains<3>(z);
  visco_->Start(visco_strains_, t);
}

template <int D>
double MultibodyModel::ViscoelasticEnergyJump(const std::vector<double>& per_point) const {
  double jump = 0;
  int point = 0;
  for (int k : visco_elements_) {
    const ElementData<D>& e = Elements<D>()[k];
    for (int g = 0; g < e.element.gauss_points(); ++g, ++point)
      jump += e.element.GaussLength(g) * per_point[point];
  }
  return jump;
}

void MultibodyModel::CommitViscoelastic(const VectorXd& z, double t) {
  if (!visco_) return;
  dim_ == 2 ? ViscoelasticStrains<2>(z) : ViscoelasticStrains<3>(z);
  visco_->Commit(visco_strains_, t, &visco_jump_);
  // The mean-load law's change of stored energy with its stiffness
  // (ViscoelasticHistory::Commit), counted as external work.
  const double jump =
      dim_ == 2 ? ViscoelasticEnergyJump<2>(visco_jump_) : ViscoelasticEnergyJump<3>(visco_jump_);
  external_work_ += jump;
  visco_work_ += jump;
}

bool MultibodyModel::AdoptViscoelastic(const MultibodyModel& old) {
  if (!visco_ || !old.visco_ || visco_->points() != old.visco_->points() ||
      visco_elements_ != old.visco_elements_)
    return false;
  *visco_ = *old.visco_;  // the contents: the elements point at visco_
  visco_work_ = old.visco_work_;
  return true;
}

void MultibodyModel::RelaxViscoelastic() {
  if (visco_) visco_->Relax();
}

double MultibodyModel::DampingPower(const VectorXd& q, const VectorXd& qdot) const {
  if (!has_dissipated_power()) return 0;
  double power = 0;  // -Q_d . qdot
  if (visco_) power += dim_ == 2 ? ViscoelasticPower<2>(q) : ViscoelasticPower<3>(q);
  if (!has_damping_) return power;
  if (dim_ == 2) {
    ElementDamping<2>(q, qdot, nullptr, nullptr, 0, nullptr, &power);
  } else {
    ElementDamping<3>(q, qdot, nullptr, nullptr, 0, nullptr, &power);
  }
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, 1.0);
    for (const auto& c : contributors_) c->AddDissipatedPower(state, &power);
  }
  return power;
}

bool MultibodyModel::has_static_friction() const {
  if (!elements2_.empty() || !elements3_.empty()) {
    for (const auto& t : element_terms_)
      if (t->has_static_friction()) return true;
  }
  for (const auto& c : contributors_)
    if (c->has_static_friction()) return true;
  return false;
}

void MultibodyModel::StaticFriction(const VectorXd& q, const VectorXd& q_start, VectorXd* f,
                                    SkylineLdlt* matrix, double scale, VectorXd* roundoff) {
  if (!has_static_friction()) return;
  VectorXd& full = scratch_static_;
  full.setZero(c_.size());
  VectorXd& full_roundoff = scratch_static_roundoff_;
  if (roundoff) full_roundoff.setZero(c_.size());
  auto cables = [&](const auto& elements, auto dim) {
    constexpr int D = decltype(dim)::value, kN = 4 * D, kN2 = kN * kN;
    const ElementTerm* term = nullptr;
    for (const auto& t : element_terms_)
      if (t->has_static_friction()) term = t.get();
    if (term == nullptr) return;
    typename AncfCableElement<D>::Coords fe;
    typename AncfCableElement<D>::Matrix me;
    double* values = matrix ? matrix->values() : nullptr;
    const bool need_matrix = matrix != nullptr || roundoff != nullptr;
    for (size_t k = 0; k < elements.size(); ++k) {
      const ElementData<D>& e = elements[k];
      fe.setZero();
      if (need_matrix) me.setZero();
      const auto ek = q.segment<kN>(e.first_coord);
      const auto e0k = q_start.segment<kN>(e.first_coord);
      term->AddElementStaticFriction(static_cast<int>(k), ek, e0k, e.element.length(), &fe,
                                     need_matrix ? &me : nullptr);
      full.segment<kN>(e.first_coord) += fe;
      if (roundoff) {
        // The regularised law's force turns by mu N over friction_length of
        // displacement, and the displacement e - e0 is known only to a few
        // eps (|e| + |e0|): that times the law's tangent (me) is what
        // rounding leaves in the force, however well Newton converges
        // (up to 1e5 N/m of bed per metre of line at friction_length
        // 1e-5 m: a 10 element buoy mooring's statics stalled 3e-12 of
        // its force scale above a floor that left it out). kSumRounding,
        // not eps: random roundings of a chain's e and e0 moved the force
        // by up to 3.7 eps |me| (|e| + |e0|), as the element's matrix sums
        // its points' tangents with signs (a per-point bound, as the
        // bodies', would be exact; Seabed does not return one yet).
        full_roundoff.segment<kN>(e.first_coord) +=
            kSumRounding * (me.cwiseAbs() * (ek.cwiseAbs() + e0k.cwiseAbs()) + fe.cwiseAbs());
      }
      if (!matrix) continue;
      ScatterElementMatrix<kN2>(k, me.data(), scale, values);
    }
  };
  if (dim_ == 2) {
    cables(elements2_, std::integral_constant<int, 2>());
  } else {
    cables(elements3_, std::integral_constant<int, 3>());
  }
  // Body contact points' friction (BodySeabedContact) adds its own floor.
  ForceOutput out{&full, roundoff ? &full_roundoff : nullptr, matrix, scale, Map()};
  for (const auto& c : contributors_) c->AddStaticFriction(q, q_start, &out);
  const int n = coordinates();
  if (f) {
    for (int i = 0; i < n; ++i)
      if (j_[i] >= 0) (*f)(j_[i]) += s_(i) * full(i);
  }
  if (roundoff) {
    for (int i = 0; i < n; ++i)
      if (j_[i] >= 0) (*roundoff)(j_[i]) += std::abs(s_(i)) * full_roundoff(i);
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
  if (visco_) visco_->SetTime(t);
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

}  // namespace cablesim
