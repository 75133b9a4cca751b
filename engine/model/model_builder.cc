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

// Relative tolerance for matching arc lengths to nodes.
constexpr double kSnap = 1e-9;
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

absl::Status ModelBuilder::CheckWinches() const {
  const int num_cables = static_cast<int>(scene_.cables.size());
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene_.cables[c];
    if (!cable.winch.enabled) continue;
    const double len = cable.length_m, tol = kSnap * len;
    if (scene_.solver.analysis == Analysis::kDynamic && scene_.solver.duration_s > 0) {
      // L(t) = len + int_0^t speed on a grid no coarser than the step (at
      // most 100,000 points), the first crossing of 0 refined by bisection.
      const double duration = scene_.solver.duration_s;
      const int n = static_cast<int>(std::min(
          1e5, std::max(100.0, std::ceil(duration / std::max(scene_.solver.step_s, 1e-12)))));
      auto length = [&](double t) { return len + cable.winch.speed.Integral(t); };
      double t_prev = 0;
      for (int i = 1; i <= n; ++i) {
        const double t = duration * i / n;
        if (length(t) > 0) {
          t_prev = t;
          continue;
        }
        double lo = t_prev, hi = t;
        for (int k = 0; k < 60 && hi - lo > 1e-12 * (1 + hi); ++k) {
          const double mid = 0.5 * (lo + hi);
          (length(mid) > 0 ? lo : hi) = mid;
        }
        return absl::InvalidArgumentError(absl::StrFormat(
            "cables[%d].winch.speed: reels in the whole cable: its free length (length + "
            "int speed dt) reaches 0 at t = %.6g s, within solver.duration (%.6g s)",
            c, hi, duration));
      }
    }
    bool held = false;
    for (size_t j = 0; j < scene_.joints.size(); ++j) {
      const JointSpec& joint = scene_.joints[j];
      for (const Attachment* at : {&joint.a, &joint.b}) {
        if (at->cable != c) continue;
        if (joint.type == JointType::kSlide) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "joints[%d]: a sliding joint cannot run on a winch cable (cables[%d].winch)", j, c));
        }
        const Attachment& other = at == &joint.a ? joint.b : joint.a;
        if (std::abs(at->s_m - len) <= tol && other.IsGround()) held = true;
        if (at->s_m > tol && at->s_m < len - tol) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "joints[%d]: a winch cable (cables[%d].winch) takes joints only at its ends (s = 0 "
              "or its length): its mesh moves through the material",
              j, c));
        }
      }
    }
    if (!held) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "cables[%d].winch: the winch holds the cable's last point (s = length): join it to "
          "the ground with a PIN or FIXED joint (with a motion for a moving winch)",
          c));
    }
    for (size_t i = 0; i < scene_.loads.size(); ++i) {
      const Attachment& at = scene_.loads[i].at;
      if (at.cable == c && at.s_m > tol && at.s_m < len - tol) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "loads[%d].at: a winch cable (cables[%d].winch) takes loads only at its ends", i, c));
      }
    }
    for (size_t i = 0; i < scene_.probes.size(); ++i) {
      const Attachment& at = scene_.probes[i].at;
      if (at.cable == c && at.s_m > tol && at.s_m < len - tol) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "probes[%d].at: a winch cable (cables[%d].winch) takes probes only at its ends", i,
            c));
      }
    }
    if (cable.bending_damping_s != 0 || cable.rayleigh_beta_s != 0) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "cables[%d].damping: a winch cable takes axial_time and rayleigh_alpha only (bending "
          "damping on an axially moving mesh is not built)",
          c));
    }
    if (scene_.fluid.density_kg_m3 > 0 || scene_.seabed.enabled) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "cables[%d].winch: a winch cable in a fluid or on a seabed is not modelled (their "
          "loads on an axially moving mesh are not built)",
          c));
    }
    if (scene_.solver.integrator == Integrator::kEnergyMomentum &&
        scene_.solver.analysis == Analysis::kDynamic) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "solver.integrator: ENERGY_MOMENTUM does not take winches (cables[%d].winch): its "
          "energy statement needs a constant mass; use HHT, GENERALIZED_ALPHA or "
          "IMPLICIT_EULER",
          c));
    }
  }
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

  // z0 and v0 by least squares through the map (exact for consistent data).
  m.z0_ = m.Reduce(q0_);
  VectorXd qd0 = VectorXd::Zero(ncoord);
  m.RigidVelocity(q0_, &qd0);
  m.v0_ = m.Reduce(qd0);
}

