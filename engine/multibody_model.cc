#include "engine/multibody_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {
namespace {

using Eigen::Vector2d;
using Eigen::VectorXd;

Vector2d Xy(const Eigen::Vector3d& v) { return v.head<2>(); }

Eigen::Matrix2d Rotation(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

// J v: v rotated by +90 degrees (the planar "omega x").
Vector2d Perp(const Vector2d& v) { return Vector2d(-v.y(), v.x()); }

double Cross(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Relative tolerance for matching arc lengths to nodes.
constexpr double kSnap = 1e-9;

// Arc-length position along a polyline: point and unit tangent at `frac`
// of its total length. At an interior vertex the tangent is the average of
// the two segments' directions.
void PolylineAt(const std::vector<Eigen::Vector3d>& pts, double frac, Vector2d* point,
                Vector2d* tangent) {
  std::vector<double> cum(pts.size(), 0.0);
  for (size_t i = 1; i < pts.size(); ++i) cum[i] = cum[i - 1] + (pts[i] - pts[i - 1]).norm();
  const double total = cum.back();
  const double s = std::clamp(frac, 0.0, 1.0) * total;
  size_t seg = 1;
  while (seg + 1 < pts.size() && cum[seg] < s) ++seg;
  const Vector2d a = Xy(pts[seg - 1]), b = Xy(pts[seg]);
  const double len = cum[seg] - cum[seg - 1];
  const double t = len > 0 ? (s - cum[seg - 1]) / len : 0;
  *point = a + t * (b - a);
  Vector2d dir = (b - a).normalized();
  const double tol = kSnap * total;
  if (std::abs(s - cum[seg]) <= tol && seg + 1 < pts.size()) {
    dir = (dir + (Xy(pts[seg + 1]) - b).normalized()).normalized();
  } else if (std::abs(s - cum[seg - 1]) <= tol && seg >= 2) {
    dir = (dir + (a - Xy(pts[seg - 2])).normalized()).normalized();
  }
  *tangent = dir;
}

double PolylineLength(const std::vector<Eigen::Vector3d>& pts) {
  double total = 0;
  for (size_t i = 1; i < pts.size(); ++i) total += (pts[i] - pts[i - 1]).norm();
  return total;
}

std::string SideName(int joint, bool a) { return absl::StrCat("joints[", joint, "].", a ? "a" : "b"); }

}  // namespace

absl::StatusOr<MultibodyModel> MultibodyModel::Build(const Scene& scene) {
  MultibodyModel m;
  const int num_cables = static_cast<int>(scene.cables.size());
  const int num_bodies = static_cast<int>(scene.bodies.size());

  // ---- Mesh: uniform nodes plus a node at every joint, load and probe. ----
  std::vector<std::vector<double>> node_s(num_cables);
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene.cables[c];
    for (int k = 0; k <= cable.elements; ++k)
      node_s[c].push_back(cable.length_m * k / cable.elements);
  }
  auto require = [&](const Attachment& at) {
    if (at.cable >= 0) node_s[at.cable].push_back(at.s_m);
  };
  for (const JointSpec& j : scene.joints) require(j.a), require(j.b);
  for (const LoadSpec& l : scene.loads) require(l.at);
  for (const ProbeSpec& p : scene.probes) require(p.at);
  std::vector<int> first_node(num_cables + 1, 0);
  for (int c = 0; c < num_cables; ++c) {
    auto& s = node_s[c];
    std::sort(s.begin(), s.end());
    const double tol = kSnap * scene.cables[c].length_m;
    std::vector<double> unique;
    for (double v : s)
      if (unique.empty() || v - unique.back() > tol) unique.push_back(v);
    // A point within tol of the end snaps to it.
    unique.back() = scene.cables[c].length_m;
    s = unique;
    first_node[c + 1] = first_node[c] + static_cast<int>(s.size());
  }
  m.num_nodes_ = first_node[num_cables];
  auto node_of = [&](const Attachment& at) {
    const auto& s = node_s[at.cable];
    const double tol = kSnap * scene.cables[at.cable].length_m;
    auto it = std::lower_bound(s.begin(), s.end(), at.s_m - tol);
    return first_node[at.cable] + static_cast<int>(it - s.begin());
  };

  // ---- Full coordinates and their initial values and rates. ----
  const int ncoord = 4 * m.num_nodes_ + 3 * num_bodies;
  const int body0 = 4 * m.num_nodes_;
  VectorXd q0 = VectorXd::Zero(ncoord), qd0 = VectorXd::Zero(ncoord);
  const InitialVelocitySpec& iv = scene.initial_velocity;
  const double omega = iv.angular_rad_s.z();
  auto rigid_velocity = [&](const Vector2d& r) {
    return Vector2d(Xy(iv.linear_m_s) + omega * Perp(r - Xy(iv.origin_m)));
  };
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene.cables[c];
    const double stretch = PolylineLength(cable.points) / cable.length_m;
    for (size_t k = 0; k < node_s[c].size(); ++k) {
      Vector2d p, t;
      PolylineAt(cable.points, node_s[c][k] / cable.length_m, &p, &t);
      const int i = 4 * (first_node[c] + static_cast<int>(k));
      q0.segment<2>(i) = p;
      q0.segment<2>(i + 2) = stretch * t;
      qd0.segment<2>(i) = rigid_velocity(p);
      qd0.segment<2>(i + 2) = omega * Perp(stretch * t);
    }
  }
  for (int b = 0; b < num_bodies; ++b) {
    const BodySpec& body = scene.bodies[b];
    const int i = body0 + 3 * b;
    q0.segment<2>(i) = Xy(body.position_m);
    q0(i + 2) = std::atan2(body.axis.y(), body.axis.x());
    qd0.segment<2>(i) = rigid_velocity(Xy(body.position_m));
    qd0(i + 2) = omega;
    m.bodies_.push_back({i, body.mass_kg, body.inertia_kg_m2.z()});
  }

