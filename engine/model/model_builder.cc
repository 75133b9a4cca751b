#include "engine/model/model_builder.h"
#include "engine/scene/integrator_traits.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <Eigen/Dense>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/model/model_choice.h"
#include "engine/scene/polyline.h"

namespace cablesim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kPi = std::numbers::pi;

// The body frame at t = 0 from its x axis (scene.h): columns x, y, z.
Eigen::Matrix3d BodyFrame(const Vector3d& axis) {
  const Vector3d x = axis.normalized();
  Vector3d y = Vector3d::UnitZ().cross(x);
  if (y.norm() < 1e-12) y = Vector3d::UnitX().cross(x);
  y.normalize();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = x.cross(y);
  return r;
}

}  // namespace

int ModelBuilder::Mesh::Node(const Attachment& at) const {
  const auto& s = node_s[at.cable];
  auto it = std::lower_bound(s.begin(), s.end(), at.s_m - snap_m[at.cable]);
  return first_node[at.cable] + static_cast<int>(it - s.begin());
}

absl::Status ModelBuilder::ChooseDimension() {
  absl::StatusOr<int> dim = cablesim::ChooseDimension(scene_);
  if (!dim.ok()) return dim.status();
  model_.dim_ = *dim;
  model_.node_stride_ = 2 * *dim;
  model_.body_stride_ = *dim == 2 ? 4 : 12;
  return absl::OkStatus();
}

void ModelBuilder::MeshCables() {
  const int num_cables = static_cast<int>(scene_.cables.size());
  std::vector<std::vector<double>>& node_s = mesh_.node_s;
  node_s.assign(num_cables, {});
  mesh_.snap_m.resize(num_cables);
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene_.cables[c];
    mesh_.snap_m[c] = kSnap * cable.length_m;
    for (int k = 0; k <= cable.elements; ++k)
      node_s[c].push_back(cable.length_m * k / cable.elements);
  }
  auto require = [&](const Attachment& at) {
    if (at.cable >= 0) node_s[at.cable].push_back(at.s_m);
  };
  // A sliding joint needs no node: it moves along the cable.
  for (const JointSpec& j : scene_.joints)
    if (j.type != JointType::kSlide) require(j.a), require(j.b);
  for (const LoadSpec& l : scene_.loads) require(l.at);
  for (const ProbeSpec& p : scene_.probes) require(p.at);
  // Where a bending-free cable kinks (a PIN or a load inside it) and where
  // it must not (a FIXED joint there).
  std::vector<std::vector<double>> kink_s(num_cables), smooth_s(num_cables);
  auto interior = [&](const Attachment& at) {
    if (at.cable < 0 || scene_.cables[at.cable].bending != BendingModel::kNone) return false;
    const double len = scene_.cables[at.cable].length_m, tol = mesh_.snap_m[at.cable];
    return at.s_m > tol && at.s_m < len - tol;
  };
  for (const JointSpec& j : scene_.joints) {
    if (j.type == JointType::kSlide) continue;
    for (const Attachment* at : {&j.a, &j.b}) {
      if (!interior(*at)) continue;
      (j.type == JointType::kPin ? kink_s : smooth_s)[at->cable].push_back(at->s_m);
    }
  }
  for (const LoadSpec& l : scene_.loads)
    if (interior(l.at)) kink_s[l.at.cable].push_back(l.at.s_m);
  mesh_.first_node.assign(num_cables + 1, 0);
  mesh_.twin_of.clear();
  std::vector<int>& twin_of = mesh_.twin_of;
  for (int c = 0; c < num_cables; ++c) {
    if (Stopped()) return;
    auto& s = node_s[c];
    std::sort(s.begin(), s.end());
    const double tol = mesh_.snap_m[c];
    std::vector<double> unique;
    for (double v : s)
      if (unique.empty() || v - unique.back() > tol) unique.push_back(v);
    // A point within tol of the end snaps to it.
    unique.back() = scene_.cables[c].length_m;
    auto near = [&](const std::vector<double>& list, double v) {
      for (double x : list)
        if (std::abs(x - v) <= tol) return true;
      return false;
    };
    s.clear();
    for (double v : unique) {
      s.push_back(v);
      twin_of.push_back(-1);
      if (near(kink_s[c], v) && !near(smooth_s[c], v)) {
        s.push_back(v);
        twin_of.push_back(static_cast<int>(twin_of.size()) - 1);
        ++model_.split_nodes_;
      }
    }
    mesh_.first_node[c + 1] = mesh_.first_node[c] + static_cast<int>(s.size());
  }
  model_.num_nodes_ = mesh_.nodes();
}