absl::Status ModelBuilder::CheckIntegratorFits() const {
  if (!TraitsOf(scene_.solver.integrator).is_explicit || scene_.solver.analysis != Analysis::kDynamic)
    return absl::OkStatus();
  const std::string name(IntegratorName(scene_.solver.integrator));
  const MultibodyModel& m = model_;
  if (m.joint_rows_->size() > 0) {
    const JointRows::Row& r = m.joint_rows_->row(0);
    const std::string what = r.joint >= 0
                                 ? absl::StrFormat("joints[%d] is kept as constraint rows", r.joint)
                                 : absl::StrFormat("bodies[%d] has its axes' constraint rows", r.body);
    return absl::InvalidArgumentError(absl::StrFormat(
        "solver.integrator: %s is explicit and integrates unconstrained motion "
        "only, and this scene has %d constraint rows (%s; only joints to fixed ground "
        "points are eliminated): use HHT, GENERALIZED_ALPHA, ENERGY_MOMENTUM or IMPLICIT_EULER",
        name, m.multipliers(), what));
  }
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    if (scene_.cables[c].winch.enabled) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "solver.integrator: %s does not take winches (cables[%d].winch): it "
          "factors the mass matrix once; use HHT, GENERALIZED_ALPHA or IMPLICIT_EULER",
          name, c));
    }
  }
  return absl::OkStatus();
}

template <int D>
void ModelBuilder::BuildElementsOf(std::vector<MultibodyModel::ElementData<D>>* elements) {
  const double extent = q0_.lpNorm<Eigen::Infinity>();  // scene size [m]
  const Eigen::Matrix<double, D, 1> g = scene_.gravity_m_s2.head<D>();
  const std::vector<int>& first_node = mesh_.first_node;
  model_.cable_element_begin_.assign(1, 0);
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    if (Stopped()) return;
    const CableSpec& cable = scene_.cables[c];
    model_.cable_names_.push_back(cable.name);
    const double ea = cable.youngs_modulus_pa * cable.area_m2;
    const double ei = cable.youngs_modulus_pa * cable.second_moment_m4;
    const double mpl = cable.density_kg_m3 * cable.area_m2;
    // In a fluid: buoyancy (the displaced fluid's weight off gravity),
    // isotropic added mass, and the drag factors of AddDrag.
    const double rho_f = scene_.fluid.density_kg_m3;
    const double dh = cable.hydro_diameter_m > 0 ? cable.hydro_diameter_m
                                                 : std::sqrt(4 * cable.area_m2 / kPi);
    const double displaced = rho_f > 0 ? rho_f * kPi * dh * dh / 4 : 0.0;  // [kg/m]
    const double drag_n = 0.5 * rho_f * cable.normal_drag * dh;
    const double drag_t = 0.5 * rho_f * cable.tangential_drag * kPi * dh;
    for (int k = first_node[c]; k + 1 < first_node[c + 1]; ++k) {
      if (mesh_.twin_of[k + 1] == k) continue;  // the two halves of a split node
      const int local = k - first_node[c];
      const double l = mesh_.node_s[c][local + 1] - mesh_.node_s[c][local];
      MultibodyModel::ElementData<D> e;
      e.element = AncfCableElement<D>(l, ea, ei, cable.bending,
                                      AncfCableElement<D>::kDefaultGaussPoints, cable.axial_law);
      // Energy the element can hold from coordinates known to 16 eps
      // (1 + |q0|_inf): a strain of that over l, a curvature of it over l^2.
      const double strain = 16 * std::numeric_limits<double>::epsilon() * (1 + extent) / l;
      model_.energy_roundoff_ += (ea + ei / (l * l)) * l * strain * strain;
      e.first_coord = NodeCoord(k);
      e.mass_per_length = mpl + cable.added_mass * displaced;
      e.gravity = e.element.GravityForce(mpl - displaced, g);
      CableFluidLoad::Element fluid;
      fluid.drag_n = drag_n;
      fluid.drag_t = drag_t;
      // With waves, the flow's inertia: Froude-Krylov plus added mass
      // (WaveLoad).
      if (model_.wave_load_) fluid.fluid_inertia = (1 + cable.added_mass) * displaced;
      fluid_elements_.push_back(fluid);
      CableDamping::Element damping;
      damping.axial_s = cable.axial_damping_s + cable.rayleigh_beta_s;
      damping.bending_s = cable.bending_damping_s + cable.rayleigh_beta_s;
      damping.alpha_1_s = cable.rayleigh_alpha_1_s;
      damping.mass_per_length = e.mass_per_length;
      damping_elements_.push_back(damping);
      const auto me = e.element.MassMatrix(e.mass_per_length);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(D * a, D * b);
      elements->push_back(e);
    }
    model_.cable_element_begin_.push_back(static_cast<int>(elements->size()));
  }
}