  // ---- Joints: eliminate ground-fixed coordinates, the rest as rows. ----
  // Per full coordinate: -1 free, -2 fixed; slope coordinates of a clamped
  // node share one unknown along `clamp_dir`.
  std::vector<int> state(ncoord, -1);
  std::vector<Vector2d> clamp_dir(m.num_nodes_, Vector2d::Zero());
  std::vector<bool> clamped(m.num_nodes_, false);
  auto make_side = [&](const Attachment& at) {
    Side s;
    if (at.cable >= 0) {
      s.kind = Side::kNode;
      s.coord = 4 * node_of(at);
    } else if (at.body >= 0) {
      s.kind = Side::kBody;
      s.coord = body0 + 3 * at.body;
      s.local = Xy(at.point_body_m);
    }
    return s;
  };
  auto point_of = [&](const Side& s) -> Vector2d {
    if (s.kind == Side::kNode) return q0.segment<2>(s.coord);
    if (s.kind == Side::kBody)
      return q0.segment<2>(s.coord) + Rotation(q0(s.coord + 2)) * s.local;
    return s.ground;
  };
  auto direction_of = [&](const Side& s) -> Vector2d {
    if (s.kind == Side::kNode) return q0.segment<2>(s.coord + 2).normalized();
    if (s.kind == Side::kBody) return Rotation(q0(s.coord + 2)).col(0);
    return s.ground;
  };
  for (int ji = 0; ji < static_cast<int>(scene.joints.size()); ++ji) {
    const JointSpec& joint = scene.joints[ji];
    Side a = make_side(joint.a), b = make_side(joint.b);
    if (a.kind == Side::kGround) std::swap(a, b);
    if (a.kind == Side::kGround) {
      return absl::InvalidArgumentError(
          absl::StrCat(SideName(ji, true), ": a joint needs a cable or a body on one side"));
    }
    const bool fixed = joint.type == JointType::kFixed;
    if (b.kind == Side::kGround) {
      if (a.kind == Side::kNode) {
        state[a.coord] = state[a.coord + 1] = -2;
        if (fixed) {
          const int node = a.coord / 4;
          clamped[node] = true;
          clamp_dir[node] = direction_of(a);
        }
        continue;
      }
      if (fixed) {
        state[a.coord] = state[a.coord + 1] = state[a.coord + 2] = -2;
        continue;
      }
      if (a.local.norm() == 0) {
        state[a.coord] = state[a.coord + 1] = -2;
        continue;
      }
      b.ground = point_of(a);
      m.rows_.push_back({Row::kPositionX, ji, a, b});
      m.rows_.push_back({Row::kPositionY, ji, a, b});
      continue;
    }
    m.rows_.push_back({Row::kPositionX, ji, a, b});
    m.rows_.push_back({Row::kPositionY, ji, a, b});
    if (fixed) m.rows_.push_back({Row::kParallel, ji, a, b});
  }