int ModelBuilder::BodyCoord(int body) const {
  return model_.node_stride_ * model_.num_nodes_ + model_.body_stride_ * body;
}

absl::Status ModelBuilder::InitialCoordinates() {
  const int D = model_.dim_, num_nodes = model_.num_nodes_;
  const int num_bodies = static_cast<int>(scene_.bodies.size());
  q0_ = VectorXd::Zero(BodyCoord(num_bodies));
  model_.initial_velocity_ = scene_.initial_velocity;
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    if (Stopped()) return absl::OkStatus();
    const CableSpec& cable = scene_.cables[c];
    const double stretch = PolylineLength(cable.points) / cable.length_m;
    for (size_t k = 0; k < mesh_.node_s[c].size(); ++k) {
      const int node = mesh_.first_node[c] + static_cast<int>(k);
      // The two halves of a split node take the tangents of their sides.
      const std::vector<int>& twin_of = mesh_.twin_of;
      const int side = twin_of[node] >= 0                                 ? 1
                       : node + 1 < num_nodes && twin_of[node + 1] == node ? -1
                                                                          : 0;
      Vector3d p, t;
      PolylineAt(cable.points, mesh_.node_s[c][k] / cable.length_m, &p, &t, side);
      const int i = NodeCoord(node);
      const Vector3d slope = stretch * t;
      q0_.segment(i, D) = p.head(D);
      q0_.segment(i + D, D) = slope.head(D);
    }
  }
  frame0_.resize(num_bodies);
  for (int b = 0; b < num_bodies; ++b) {
    const BodySpec& body = scene_.bodies[b];
    const int i = BodyCoord(b);
    frame0_[b] = BodyFrame(body.axis);
    q0_.segment(i, D) = body.position_m.head(D);
    MultibodyModel::BodyData data;
    data.coord = i;
    data.mass = body.mass_kg;
    const Vector3d& inertia = body.inertia_kg_m2;
    if (D == 2) {
      q0_.segment<2>(i + 2) = frame0_[b].col(0).head<2>();
      data.jbar = Vector3d(inertia.z(), 0, 0);
    } else {
      for (int k = 0; k < 3; ++k) {
        q0_.segment<3>(i + 3 + 3 * k) = frame0_[b].col(k);
      }
      data.jbar = Vector3d::Constant(inertia.sum() / 2) - inertia;
      // Relative: a plate's (0.1, 0.2, 0.3) leaves 6e-17 by rounding, a
      // mass matrix singular in all but name.
      if (!(data.jbar.minCoeff() > 1e-12 * inertia.maxCoeff())) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d].inertia: the spatial model needs each principal moment to be less than "
            "the sum of the other two (a real body's mass lies off every axis); got "
            "(%.6g, %.6g, %.6g) kg m^2",
            b, inertia.x(), inertia.y(), inertia.z()));
      }
    }
    model_.bodies_.push_back(data);
  }
  return absl::OkStatus();
}

LinearVector ModelBuilder::NodePosition(int node) const {
  LinearVector v;
  for (int d = 0; d < model_.dim_; ++d) v[d] = LinearForm::Coordinate(NodeCoord(node) + d);
  return v;
}

LinearVector ModelBuilder::NodeSlope(int node) const {
  const int D = model_.dim_;
  LinearVector v;
  for (int d = 0; d < D; ++d) v[d] = LinearForm::Coordinate(NodeCoord(node) + D + d);
  return v;
}

LinearVector ModelBuilder::BodyAxis(int body, int k) const {
  const int i = BodyCoord(body);
  LinearVector v;
  if (model_.dim_ == 3) {
    for (int d = 0; d < 3; ++d) v[d] = LinearForm::Coordinate(i + 3 + 3 * k + d);
  } else if (k == 0) {
    v[0] = LinearForm::Coordinate(i + 2);
    v[1] = LinearForm::Coordinate(i + 3);
  } else if (k == 1) {  // perp(u) = (-u_y, u_x)
    v[0] = LinearForm::Coordinate(i + 3, -1);
    v[1] = LinearForm::Coordinate(i + 2);
  } else {
    v = Constant(Vector3d::UnitZ());
  }
  return v;
}