void ModelBuilder::BuildElements() {
  // Waves need a fluid, gravity (the vertical and the dispersion) and a
  // depth; SceneFromProto refuses waves without them, naming the field.
  const FluidSpec& fluid = scene_.fluid;
  const double g = scene_.gravity_m_s2.norm();
  if (fluid.waves.any() && fluid.density_kg_m3 > 0 && g > 0 && fluid.water_depth_m > 0) {
    WaveField field(-scene_.gravity_m_s2 / g, fluid.still_water_level_m, fluid.water_depth_m, g,
                    fluid.waves.ramp_s);
    for (const RegularWaveSpec& r : fluid.waves.regular)
      field.AddRegular(r.height_m, r.period_s, r.direction, r.phase_rad);
    for (const JonswapSpec& j : fluid.waves.jonswap)
      field.AddJonswap(j.significant_height_m, j.peak_period_s, j.peak_factor, j.direction,
                       j.components, j.seed);
    model_.wave_load_ = std::make_shared<const WaveLoad>(std::move(field), fluid.current_m_s);
  }
  if (model_.dim_ == 2) {
    BuildElementsOf<2>(&model_.elements2_);
  } else {
    BuildElementsOf<3>(&model_.elements3_);
  }
  // The element terms, in the order they are summed: damping, the fluid's
  // load, the seabed, the sheaves.
  if (auto damping = MakeCableDamping(std::move(damping_elements_))) {
    cable_damping_ = damping.get();
    model_.element_terms_.push_back(std::move(damping));
  }
  if (auto load = MakeCableFluidLoad(std::move(fluid_elements_), model_.wave_load_,
                                     scene_.fluid.current_m_s))
    model_.element_terms_.push_back(std::move(load));
  if (auto bed = MakeCableSeabed(scene_)) {
    model_.cable_seabed_ = bed.get();
    model_.element_terms_.push_back(std::move(bed));
  }
  std::vector<int> body_coord;
  for (const MultibodyModel::BodyData& b : model_.bodies_) body_coord.push_back(b.coord);
  if (auto wheels = MakeSheaves(scene_, model_.cable_element_begin_, body_coord)) {
    model_.sheaves_ = wheels.get();
    model_.element_terms_.push_back(std::move(wheels));
  }
  for (const auto& t : model_.element_terms_) {
    if (t->has_potential()) {
      model_.potential_terms_.push_back(t.get());
      if (t->bucket() == EnergyBucket::kContact) model_.has_element_contact_ = true;
    }
    if (t->dissipates()) {
      model_.dissipative_terms_.push_back(t.get());
      model_.has_damping_ = true;
    }
  }
}

absl::Status ModelBuilder::Contributors() {
  MultibodyModel& m = model_;
  std::vector<int> body_coord(scene_.bodies.size());
  for (size_t b = 0; b < body_coord.size(); ++b) body_coord[b] = BodyCoord(static_cast<int>(b));
  auto add = [&m](std::unique_ptr<ForceContributor> c) {
    if (c->dissipates()) m.has_damping_ = true;
    m.contributors_.push_back(std::move(c));
  };
  // The list's order is the order of summation.
  std::vector<std::array<std::vector<AppliedLoads::Term>, 3>> points(scene_.loads.size());
  for (size_t l = 0; l < points.size(); ++l) {
    if (IsZero(scene_.loads[l].varying_force_n)) continue;
    const LinearVector point = PointOf(scene_.loads[l].at);
    for (int d = 0; d < m.dim_; ++d)
      for (const auto& [i, c] : point[d].terms) points[l][d].push_back({i, c});
  }
  if (auto loads = MakeAppliedLoads(scene_, points, body_coord, m.dim_)) {
    m.has_step_work_ = true;
    add(std::move(loads));
  }
  if (auto damping = MakeBodyDamping(scene_, body_coord, m.dim_)) add(std::move(damping));
  if (auto contact = MakeBodySeabedContact(scene_, body_coord, m.dim_)) {
    m.body_contact_ = contact.get();
    add(std::move(contact));
  }
  if (auto fluid = MakeBodyFluidForces(scene_, body_coord, m.dim_, m.wave_load_ != nullptr)) {
    // The added mass joins the body's mass matrix and kinetic energy.
    for (const BodyFluidLoad& load : fluid->loads()) {
      for (size_t b = 0; b < body_coord.size(); ++b) {
        if (body_coord[b] != load.coord()) continue;
        MultibodyModel::BodyData& data = m.bodies_[b];
        data.added_mass = load.AddedMass(q0_);
        data.has_added_mass = !data.added_mass.isZero(0);
      }
    }
    m.body_fluid_ = fluid.get();
    add(std::move(fluid));
  }
  bool slides = false;
  for (const JointSpec& joint : scene_.joints) slides = slides || joint.type == JointType::kSlide;
  if (slides) {
    std::vector<std::vector<SlidingJoint::Segment>> segments(scene_.cables.size());
    for (size_t cable = 0; cable < segments.size(); ++cable) {
      double s0 = 0;
      for (int k = m.cable_element_begin_[cable]; k < m.cable_element_begin_[cable + 1]; ++k) {
        const int first = m.dim_ == 2 ? m.elements2_[k].first_coord : m.elements3_[k].first_coord;
        const double l =
            m.dim_ == 2 ? m.elements2_[k].element.length() : m.elements3_[k].element.length();
        segments[cable].push_back({first, s0, l});
        s0 += l;
      }
    }
    absl::StatusOr<std::unique_ptr<SlidingJoints>> sliders =
        MakeSlidingJoints(scene_, segments, body_coord, m.dim_, m.body_stride_, q0_);
    if (!sliders.ok()) return sliders.status();
    m.sliders_ = sliders->get();
    add(std::move(*sliders));
  }
  return absl::OkStatus();
}