  // ---- Unknowns, ordered along the cables; bodies after their first joined node.
  m.c_ = VectorXd::Zero(ncoord);
  m.s_ = VectorXd::Zero(ncoord);
  m.j_.assign(ncoord, -1);
  int next = 0;
  std::vector<bool> body_placed(num_bodies, false);
  auto place_body = [&](int b) {
    if (body_placed[b]) return;
    body_placed[b] = true;
    const int i = body0 + 3 * b;
    for (int k = 0; k < 3; ++k) {
      if (state[i + k] == -2) {
        m.c_(i + k) = q0(i + k);
      } else {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
  };
  std::vector<std::vector<int>> bodies_at_node(m.num_nodes_);
  for (const JointSpec& joint : scene.joints) {
    if (joint.a.cable >= 0 && joint.b.body >= 0) bodies_at_node[node_of(joint.a)].push_back(joint.b.body);
    if (joint.b.cable >= 0 && joint.a.body >= 0) bodies_at_node[node_of(joint.b)].push_back(joint.a.body);
  }
  for (int node = 0; node < m.num_nodes_; ++node) {
    const int i = 4 * node;
    for (int k = 0; k < 2; ++k) {
      if (state[i + k] == -2) {
        m.c_(i + k) = q0(i + k);
      } else {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
    if (clamped[node]) {
      const int alpha = next++;
      for (int k = 0; k < 2; ++k) {
        m.j_[i + 2 + k] = alpha;
        m.s_(i + 2 + k) = clamp_dir[node](k);
      }
    } else {
      for (int k = 2; k < 4; ++k) {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
    for (int b : bodies_at_node[node]) place_body(b);
  }
  for (int b = 0; b < num_bodies; ++b) place_body(b);
  m.dofs_ = next;

  // z0 and v0 by least squares through the map (exact for consistent data).
  m.z0_ = VectorXd::Zero(m.dofs_);
  m.v0_ = VectorXd::Zero(m.dofs_);
  {
    VectorXd norm2 = VectorXd::Zero(m.dofs_);
    for (int i = 0; i < ncoord; ++i) {
      if (m.j_[i] < 0) continue;
      m.z0_(m.j_[i]) += m.s_(i) * q0(i);
      m.v0_(m.j_[i]) += m.s_(i) * qd0(i);
      norm2(m.j_[i]) += m.s_(i) * m.s_(i);
    }
    for (int j = 0; j < m.dofs_; ++j) {
      if (norm2(j) > 0) {
        m.z0_(j) /= norm2(j);
        m.v0_(j) /= norm2(j);
      }
    }
  }

  // ---- Elements. ----
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene.cables[c];
    const double ea = cable.youngs_modulus_pa * cable.area_m2;
    const double ei = cable.youngs_modulus_pa * cable.second_moment_m4;
    const double mpl = cable.density_kg_m3 * cable.area_m2;
    for (int k = first_node[c]; k + 1 < first_node[c + 1]; ++k) {
      const int local = k - first_node[c];
      const double l = node_s[c][local + 1] - node_s[c][local];
      ElementData e;
      e.element = Element(l, ea, ei, cable.bending);
      m.force_roundoff_ = std::max(
          m.force_roundoff_, 100 * std::numeric_limits<double>::epsilon() * std::max(ea, ei / (l * l)));
      e.first_coord = 4 * k;
      e.mass_per_length = mpl;
      e.gravity = e.element.GravityForce(mpl, Xy(scene.gravity_m_s2));
      m.elements_.push_back(e);
    }
  }
  m.gravity_ = Xy(scene.gravity_m_s2);

  // ---- Constant forces: gravity and loads at nodes; body loads kept. ----
  m.constant_force_ = VectorXd::Zero(ncoord);
  for (const ElementData& e : m.elements_) m.constant_force_.segment<8>(e.first_coord) += e.gravity;
  for (const BodyData& b : m.bodies_) m.constant_force_.segment<2>(b.coord) += b.mass * m.gravity_;
  for (const LoadSpec& load : scene.loads) {
    if (load.at.cable >= 0) {
      m.constant_force_.segment<2>(4 * node_of(load.at)) += Xy(load.force_n);
    } else {
      BodyLoad bl;
      bl.body = load.at.body;
      bl.local = Xy(load.at.point_body_m);
      bl.force = Xy(load.force_n);
      bl.torque = load.torque_nm.z();
      m.body_loads_.push_back(bl);
    }
  }

  // ---- Probes. ----
  for (const ProbeSpec& p : scene.probes) {
    ProbeData d;
    if (p.at.cable >= 0) {
      d.coord = 4 * node_of(p.at);
    } else {
      d.body = true;
      d.coord = body0 + 3 * p.at.body;
      d.local = Xy(p.at.point_body_m);
    }
    m.probes_.push_back(d);
    m.probe_names_.push_back(p.name);
  }

  // ---- Initial consistency of the joints kept as constraints. ----
  for (const Row& row : m.rows_) {
    const RowEval ev = m.EvalRow(row, q0);
    if (row.kind != Row::kParallel) {
      const double gap = (point_of(row.a) - (row.b.kind == Side::kGround ? row.b.ground
                                                                          : point_of(row.b)))
                             .norm();
      if (gap > 1e-6) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "joints[%d]: its two points are %.6g m apart at t = 0 (they must coincide)",
            row.joint, gap));
      }
    } else if (std::abs(ev.value) > 1e-6) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "joints[%d]: FIXED needs the cable tangent parallel to the other side's axis at "
          "t = 0 (sine of the angle between them: %.6g)",
          row.joint, ev.value));
    }
  }
  // A row that no unknown can change (both sides held by ground, say a
  // pinned node and a body pinned at its centre of mass) is satisfied by
  // construction, as far as the check above allows, and could never be
  // corrected: it would only make the system singular.
  std::erase_if(m.rows_, [&](const Row& row) {
    const RowEval ev = m.EvalRow(row, q0);
    for (int k = 0; k < ev.n; ++k)
      if (m.j_[ev.idx[k]] >= 0 && m.s_(ev.idx[k]) != 0 && ev.grad(k) != 0) return false;
    return true;
  });

  // ---- Envelope of the Newton matrix on z. ----
  m.envelope_.resize(m.dofs_);
  for (int j = 0; j < m.dofs_; ++j) m.envelope_[j] = j;
  auto couple = [&](const int* idx, int n) {
    int lo = std::numeric_limits<int>::max();
    for (int k = 0; k < n; ++k)
      if (m.j_[idx[k]] >= 0) lo = std::min(lo, m.j_[idx[k]]);
    for (int k = 0; k < n; ++k)
      if (m.j_[idx[k]] >= 0) m.envelope_[m.j_[idx[k]]] = std::min(m.envelope_[m.j_[idx[k]]], lo);
  };
  for (const ElementData& e : m.elements_) {
    int idx[8];
    for (int k = 0; k < 8; ++k) idx[k] = e.first_coord + k;
    couple(idx, 8);
  }
  for (const BodyData& b : m.bodies_) {
    int idx[3] = {b.coord, b.coord + 1, b.coord + 2};
    couple(idx, 3);
  }
  for (const Row& row : m.rows_) {
    const RowEval ev = m.EvalRow(row, q0);
    couple(ev.idx, ev.n);
  }

  // ---- Reduced mass matrix and element scatter tables. ----
  m.mass_.SetPattern(m.envelope_);
  m.element_slots_.resize(64 * m.elements_.size());
  m.element_factors_.resize(64 * m.elements_.size());
  for (size_t k = 0; k < m.elements_.size(); ++k) {
    const ElementData& e = m.elements_[k];
    for (int a = 0; a < 8; ++a) {
      for (int b = 0; b < 8; ++b) {
        const int ia = e.first_coord + a, ib = e.first_coord + b;
        const int ja = m.j_[ia], jb = m.j_[ib];
        // A(ja, jb) with ja > jb is stored once; the diagonal takes every
        // (a, b) with ja == jb (both orders of a != b), as the sum requires.
        const int slot = (ja >= 0 && jb >= 0 && ja >= jb) ? m.mass_.Slot(ja, jb) : -1;
        m.element_slots_[64 * k + 8 * a + b] = slot;
        m.element_factors_[64 * k + 8 * a + b] = slot < 0 ? 0 : m.s_(ia) * m.s_(ib);
      }
    }
    const auto me = e.element.MassMatrix(e.mass_per_length);
    for (int t = 0; t < 64; ++t) {
      const int slot = m.element_slots_[64 * k + t];
      if (slot >= 0) m.mass_.values()[slot] += m.element_factors_[64 * k + t] * me(t / 8, t % 8);
    }
  }
  for (const BodyData& b : m.bodies_) {
    const double diag[3] = {b.mass, b.mass, b.inertia};
    for (int k = 0; k < 3; ++k) {
      const int j = m.j_[b.coord + k];
      if (j >= 0) m.mass_.values()[m.mass_.Slot(j, j)] += diag[k];
    }
  }

  // ---- Constraint Jacobian pattern. ----
  m.jac_pattern_.cols = m.dofs_;
  for (const Row& row : m.rows_) {
    const RowEval ev = m.EvalRow(row, q0);
    for (int k = 0; k < ev.n; ++k) {
      if (m.j_[ev.idx[k]] < 0) continue;
      m.jac_pattern_.col.push_back(m.j_[ev.idx[k]]);
      m.jac_pattern_.value.push_back(0);
    }
    m.jac_pattern_.row_start.push_back(static_cast<int>(m.jac_pattern_.col.size()));
  }
  m.scratch_full_ = VectorXd::Zero(ncoord);
  return m;
}