std::array<LinearVector, 3> ModelBuilder::BodyAxes(int body) const {
  return {BodyAxis(body, 0), BodyAxis(body, 1), BodyAxis(body, 2)};
}

LinearVector ModelBuilder::BodyPoint(int body, const Vector3d& p) const {
  const int D = model_.dim_, i = BodyCoord(body);
  LinearVector v;
  for (int d = 0; d < D; ++d) v[d] = LinearForm::Coordinate(i + d);
  for (int k = 0; k < D; ++k)
    if (p(k) != 0) v = Add(v, BodyAxis(body, k), p(k));
  return v;
}

LinearVector ModelBuilder::PointOf(const Attachment& at) const {
  if (at.cable >= 0) return NodePosition(mesh_.Node(at));
  return BodyPoint(at.body, at.point_body_m);
}

Vector3d ModelBuilder::AtStart(const LinearVector& v) const {
  return Vector3d(v[0].Evaluate(q0_), v[1].Evaluate(q0_), v[2].Evaluate(q0_));
}

void ModelBuilder::OrderUnknowns() {
  MultibodyModel& m = model_;
  const int D = m.dim_, bs = m.body_stride_, ncoord = static_cast<int>(q0_.size());
  const int num_bodies = static_cast<int>(scene_.bodies.size());
  const std::vector<bool>& grounded = elimination_.grounded;
  m.c_ = VectorXd::Zero(ncoord);
  m.s_ = VectorXd::Zero(ncoord);
  m.j_.assign(ncoord, -1);
  int next = 0;
  std::vector<bool> body_placed(num_bodies, false);
  auto place_body = [&](int b) {
    if (body_placed[b]) return;
    body_placed[b] = true;
    const int i = BodyCoord(b);
    for (int k = 0; k < bs; ++k) {
      if (grounded[i + k]) {
        m.c_(i + k) = q0_(i + k);
      } else {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
  };
  std::vector<std::vector<int>> bodies_at_node(m.num_nodes_);
  for (const JointSpec& joint : scene_.joints) {
    // A slider's body goes last (SlidingJoint: a bordered band).
    if (joint.type == JointType::kSlide) continue;
    if (joint.a.cable >= 0 && joint.b.body >= 0)
      bodies_at_node[mesh_.Node(joint.a)].push_back(joint.b.body);
    if (joint.b.cable >= 0 && joint.a.body >= 0)
      bodies_at_node[mesh_.Node(joint.b)].push_back(joint.a.body);
  }
  for (int node = 0; node < m.num_nodes_; ++node) {
    if (node % 65536 == 0 && Stopped()) return;
    const int i = NodeCoord(node);
    const int twin = mesh_.twin_of[node];
    for (int k = 0; k < D; ++k) {
      if (twin >= 0) {
        const int t = NodeCoord(twin) + k;
        m.j_[i + k] = m.j_[t];
        m.s_(i + k) = m.s_(t);
        m.c_(i + k) = m.c_(t);
      } else if (grounded[i + k]) {
        m.c_(i + k) = q0_(i + k);
      } else {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
    if (elimination_.clamped[node]) {
      const int alpha = next++;
      for (int k = 0; k < D; ++k) {
        m.j_[i + D + k] = alpha;
        m.s_(i + D + k) = elimination_.clamp_dir[node](k);
      }
    } else {
      for (int k = D; k < 2 * D; ++k) {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
    for (int b : bodies_at_node[node]) place_body(b);
  }
  for (int b = 0; b < num_bodies; ++b) place_body(b);
  m.dofs_ = next;
  if (Stopped()) return;

  // z0 and v0 by least squares through the map (exact for consistent data).
  // Each of the three passes takes 0.3 s on 2 million elements (most of it
  // first touching the new vectors' pages): the stop is asked between them.
  m.z0_ = m.Reduce(q0_);
  if (Stopped()) return;
  VectorXd qd0(ncoord);
  m.RigidVelocity(q0_, &qd0);
  if (Stopped()) return;
  m.v0_ = m.Reduce(qd0);
}

absl::Status ModelBuilder::CheckIntegratorFits() const {
  // What the integrator takes is read from its traits (integrator_traits.h),
  // and so are the alternatives the messages offer.
  const IntegratorTraits& traits = TraitsOf(scene_.solver.integrator);
  if (scene_.solver.analysis != Analysis::kDynamic) return absl::OkStatus();
  const std::string name(traits.name);
  const MultibodyModel& m = model_;
  if (!traits.takes_constraint_rows && m.joint_rows_->size() > 0) {
    const JointRows::Row& r = m.joint_rows_->row(0);
    const std::string what = r.joint >= 0
                                 ? absl::StrFormat("joints[%d] is kept as constraint rows", r.joint)
                                 : absl::StrFormat("bodies[%d] has its axes' constraint rows", r.body);
    return absl::InvalidArgumentError(absl::StrFormat(
        "solver.integrator: %s is explicit and integrates unconstrained motion "
        "only, and this scene has %d constraint rows (%s; only joints to fixed ground "
        "points are eliminated): use %s",
        name, m.multipliers(), what,
        IntegratorNames([](const IntegratorTraits& t) { return t.takes_constraint_rows; })));
  }
  // The cables' added mass beyond the constant mass matrix
  // (CableAddedMass) joins the residual of the steppers that solve for
  // accelerations: the alpha family.
  if (!traits.has_rho_infinity && !scene_.solver.auto_integrator &&
      scene_.fluid.density_kg_m3 > 0) {
    for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
      const CableSpec& cable = scene_.cables[c];
      std::string why;
      if (cable.has_axial_added_mass && cable.axial_added_mass != cable.added_mass) {
        why = absl::StrFormat("cables[%d].hydrodynamics.axial_added_mass differs from its "
                              "added_mass",
                              c);
      } else if (cable.tip_added_mass_kg[0] != 0 || cable.tip_added_mass_kg[1] != 0) {
        why = absl::StrFormat("cables[%d].hydrodynamics.%s.added_mass acts along the tangent", c,
                              cable.tip_added_mass_kg[0] != 0 ? "start_tip" : "end_tip");
      } else if (scene_.fluid.free_surface && cable.added_mass != 0) {
        why = absl::StrFormat("fluid.free_surface takes cables[%d]'s added mass off above the "
                              "surface",
                              c);
      }
      if (!why.empty()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "solver.integrator: %s does not take an added mass that depends on the line's "
            "direction or position (%s): use %s",
            name, why,
            IntegratorNames([](const IntegratorTraits& t) { return t.has_rho_infinity; })));
      }
    }
  }
  if (traits.takes_winches) return absl::OkStatus();
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    if (scene_.cables[c].winch.enabled) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "solver.integrator: %s does not take winches (cables[%d].winch): %s; use %s", name, c,
          traits.is_explicit ? "it factors the mass matrix once"
                             : "its energy statement needs a constant mass",
          IntegratorNames([](const IntegratorTraits& t) { return t.takes_winches; })));
    }
  }
  return absl::OkStatus();
}