void ModelBuilder::Winches() {
  MultibodyModel& m = model_;
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    const CableSpec& cable = scene_.cables[c];
    if (!cable.winch.enabled) continue;
    MultibodyModel::WinchData w;
    w.cable = c;
    w.element_begin = m.cable_element_begin_[c];
    w.element_end = m.cable_element_begin_[c + 1];
    w.length0 = w.length = cable.length_m;
    w.speed = cable.winch.speed;
    w.mass_per_length = cable.density_kg_m3 * cable.area_m2;
    w.ea = cable.youngs_modulus_pa * cable.area_m2;
    w.axial_damping_s = cable.axial_damping_s;
    w.alpha_1_s = cable.rayleigh_alpha_1_s;
    m.winches_.push_back(std::move(w));
  }
  if (m.winches_.empty()) return;
  m.winch_slot_.assign(m.elements(), -1);
  int elements = 0;
  for (const MultibodyModel::WinchData& w : m.winches_) {
    for (int k = w.element_begin; k < w.element_end; ++k) {
      m.winch_slot_[k] = elements++;
      // The winch damps the material motion instead (WinchDamping).
      if (cable_damping_) cable_damping_->ClearMaterialDamping(k);
    }
  }
  for (auto* v : {&m.winch_cv_, &m.winch_ce_, &m.winch_mdot_, &m.winch_g_, &m.winch_h_})
    v->assign(elements, Eigen::Matrix4d::Zero());
  m.has_damping_ = true;  // the convective terms ride on DampingForce
}

void ModelBuilder::ConstantForces() {
  MultibodyModel& m = model_;
  const int D = m.dim_;
  m.gravity_ = scene_.gravity_m_s2;
  for (const BodySpec& body : scene_.bodies) m.body_names_.push_back(body.name);
  m.constant_force_ = VectorXd::Zero(q0_.size());
  for (const auto& e : m.elements2_) m.constant_force_.segment<8>(e.first_coord) += e.gravity;
  for (const auto& e : m.elements3_) m.constant_force_.segment<12>(e.first_coord) += e.gravity;
  for (const MultibodyModel::BodyData& b : m.bodies_)
    m.constant_force_.segment(b.coord, D) += b.mass * scene_.gravity_m_s2.head(D);
  // A force F at a point r = sum_i a_i q_i + c does the work F . dr, so its
  // generalized force is sum_d F_d a_{d,i} on q_i (constant: the point is
  // linear in q).
  if (!scene_.loads.empty()) m.load_force_ = VectorXd::Zero(q0_.size());
  auto add_point_force = [&](const LinearVector& point, const Vector3d& force) {
    for (int d = 0; d < D; ++d) {
      for (const auto& [i, v] : point[d].terms) {
        m.constant_force_(i) += v * force(d);
        m.load_force_(i) += v * force(d);
      }
    }
  };
  for (const LoadSpec& load : scene_.loads) {
    const LinearVector point = PointOf(load.at);
    add_point_force(point, load.force_n);
  }
}

void ModelBuilder::Probes() {
  MultibodyModel& m = model_;
  // The cable nodes (output.shape), a split node's second half left out.
  m.shape_ = scene_.output.shape;
  for (const JointSpec& joint : scene_.joints) {
    m.joint_names_.push_back(joint.name);
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
  m.constant_force_base_ = m.constant_force_;
  for (const MultibodyModel::WinchData& w : m.winches_) {
    for (int k = w.element_begin; k < w.element_end; ++k) {
      const MultibodyModel::ElementData<D>& e = elements[k];
      m.constant_force_base_.segment<kN>(e.first_coord) -= e.gravity;
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
  if (absl::Status s = builder.InitialCoordinates(); !s.ok()) return s;
  if (absl::Status s = builder.Joints(); !s.ok()) return s;
  if (absl::Status s = builder.CheckJointsAtStart(); !s.ok()) return s;
  builder.OrderUnknowns();
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