ModelInfo MultibodyModel::Info() const {
  ModelInfo info;
  info.model = "planar";
  info.coordinates = coordinates();
  info.dofs = dofs();
  info.multipliers = multipliers();
  info.elements = elements();
  info.nodes = nodes();
  info.probe_names = probe_names_;
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

double MultibodyModel::NetForce(const VectorXd& q, double load_factor, VectorXd* f,
                             SkylineLdlt* stiffness, double stiffness_scale) {
  VectorXd& full = scratch_full_;
  full = load_factor * constant_force_;
  for (const BodyLoad& bl : body_loads_) {
    const int c = bodies_[bl.body].coord;
    const Vector2d rp = Rotation(q(c + 2)) * bl.local;
    full.segment<2>(c) += load_factor * bl.force;
    full(c + 2) += load_factor * (bl.force.dot(Perp(rp)) + bl.torque);
    // Q_theta = F . (R' p) has derivative -F . (R p); the stiffness is its
    // negative.
    const int j = j_[c + 2];
    if (stiffness && j >= 0) {
      stiffness->values()[stiffness->Slot(j, j)] +=
          stiffness_scale * load_factor * bl.force.dot(rp);
    }
  }
  double size = full.lpNorm<Eigen::Infinity>();
  Element::Coords fe;
  Element::Matrix ke;
  double* values = stiffness ? stiffness->values() : nullptr;
  for (size_t k = 0; k < elements_.size(); ++k) {
    const ElementData& e = elements_[k];
    fe.setZero();
    if (stiffness) ke.setZero();
    e.element.ElasticForce(q.segment<8>(e.first_coord), &fe, stiffness ? &ke : nullptr);
    full.segment<8>(e.first_coord) -= fe;
    size = std::max(size, fe.lpNorm<Eigen::Infinity>());
    if (!stiffness) continue;
    const int* slots = &element_slots_[64 * k];
    const double* factors = &element_factors_[64 * k];
    const double* kv = ke.data();  // symmetric, so layout order does not matter
    for (int t = 0; t < 64; ++t) {
      if (slots[t] >= 0) values[slots[t]] += stiffness_scale * factors[t] * kv[t];
    }
  }
  f->setZero();
  const int n = coordinates();
  for (int i = 0; i < n; ++i)
    if (j_[i] >= 0) (*f)(j_[i]) += s_(i) * full(i);
  return size;
}

MultibodyModel::SideEval MultibodyModel::EvalPoint(const Side& s, const VectorXd& q) const {
  SideEval ev;
  if (s.kind == Side::kGround) {
    ev.value = s.ground;
  } else if (s.kind == Side::kNode) {
    ev.n = 2;
    ev.idx[0] = s.coord;
    ev.idx[1] = s.coord + 1;
    ev.value = q.segment<2>(s.coord);
    ev.jac(0, 0) = ev.jac(1, 1) = 1;
  } else {
    ev.n = 3;
    for (int k = 0; k < 3; ++k) ev.idx[k] = s.coord + k;
    const Vector2d rp = Rotation(q(s.coord + 2)) * s.local;
    ev.value = q.segment<2>(s.coord) + rp;
    ev.jac(0, 0) = ev.jac(1, 1) = 1;
    ev.jac.col(2) = Perp(rp);
    ev.theta = 2;
    ev.second = -rp;
  }
  return ev;
}

MultibodyModel::SideEval MultibodyModel::EvalDirection(const Side& s, const VectorXd& q) const {
  SideEval ev;
  if (s.kind == Side::kGround) {
    ev.value = s.ground;
  } else if (s.kind == Side::kNode) {
    ev.n = 2;
    ev.idx[0] = s.coord + 2;
    ev.idx[1] = s.coord + 3;
    ev.value = q.segment<2>(s.coord + 2);
    ev.jac(0, 0) = ev.jac(1, 1) = 1;
  } else {
    ev.n = 1;
    ev.idx[0] = s.coord + 2;
    const double th = q(s.coord + 2);
    ev.value = Vector2d(std::cos(th), std::sin(th));
    ev.jac.col(0) = Perp(ev.value);
    ev.theta = 0;
    ev.second = -ev.value;
  }
  return ev;
}

MultibodyModel::RowEval MultibodyModel::EvalRow(const Row& row, const VectorXd& q) const {
  RowEval r;
  const bool parallel = row.kind == Row::kParallel;
  const SideEval a = parallel ? EvalDirection(row.a, q) : EvalPoint(row.a, q);
  const SideEval b = parallel ? EvalDirection(row.b, q) : EvalPoint(row.b, q);
  r.n = a.n + b.n;
  for (int k = 0; k < a.n; ++k) r.idx[k] = a.idx[k];
  for (int k = 0; k < b.n; ++k) r.idx[a.n + k] = b.idx[k];
  if (!parallel) {
    const int d = row.kind == Row::kPositionX ? 0 : 1;
    r.value = a.value(d) - b.value(d);
    for (int k = 0; k < a.n; ++k) r.grad(k) = a.jac(d, k);
    for (int k = 0; k < b.n; ++k) r.grad(a.n + k) = -b.jac(d, k);
    if (a.theta >= 0) r.hess(a.theta, a.theta) = a.second(d);
    if (b.theta >= 0) r.hess(a.n + b.theta, a.n + b.theta) = -b.second(d);
    return r;
  }
  // Phi = t_a x t_b.
  r.value = Cross(a.value, b.value);
  const Vector2d ga(b.value.y(), -b.value.x()), gb(-a.value.y(), a.value.x());
  for (int k = 0; k < a.n; ++k) r.grad(k) = ga.dot(a.jac.col(k));
  for (int k = 0; k < b.n; ++k) r.grad(a.n + k) = gb.dot(b.jac.col(k));
  Eigen::Matrix2d cmat;  // d^2 (t_a x t_b) / dt_a dt_b
  cmat << 0, 1, -1, 0;
  for (int i = 0; i < a.n; ++i)
    for (int k = 0; k < b.n; ++k) {
      const double h = a.jac.col(i).dot(cmat * b.jac.col(k));
      r.hess(i, a.n + k) = h;
      r.hess(a.n + k, i) = h;
    }
  if (a.theta >= 0) r.hess(a.theta, a.theta) += ga.dot(a.second);
  if (b.theta >= 0) r.hess(a.n + b.theta, a.n + b.theta) += gb.dot(b.second);
  return r;
}

void MultibodyModel::Constraints(const VectorXd& q, VectorXd* phi, SparseRows* jac) const {
  int slot = 0;
  for (size_t i = 0; i < rows_.size(); ++i) {
    const RowEval ev = EvalRow(rows_[i], q);
    (*phi)(i) = ev.value;
    if (!jac) continue;
    for (int k = 0; k < ev.n; ++k) {
      if (j_[ev.idx[k]] < 0) continue;
      jac->value[slot++] = ev.grad(k) * s_(ev.idx[k]);
    }
  }
}

void MultibodyModel::AddConstraintHessian(const VectorXd& q, const VectorXd& lambda, double scale,
                                       SkylineLdlt* a) const {
  double* values = a->values();
  for (size_t i = 0; i < rows_.size(); ++i) {
    const RowEval ev = EvalRow(rows_[i], q);
    const double f = scale * lambda(i);
    for (int x = 0; x < ev.n; ++x) {
      const int jx = j_[ev.idx[x]];
      if (jx < 0) continue;
      for (int y = 0; y < ev.n; ++y) {
        const int jy = j_[ev.idx[y]];
        if (jy < 0 || jy > jx || ev.hess(x, y) == 0) continue;
        // Pairs with jx == jy from x != y appear twice (x, y) and (y, x):
        // both add, as the quadratic form requires.
        values[a->Slot(jx, jy)] += f * ev.hess(x, y) * s_(ev.idx[x]) * s_(ev.idx[y]);
      }
    }
  }
}

void MultibodyModel::ConstraintGamma(const VectorXd& q, const VectorXd& qdot,
                                  VectorXd* gamma) const {
  for (size_t i = 0; i < rows_.size(); ++i) {
    const RowEval ev = EvalRow(rows_[i], q);
    double acc = 0;
    for (int x = 0; x < ev.n; ++x)
      for (int y = 0; y < ev.n; ++y) acc += qdot(ev.idx[x]) * ev.hess(x, y) * qdot(ev.idx[y]);
    (*gamma)(i) = -acc;
  }
}

EnergySample MultibodyModel::Energy(const VectorXd& q, const VectorXd& qdot,
                                 double load_factor) const {
  EnergySample en;
  for (const ElementData& e : elements_) {
    const auto qe = q.segment<8>(e.first_coord);
    const auto ve = qdot.segment<8>(e.first_coord);
    en.kinetic += 0.5 * ve.dot(e.element.MassMatrix(e.mass_per_length) * ve);
    const Element::Energy se = e.element.StrainEnergy(qe);
    en.axial += se.axial;
    en.bending += se.bending;
  }
  for (const BodyData& b : bodies_) {
    en.kinetic += 0.5 * (b.mass * qdot.segment<2>(b.coord).squaredNorm() +
                         b.inertia * qdot(b.coord + 2) * qdot(b.coord + 2));
  }
  // Gravity and node loads are constant forces: V = -F . q. Element gravity
  // is exactly -Q_g . e (MODEL.md section 2).
  en.potential = -load_factor * constant_force_.dot(q);
  for (const BodyLoad& bl : body_loads_) {
    const int c = bodies_[bl.body].coord;
    const Vector2d p = q.segment<2>(c) + Rotation(q(c + 2)) * bl.local;
    en.potential -= load_factor * (bl.force.dot(p) + bl.torque * q(c + 2));
  }
  en.total = en.kinetic + en.potential + en.axial + en.bending;
  return en;
}

void MultibodyModel::Probes(const VectorXd& q, const VectorXd& qdot, const VectorXd& qddot,
                         std::vector<ProbeSample>* out) const {
  out->resize(probes_.size());
  for (size_t k = 0; k < probes_.size(); ++k) {
    const ProbeData& p = probes_[k];
    ProbeSample& s = (*out)[k];
    Vector2d x, v, a;
    if (!p.body) {
      x = q.segment<2>(p.coord);
      v = qdot.segment<2>(p.coord);
      a = qddot.segment<2>(p.coord);
    } else {
      const Vector2d rp = Rotation(q(p.coord + 2)) * p.local;
      const double w = qdot(p.coord + 2), al = qddot(p.coord + 2);
      x = q.segment<2>(p.coord) + rp;
      v = qdot.segment<2>(p.coord) + w * Perp(rp);
      a = qddot.segment<2>(p.coord) + al * Perp(rp) - w * w * rp;
    }
    s.position_m << x, 0;
    s.velocity_m_s << v, 0;
    s.acceleration_m_s2 << a, 0;
  }
}

}  // namespace cablesim