void ModelBuilder::Probes() {
  MultibodyModel& m = model_;
  // The cable nodes (output.shape), a split node's second half left out.
  m.shape_ = scene_.output.shape;
  for (size_t j = 0; j < scene_.joints.size(); ++j) {
    const JointSpec& joint = scene_.joints[j];
    m.joint_names_.push_back(joint.name);
    if (joint.HasRelease()) {
      m.release_joints_.push_back(static_cast<int>(j));
      m.joint_released_.push_back(joint.released ? 1.0 : 0.0);
    }
    if (!scene_.output.reactions) continue;
    m.joint_reaction_values_.push_back(joint.type == JointType::kSlide   ? 0
                                       : joint.type == JointType::kFixed ? 6
                                                                         : 3);
  }
  for (size_t c = 0; c + 1 < mesh_.first_node.size(); ++c) {
    int count = 0;
    for (int k = mesh_.first_node[c]; k < mesh_.first_node[c + 1]; ++k) {
      if (mesh_.twin_of[k] >= 0) continue;
      m.shape_coord_.push_back(NodeCoord(k));
      m.node_s_.push_back(mesh_.node_s[c][k - mesh_.first_node[c]]);
      ++count;
    }
    m.cable_nodes_.push_back(count);
    m.node_cable_.insert(m.node_cable_.end(), count, static_cast<int>(c));
  }
  m.tension_ = scene_.output.tension;
  m.bending_moment_ = scene_.output.bending_moment;
  m.orientation_ = scene_.output.orientation;
  // The probes on a cable, for their tension and bending moment.
  if (m.tension_ || m.bending_moment_) {
    for (const CableSpec& cable : scene_.cables) {
      m.cable_ea_.push_back(cable.youngs_modulus_pa * cable.area_m2);
      m.cable_engineering_.push_back(cable.axial_law == AxialLaw::kEngineering);
    }
    for (size_t p = 0; p < scene_.probes.size(); ++p) {
      const Attachment& at = scene_.probes[p].at;
      if (at.cable < 0) continue;
      m.tension_probe_.push_back(static_cast<int>(p));
      m.tension_cable_.push_back(at.cable);
      m.tension_s_.push_back(at.s_m);
    }
  }
  m.probe_term_begin_.push_back(0);
  for (const ProbeSpec& p : scene_.probes) {
    const LinearVector point = PointOf(p.at);
    for (int d = 0; d < 3; ++d) {
      for (const auto& [i, v] : point[d].terms) m.probe_terms_.push_back({i, v});
      m.probe_term_begin_.push_back(static_cast<int>(m.probe_terms_.size()));
      m.probe_const_.push_back(point[d].c);
    }
    m.probe_names_.push_back(p.name);
  }
  // Probes placed where a moving support holds its cable or body report
  // the support's force (its rows' multipliers).
  m.probe_force_rows_.assign(scene_.probes.size(), {-1, -1, -1});
  for (size_t p = 0; p < scene_.probes.size(); ++p) {
    const Attachment& at = scene_.probes[p].at;
    bool found = false;
    const std::vector<PrescribedMotion::MovingRow> none;
    for (const PrescribedMotion::MovingRow& row : m.motion_ ? m.motion_->moving() : none) {
      const JointSpec& joint = scene_.joints[row.joint];
      const Attachment& held = joint.a.IsGround() ? joint.b : joint.a;
      const bool same = at.cable >= 0 ? held.cable == at.cable && mesh_.Node(held) == mesh_.Node(at)
                                      : held.body == at.body && held.body >= 0 &&
                                            (held.point_body_m - at.point_body_m).norm() <= 1e-12;
      if (!same) continue;
      m.probe_force_rows_[p][row.axis] = row.row;
      found = true;
    }
    // A probe at a winch's end reports the line tension.
    for (int w = 0; w < static_cast<int>(m.winches_.size()); ++w) {
      const CableSpec& cable = scene_.cables[m.winches_[w].cable];
      if (at.cable != m.winches_[w].cable ||
          std::abs(at.s_m - cable.length_m) > kSnap * cable.length_m)
        continue;
      if (m.probe_winch_.empty()) m.probe_winch_.assign(scene_.probes.size(), -1);
      m.probe_winch_[p] = w;
      found = true;
    }
    if (found) m.force_probes_.push_back(static_cast<int>(p));
  }
}

template <int D>
void ModelBuilder::WinchBases(const std::vector<MultibodyModel::ElementData<D>>& elements) {
  MultibodyModel& m = model_;
  constexpr int kN = 4 * D, kN2 = kN * kN;
  m.mass_base_.assign(m.mass_.values(), m.mass_.values() + m.mass_.stored());
  for (const MultibodyModel::WinchData& w : m.winches_) {
    for (int k = w.element_begin; k < w.element_end; ++k) {
      const MultibodyModel::ElementData<D>& e = elements[k];
      const auto me = e.element.MassMatrix(e.mass_per_length);
      for (int t = 0; t < kN2; ++t) {
        const int slot = m.element_slots_[kN2 * k + t];
        if (slot >= 0) m.mass_base_[slot] -= m.element_factors_[kN2 * k + t] * me(t / kN, t % kN);
      }
    }
  }
}

MultibodyModel ModelBuilder::Finish() {
  model_.scratch_full_ = VectorXd::Zero(q0_.size());
  model_.scratch_roundoff_ = VectorXd::Zero(q0_.size());
  // The winches' contributor, last in the list.
  if (!model_.winches_.empty()) {
    if (model_.dim_ == 2) {
      WinchContributor(model_.elements2_);
    } else {
      WinchContributor(model_.elements3_);
    }
  }
  // Constant applied loads summed once (NetForce starts from them); the
  // others called in the step loop, in the list's order. The constant ones
  // come first in the list (gravity and point loads), so the order of the
  // sum is unchanged.
  model_.constant_applied_.resize(0);
  model_.varying_applied_.clear();
  for (const auto& c : model_.contributors_) {
    if (const Eigen::VectorXd* f = c->ConstantAppliedLoad()) {
      if (model_.constant_applied_.size() == 0) {
        model_.constant_applied_ = *f;
      } else {
        model_.constant_applied_ += *f;
      }
    } else {
      model_.varying_applied_.push_back(c.get());
    }
  }
  model_.time_dependent_ = false;
  for (const ConstraintFamily* f : model_.families_)
    if (f->time_dependent()) model_.time_dependent_ = true;
  for (const auto& c : model_.contributors_)
    if (c->time_dependent()) model_.time_dependent_ = true;
  if (!model_.winches_.empty()) {
    model_.time_dependent_ = true;
    if (model_.dim_ == 2) {
      WinchBases(model_.elements2_);
    } else {
      WinchBases(model_.elements3_);
    }
  }
  model_.SetTime(0);
  // Per element, whether a dissipative term acts on it (after the winches
  // cleared their cables' damping).
  if (!model_.dissipative_terms_.empty()) {
    model_.element_dissipates_.assign(model_.elements(), 0);
    for (int k = 0; k < model_.elements(); ++k)
      for (const ElementTerm* t : model_.dissipative_terms_)
        if (t->DissipatesOn(k)) model_.element_dissipates_[k] = 1;
  }
  if (model_.has_damping_) {
    model_.scratch_damping_ = VectorXd::Zero(q0_.size());
    model_.scratch_damping_roundoff_ = VectorXd::Zero(q0_.size());
  }
  // The mass matrix is multiplied at every residual: only its non-zeros.
  model_.mass_.CompressForMultiply();
  model_.ProjectInitialVelocity();
  return std::move(model_);
}

namespace {
std::atomic<int64_t> builds_started{0};
}  // namespace

int64_t MultibodyModel::BuildsStarted() { return builds_started.load(std::memory_order_relaxed); }

// MultibodyModel::Build is defined here, beside the steps it runs, so that
// the model's own file does not need the builder (the builder needs the
// model; not the other way round).
absl::StatusOr<MultibodyModel> MultibodyModel::Build(const Scene& scene,
                                                    const std::function<bool()>& should_stop) {
  builds_started.fetch_add(1, std::memory_order_relaxed);
  // The steps, what each computes and why, are in model_builder.h.
  ModelBuilder builder(scene, should_stop);
  const absl::Status stopped =
      absl::CancelledError("stopped by the caller while building the model");
  if (absl::Status s = builder.ChooseDimension(); !s.ok()) return s;
  if (absl::Status s = builder.CheckWinches(); !s.ok()) return s;
  builder.MeshCables();
  if (builder.Stopped()) return stopped;
  if (absl::Status s = builder.InitialCoordinates(); !s.ok()) return s;
  if (builder.Stopped()) return stopped;
  if (absl::Status s = builder.Joints(); !s.ok()) return s;
  if (builder.Stopped()) return stopped;
  if (absl::Status s = builder.CheckJointsAtStart(); !s.ok()) return s;
  builder.OrderUnknowns();
  if (builder.Stopped()) return stopped;
  builder.KeepMovableRows();
  if (absl::Status s = builder.CheckMovingRows(); !s.ok()) return s;
  if (absl::Status s = builder.CheckIntegratorFits(); !s.ok()) return s;
  if (builder.Stopped()) return stopped;
  builder.BuildElements();
  if (builder.Stopped()) return stopped;
  if (absl::Status s = builder.Contributors(); !s.ok()) return s;
  builder.Winches();
  builder.ConstantForces();
  builder.Probes();
  builder.EnvelopeAndMass();
  if (builder.Stopped()) return stopped;
  builder.ConstraintPattern();
  return builder.Finish();
}

}  // namespace cablesim
