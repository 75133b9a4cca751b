#include "engine/multibody_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "engine/model_choice.h"

namespace cablesim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

// Relative tolerance for matching arc lengths to nodes.
constexpr double kSnap = 1e-9;

// Arc-length position along a polyline: point and unit tangent at `frac`
// of its total length. At an interior vertex the tangent is the average of
// the two segments' directions (side 0), or the incoming (side -1) or
// outgoing (side +1) segment's.
void PolylineAt(const std::vector<Vector3d>& pts, double frac, Vector3d* point,
                Vector3d* tangent, int side = 0) {
  std::vector<double> cum(pts.size(), 0.0);
  for (size_t i = 1; i < pts.size(); ++i) cum[i] = cum[i - 1] + (pts[i] - pts[i - 1]).norm();
  const double total = cum.back();
  const double s = std::clamp(frac, 0.0, 1.0) * total;
  size_t seg = 1;
  while (seg + 1 < pts.size() && cum[seg] < s) ++seg;
  const Vector3d a = pts[seg - 1], b = pts[seg];
  const double len = cum[seg] - cum[seg - 1];
  const double t = len > 0 ? (s - cum[seg - 1]) / len : 0;
  *point = a + t * (b - a);
  Vector3d dir = (b - a).normalized();
  const double tol = kSnap * total;
  if (std::abs(s - cum[seg]) <= tol && seg + 1 < pts.size()) {
    const Vector3d out = (pts[seg + 1] - b).normalized();
    dir = side < 0 ? dir : side > 0 ? out : (dir + out).normalized();
  } else if (std::abs(s - cum[seg - 1]) <= tol && seg >= 2) {
    const Vector3d in = (a - pts[seg - 2]).normalized();
    dir = side > 0 ? dir : side < 0 ? in : (dir + in).normalized();
  }
  *tangent = dir;
}

double PolylineLength(const std::vector<Vector3d>& pts) {
  double total = 0;
  for (size_t i = 1; i < pts.size(); ++i) total += (pts[i] - pts[i - 1]).norm();
  return total;
}

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

LinearVector Constant(const Vector3d& v) {
  return {LinearForm::Constant(v.x()), LinearForm::Constant(v.y()), LinearForm::Constant(v.z())};
}

LinearVector Combination(const std::vector<std::pair<double, LinearVector>>& terms) {
  LinearVector r;
  for (const auto& [s, v] : terms) r = Add(r, v, s);
  return r;
}

}  // namespace

void MultibodyModel::AddRow(const QuadraticForm& f, Row::Kind kind, int joint, int body) {
  Row row;
  row.kind = kind;
  row.joint = joint;
  row.body = body;
  row.c = f.c;
  std::vector<int> coords;
  for (const auto& [i, v] : f.linear)
    if (v != 0) coords.push_back(i);
  for (const auto& [ij, v] : f.quadratic) {
    if (v == 0) continue;
    coords.push_back(ij.first);
    coords.push_back(ij.second);
  }
  std::sort(coords.begin(), coords.end());
  coords.erase(std::unique(coords.begin(), coords.end()), coords.end());
  // The widest row, two welded spatial bodies, touches 24 coordinates.
  assert(static_cast<int>(coords.size()) <= kMaxRowCoords);
  auto local = [&](int i) {
    return static_cast<int>(std::lower_bound(coords.begin(), coords.end(), i) - coords.begin());
  };
  row.coord_begin = static_cast<int>(row_coord_.size());
  row_coord_.insert(row_coord_.end(), coords.begin(), coords.end());
  row.coord_end = static_cast<int>(row_coord_.size());
  row.lin_begin = static_cast<int>(lin_local_.size());
  for (const auto& [i, v] : f.linear) {
    if (v == 0) continue;
    lin_local_.push_back(local(i));
    lin_value_.push_back(v);
  }
  row.lin_end = static_cast<int>(lin_local_.size());
  row.mono_begin = static_cast<int>(mono_a_.size());
  for (const auto& [ij, v] : f.quadratic) {
    if (v == 0) continue;
    mono_a_.push_back(local(ij.first));
    mono_b_.push_back(local(ij.second));
    mono_w_.push_back(v);
  }
  row.mono_end = static_cast<int>(mono_a_.size());
  rows_.push_back(row);
}

double MultibodyModel::RowValue(const Row& row, const VectorXd& q) const {
  const int* coord = &row_coord_[row.coord_begin];
  double acc = row.c;
  for (int k = row.lin_begin; k < row.lin_end; ++k) acc += lin_value_[k] * q(coord[lin_local_[k]]);
  for (int k = row.mono_begin; k < row.mono_end; ++k)
    acc += mono_w_[k] * q(coord[mono_a_[k]]) * q(coord[mono_b_[k]]);
  return acc;
}

void MultibodyModel::RowGradient(const Row& row, const VectorXd& q, double* grad) const {
  const int* coord = &row_coord_[row.coord_begin];
  const int n = row.coord_end - row.coord_begin;
  for (int k = 0; k < n; ++k) grad[k] = 0;
  for (int k = row.lin_begin; k < row.lin_end; ++k) grad[lin_local_[k]] += lin_value_[k];
  for (int k = row.mono_begin; k < row.mono_end; ++k) {
    grad[mono_a_[k]] += mono_w_[k] * q(coord[mono_b_[k]]);
    grad[mono_b_[k]] += mono_w_[k] * q(coord[mono_a_[k]]);
  }
}

absl::StatusOr<MultibodyModel> MultibodyModel::Build(const Scene& scene) {
  MultibodyModel m;
  absl::StatusOr<int> dim = ChooseDimension(scene);
  if (!dim.ok()) return dim.status();
  const int D = *dim;
  m.dim_ = D;
  m.node_stride_ = 2 * D;
  m.body_stride_ = D == 2 ? 4 : 12;
  const int ns = m.node_stride_, bs = m.body_stride_;
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
  // A cable without bending stiffness kinks where a pin or a point load
  // acts inside it: the node there is split in two that share their
  // position unknowns but not their slopes (a C0 node), so the elements on
  // either side meet at an angle. (Slopes continuous across such a node
  // round the kink off over an element and shorten the sag at a hung body
  // at first order in the element length.) Not where a FIXED joint acts:
  // that joint is about the slope.
  std::vector<std::vector<double>> kink_s(num_cables), smooth_s(num_cables);
  auto interior = [&](const Attachment& at) {
    if (at.cable < 0 || scene.cables[at.cable].bending != BendingModel::kNone) return false;
    const double len = scene.cables[at.cable].length_m, tol = kSnap * len;
    return at.s_m > tol && at.s_m < len - tol;
  };
  for (const JointSpec& j : scene.joints) {
    for (const Attachment* at : {&j.a, &j.b}) {
      if (!interior(*at)) continue;
      (j.type == JointType::kPin ? kink_s : smooth_s)[at->cable].push_back(at->s_m);
    }
  }
  for (const LoadSpec& l : scene.loads)
    if (interior(l.at)) kink_s[l.at.cable].push_back(l.at.s_m);
  std::vector<int> first_node(num_cables + 1, 0);
  // Per node: the node whose position it shares (the first of a split
  // pair), or -1.
  std::vector<int> twin_of;
  for (int c = 0; c < num_cables; ++c) {
    auto& s = node_s[c];
    std::sort(s.begin(), s.end());
    const double tol = kSnap * scene.cables[c].length_m;
    std::vector<double> unique;
    for (double v : s)
      if (unique.empty() || v - unique.back() > tol) unique.push_back(v);
    // A point within tol of the end snaps to it.
    unique.back() = scene.cables[c].length_m;
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
        ++m.split_nodes_;
      }
    }
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
  const int ncoord = ns * m.num_nodes_ + bs * num_bodies;
  const int body0 = ns * m.num_nodes_;
  VectorXd q0 = VectorXd::Zero(ncoord);
  m.initial_velocity_ = scene.initial_velocity;
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene.cables[c];
    const double stretch = PolylineLength(cable.points) / cable.length_m;
    for (size_t k = 0; k < node_s[c].size(); ++k) {
      const int node = first_node[c] + static_cast<int>(k);
      // The two halves of a split node take the tangents of their sides.
      const int side = twin_of[node] >= 0                                   ? 1
                       : node + 1 < m.num_nodes_ && twin_of[node + 1] == node ? -1
                                                                              : 0;
      Vector3d p, t;
      PolylineAt(cable.points, node_s[c][k] / cable.length_m, &p, &t, side);
      const int i = ns * node;
      const Vector3d slope = stretch * t;
      q0.segment(i, D) = p.head(D);
      q0.segment(i + D, D) = slope.head(D);
    }
  }
  std::vector<Eigen::Matrix3d> frame0(num_bodies);
  for (int b = 0; b < num_bodies; ++b) {
    const BodySpec& body = scene.bodies[b];
    const int i = body0 + bs * b;
    frame0[b] = BodyFrame(body.axis);
    q0.segment(i, D) = body.position_m.head(D);
    BodyData data;
    data.coord = i;
    data.mass = body.mass_kg;
    const Vector3d& inertia = body.inertia_kg_m2;
    if (D == 2) {
      q0.segment<2>(i + 2) = frame0[b].col(0).head<2>();
      data.jbar = Vector3d(inertia.z(), 0, 0);
    } else {
      for (int k = 0; k < 3; ++k) {
        q0.segment<3>(i + 3 + 3 * k) = frame0[b].col(k);
      }
      data.jbar = Vector3d::Constant(inertia.sum() / 2) - inertia;
      if (!(data.jbar.minCoeff() > 0)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "bodies[%d].inertia: the spatial model needs each principal moment to be less than "
            "the sum of the other two (a real body's mass lies off every axis); got "
            "(%.6g, %.6g, %.6g) kg m^2",
            b, inertia.x(), inertia.y(), inertia.z()));
      }
    }
    m.bodies_.push_back(data);
  }

  // ---- Points and directions as linear forms of q. ----
  auto node_position = [&](int node) {
    LinearVector v;
    for (int d = 0; d < D; ++d) v[d] = LinearForm::Coordinate(ns * node + d);
    return v;
  };
  auto node_slope = [&](int node) {
    LinearVector v;
    for (int d = 0; d < D; ++d) v[d] = LinearForm::Coordinate(ns * node + D + d);
    return v;
  };
  auto body_axis = [&](int b, int k) {
    const int i = body0 + bs * b;
    LinearVector v;
    if (D == 3) {
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
  };
  auto body_point = [&](int b, const Vector3d& p) {
    const int i = body0 + bs * b;
    LinearVector v;
    for (int d = 0; d < D; ++d) v[d] = LinearForm::Coordinate(i + d);
    for (int k = 0; k < D; ++k)
      if (p(k) != 0) v = Add(v, body_axis(b, k), p(k));
    return v;
  };
  auto point_form = [&](const Attachment& at) {
    if (at.cable >= 0) return node_position(node_of(at));
    return body_point(at.body, at.point_body_m);
  };
  auto eval = [&](const LinearVector& v) {
    return Vector3d(v[0].Evaluate(q0), v[1].Evaluate(q0), v[2].Evaluate(q0));
  };
  auto body_frame_forms = [&](int b) {
    return std::array<LinearVector, 3>{body_axis(b, 0), body_axis(b, 1), body_axis(b, 2)};
  };

  // ---- Joints: eliminate ground-fixed coordinates, the rest as rows. ----
  // Per full coordinate: -1 free, -2 fixed; slope coordinates of a clamped
  // node share one unknown along `clamp_dir`.
  std::vector<int> state(ncoord, -1);
  std::vector<Vector3d> clamp_dir(m.num_nodes_, Vector3d::Zero());
  std::vector<bool> clamped(m.num_nodes_, false);
  struct PendingRow {
    QuadraticForm f;
    Row::Kind kind;
    int joint;
    int body;
  };
  std::vector<PendingRow> pending;
  auto side_name = [](int joint, bool a) { return absl::StrCat("joints[", joint, "].", a ? "a" : "b"); };
  for (int ji = 0; ji < static_cast<int>(scene.joints.size()); ++ji) {
    const JointSpec& joint = scene.joints[ji];
    Attachment a = joint.a, b = joint.b;
    if (a.IsGround()) std::swap(a, b);
    if (a.IsGround()) {
      return absl::InvalidArgumentError(
          absl::StrCat(side_name(ji, true), ": a joint needs a cable or a body on one side"));
    }
    const bool fixed = joint.type == JointType::kFixed;
    if (b.IsGround()) {
      if (a.cable >= 0) {
        const int node = node_of(a);
        for (int d = 0; d < D; ++d) state[ns * node + d] = -2;
        if (fixed) {
          clamped[node] = true;
          clamp_dir[node] = eval(node_slope(node)).normalized();
        }
        continue;
      }
      const int i = body0 + bs * a.body;
      if (fixed) {
        for (int k = 0; k < bs; ++k) state[i + k] = -2;
        continue;
      }
      if (a.point_body_m.norm() == 0) {
        for (int d = 0; d < D; ++d) state[i + d] = -2;
        continue;
      }
    }
    // Points coincide: D rows.
    const LinearVector pa = point_form(a);
    const LinearVector pb = b.IsGround() ? Constant(eval(pa)) : point_form(b);
    for (int d = 0; d < D; ++d) {
      LinearForm diff = pa[d];
      diff += pb[d].Scaled(-1);
      pending.push_back({QuadraticForm::FromLinear(diff), Row::kPosition, ji, -1});
    }
    if (!fixed || b.IsGround()) continue;
    if (a.cable < 0 && b.cable >= 0) std::swap(a, b);  // a node first
    if (a.cable >= 0 && b.cable >= 0) {
      // Two cables welded end to end: the slopes stay equal, r_x,b = c r_x,a
      // with c = |r_x,b| / |r_x,a| at t = 0 (1 for a cable split at the
      // joint): D linear rows, of full rank in every configuration. (Rows
      // (r_x,a x r_x,b) . m with fixed m lose rank once the tangent turns
      // onto m.) The stretch on both sides is thereby tied; that is exact for
      // a uniform cable without a point load at the joint.
      const LinearVector ta = node_slope(node_of(a)), tb = node_slope(node_of(b));
      const Vector3d t0a = eval(ta), t0b = eval(tb);
      const double sine = t0a.cross(t0b).norm() / (t0a.norm() * t0b.norm());
      if (!(sine <= 1e-6) || t0a.dot(t0b) <= 0) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "joints[%d]: FIXED between two cables needs their tangents parallel and in the same "
            "sense at t = 0 (sine of the angle between them: %.6g)",
            ji, sine));
      }
      const double ratio = t0b.norm() / t0a.norm();
      for (int d = 0; d < D; ++d) {
        LinearForm diff = tb[d];
        diff += ta[d].Scaled(-ratio);
        pending.push_back({QuadraticForm::FromLinear(diff), Row::kSlope, ji, -1});
      }
    } else if (a.cable >= 0) {
      // A cable tangent along the body's x axis: t . e2 = 0 (and t . e3 = 0).
      const LinearVector t = node_slope(node_of(a));
      pending.push_back({Dot(t, body_axis(b.body, 1), D), Row::kDirection, ji, -1});
      if (D == 3) pending.push_back({Dot(t, body_axis(b.body, 2), D), Row::kDirection, ji, -1});
    } else {
      // Two bodies welded: with B0 = A0 R0 at t = 0, b's axes must stay
      // A R0: e2_b . u_hat = 0, e3_b . u_hat = 0, e3_b . v_hat = 0 where
      // u_hat, v_hat are A R0 e_x, A R0 e_y (planar: the first only).
      const Eigen::Matrix3d r0 = frame0[a.body].transpose() * frame0[b.body];
      const auto ea = body_frame_forms(a.body);
      const LinearVector u_hat =
          Combination({{r0(0, 0), ea[0]}, {r0(1, 0), ea[1]}, {r0(2, 0), ea[2]}});
      const LinearVector v_hat =
          Combination({{r0(0, 1), ea[0]}, {r0(1, 1), ea[1]}, {r0(2, 1), ea[2]}});
      pending.push_back({Dot(body_axis(b.body, 1), u_hat, D), Row::kDirection, ji, -1});
      if (D == 3) {
        pending.push_back({Dot(body_axis(b.body, 2), u_hat, D), Row::kDirection, ji, -1});
        pending.push_back({Dot(body_axis(b.body, 2), v_hat, D), Row::kDirection, ji, -1});
      }
    }
  }
  // Each body's axes stay unit and orthogonal.
  for (int b = 0; b < num_bodies; ++b) {
    const auto e = body_frame_forms(b);
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k) {
      QuadraticForm f = Dot(e[k], e[k], D);
      f.c -= 1;
      pending.push_back({f, Row::kAxes, -1, b});
    }
    for (int k = 0; k < axes; ++k)
      for (int l = k + 1; l < axes; ++l) pending.push_back({Dot(e[k], e[l], D), Row::kAxes, -1, b});
  }

  // ---- Initial consistency of the joints kept as constraints. ----
  {
    std::vector<double> gap2(scene.joints.size(), 0.0);
    for (const PendingRow& r : pending) {
      const double v = r.f.Evaluate(q0);
      if (r.kind == Row::kPosition) gap2[r.joint] += v * v;
      if (r.kind == Row::kDirection && std::abs(v) > 1e-6) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "joints[%d]: FIXED needs the cable tangent parallel to the other side's axis at "
            "t = 0 (sine of the angle between them: %.6g)",
            r.joint, v));
      }
    }
    for (size_t j = 0; j < gap2.size(); ++j) {
      if (std::sqrt(gap2[j]) > 1e-6) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "joints[%d]: its two points are %.6g m apart at t = 0 (they must coincide)",
            static_cast<int>(j), std::sqrt(gap2[j])));
      }
    }
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
    const int i = body0 + bs * b;
    for (int k = 0; k < bs; ++k) {
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
    const int i = ns * node;
    for (int k = 0; k < D; ++k) {
      if (twin_of[node] >= 0) {
        const int t = ns * twin_of[node] + k;
        m.j_[i + k] = m.j_[t];
        m.s_(i + k) = m.s_(t);
        m.c_(i + k) = m.c_(t);
      } else if (state[i + k] == -2) {
        m.c_(i + k) = q0(i + k);
      } else {
        m.j_[i + k] = next++;
        m.s_(i + k) = 1;
      }
    }
    if (clamped[node]) {
      const int alpha = next++;
      for (int k = 0; k < D; ++k) {
        m.j_[i + D + k] = alpha;
        m.s_(i + D + k) = clamp_dir[node](k);
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
  m.z0_ = m.Reduce(q0);
  VectorXd qd0 = VectorXd::Zero(ncoord);
  m.RigidVelocity(q0, &qd0);
  m.v0_ = m.Reduce(qd0);

  // A row that no unknown can change (both sides held by ground, say a
  // pinned node and a body pinned at its centre of mass, or the axes of a
  // welded body) is satisfied by construction, as far as the check above
  // allows, and could never be corrected: it would only make the system
  // singular.
  // The test is the row's gradient on z at t = 0 (the rows are linear or
  // bilinear, so a row with a zero reduced gradient there is one that the
  // elimination has made constant, e.g. a clamped node welded to a body
  // welded to ground).
  for (const PendingRow& r : pending) {
    VectorXd grad = VectorXd::Zero(m.dofs_);
    for (const auto& [i, v] : r.f.linear)
      if (m.j_[i] >= 0) grad(m.j_[i]) += v * m.s_(i);
    for (const auto& [ij, v] : r.f.quadratic) {
      if (m.j_[ij.first] >= 0) grad(m.j_[ij.first]) += v * m.s_(ij.first) * q0(ij.second);
      if (m.j_[ij.second] >= 0) grad(m.j_[ij.second]) += v * m.s_(ij.second) * q0(ij.first);
    }
    if (grad.lpNorm<Eigen::Infinity>() > 1e-12) m.AddRow(r.f, r.kind, r.joint, r.body);
  }

  // ---- Elements. ----
  const double extent = q0.lpNorm<Eigen::Infinity>();  // scene size [m]
  auto build_elements = [&](auto& elements, auto dim_tag) {
    constexpr int kD = decltype(dim_tag)::value;
    const Eigen::Matrix<double, kD, 1> g = scene.gravity_m_s2.head<kD>();
    for (int c = 0; c < num_cables; ++c) {
      const CableSpec& cable = scene.cables[c];
      const double ea = cable.youngs_modulus_pa * cable.area_m2;
      const double ei = cable.youngs_modulus_pa * cable.second_moment_m4;
      const double mpl = cable.density_kg_m3 * cable.area_m2;
      for (int k = first_node[c]; k + 1 < first_node[c + 1]; ++k) {
        if (twin_of[k + 1] == k) continue;  // the two halves of a split node
        const int local = k - first_node[c];
        const double l = node_s[c][local + 1] - node_s[c][local];
        ElementData<kD> e;
        e.element = AncfCableElement<kD>(l, ea, ei, cable.bending);
        // Energy the element can hold from coordinates known to 16 eps
        // (1 + |q0|_inf): a strain of that over l, a curvature of it over l^2.
        const double strain = 16 * std::numeric_limits<double>::epsilon() * (1 + extent) / l;
        m.energy_roundoff_ += (ea + ei / (l * l)) * l * strain * strain;
        e.first_coord = ns * k;
        e.mass_per_length = mpl;
        e.gravity = e.element.GravityForce(mpl, g);
        const auto me = e.element.MassMatrix(mpl);
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(kD * a, kD * b);
        elements.push_back(e);
      }
    }
  };
  if (D == 2) {
    build_elements(m.elements2_, std::integral_constant<int, 2>());
  } else {
    build_elements(m.elements3_, std::integral_constant<int, 3>());
  }

  // ---- Constant forces: gravity and loads at points; torques kept. ----
  m.constant_force_ = VectorXd::Zero(ncoord);
  for (const auto& e : m.elements2_) m.constant_force_.segment<8>(e.first_coord) += e.gravity;
  for (const auto& e : m.elements3_) m.constant_force_.segment<12>(e.first_coord) += e.gravity;
  for (const BodyData& b : m.bodies_)
    m.constant_force_.segment(b.coord, D) += b.mass * scene.gravity_m_s2.head(D);
  // A force F at a point r = sum_i a_i q_i + c does the work F . dr, so its
  // generalized force is sum_d F_d a_{d,i} on q_i (constant: the point is
  // linear in q).
  auto add_point_force = [&](const LinearVector& point, const Vector3d& force) {
    for (int d = 0; d < D; ++d)
      for (const auto& [i, v] : point[d].terms) m.constant_force_(i) += v * force(d);
  };
  for (const LoadSpec& load : scene.loads) {
    add_point_force(point_form(load.at), load.force_n);
    if (load.at.body >= 0 && load.torque_nm.norm() > 0) {
      m.torques_.push_back({load.at.body, load.torque_nm});
    }
  }

  // ---- Probes. ----
  m.probe_term_begin_.push_back(0);
  for (const ProbeSpec& p : scene.probes) {
    const LinearVector point = point_form(p.at);
    for (int d = 0; d < 3; ++d) {
      for (const auto& [i, v] : point[d].terms) m.probe_terms_.push_back({i, v});
      m.probe_term_begin_.push_back(static_cast<int>(m.probe_terms_.size()));
      m.probe_const_.push_back(point[d].c);
    }
    m.probe_names_.push_back(p.name);
  }

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
  {
    std::vector<int> idx(4 * D);
    for (const auto& e : m.elements2_) {
      for (int k = 0; k < 8; ++k) idx[k] = e.first_coord + k;
      couple(idx.data(), 8);
    }
    for (const auto& e : m.elements3_) {
      for (int k = 0; k < 12; ++k) idx[k] = e.first_coord + k;
      couple(idx.data(), 12);
    }
  }
  for (const BodyData& b : m.bodies_) {
    std::vector<int> idx(bs);
    for (int k = 0; k < bs; ++k) idx[k] = b.coord + k;
    couple(idx.data(), bs);
  }
  for (const Row& row : m.rows_) {
    couple(&m.row_coord_[row.coord_begin], row.coord_end - row.coord_begin);
  }

  // ---- Reduced mass matrix and element scatter tables. ----
  m.mass_.SetPattern(m.envelope_);
  if (D == 2) {
    m.SetupElementSlots(m.elements2_);
  } else {
    m.SetupElementSlots(m.elements3_);
  }
  for (const BodyData& b : m.bodies_) {
    for (int k = 0; k < bs; ++k) {
      const int j = m.j_[b.coord + k];
      if (j < 0) continue;
      const double diag = k < D ? b.mass : b.jbar((k - D) / D);
      m.mass_.values()[m.mass_.Slot(j, j)] += m.s_(b.coord + k) * m.s_(b.coord + k) * diag;
    }
  }

  // ---- Constraint Jacobian pattern and Hessian factors. ----
  m.jac_pattern_.cols = m.dofs_;
  for (const Row& row : m.rows_) {
    for (int k = row.coord_begin; k < row.coord_end; ++k) {
      if (m.j_[m.row_coord_[k]] < 0) continue;
      m.jac_pattern_.col.push_back(m.j_[m.row_coord_[k]]);
      m.jac_pattern_.value.push_back(0);
    }
    m.jac_pattern_.row_start.push_back(static_cast<int>(m.jac_pattern_.col.size()));
  }
  m.mono_row_.assign(m.mono_a_.size(), -1);
  m.mono_col_.assign(m.mono_a_.size(), -1);
  m.mono_factor_.assign(m.mono_a_.size(), 0.0);
  for (const Row& row : m.rows_) {
    const int* coord = &m.row_coord_[row.coord_begin];
    for (int k = row.mono_begin; k < row.mono_end; ++k) {
      const int a = coord[m.mono_a_[k]], b = coord[m.mono_b_[k]];
      const int ja = m.j_[a], jb = m.j_[b];
      if (ja < 0 || jb < 0) continue;
      // w q_a q_b has Hessian entries (a, b) and (b, a) equal to w; on z
      // they land on (ja, jb) and (jb, ja): stored once off the diagonal,
      // twice (2 w) on it.
      m.mono_row_[k] = std::max(ja, jb);
      m.mono_col_[k] = std::min(ja, jb);
      m.mono_factor_[k] = m.mono_w_[k] * m.s_(a) * m.s_(b) * (ja == jb ? 2 : 1);
    }
  }
  m.scratch_full_ = VectorXd::Zero(ncoord);
  m.scratch_roundoff_ = VectorXd::Zero(ncoord);
  m.ProjectInitialVelocity();
  return m;
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

template <int D>
void MultibodyModel::SetupElementSlots(const std::vector<ElementData<D>>& elements) {
  constexpr int kN = 4 * D, kN2 = kN * kN;
  element_slots_.resize(kN2 * elements.size());
  element_factors_.resize(kN2 * elements.size());
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    for (int a = 0; a < kN; ++a) {
      for (int b = 0; b < kN; ++b) {
        const int ia = e.first_coord + a, ib = e.first_coord + b;
        const int ja = j_[ia], jb = j_[ib];
        // A(ja, jb) with ja > jb is stored once; the diagonal takes every
        // (a, b) with ja == jb (both orders of a != b), as the sum requires.
        const int slot = (ja >= 0 && jb >= 0 && ja >= jb) ? mass_.Slot(ja, jb) : -1;
        element_slots_[kN2 * k + kN * a + b] = slot;
        element_factors_[kN2 * k + kN * a + b] = slot < 0 ? 0 : s_(ia) * s_(ib);
      }
    }
    const auto me = e.element.MassMatrix(e.mass_per_length);
    for (int t = 0; t < kN2; ++t) {
      const int slot = element_slots_[kN2 * k + t];
      if (slot >= 0) mass_.values()[slot] += element_factors_[kN2 * k + t] * me(t / kN, t % kN);
    }
  }
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
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    fe.setZero();
    if (stiffness) ke.setZero();
    if (roundoff) re.setZero();
    e.element.ElasticForce(q.segment<kN>(e.first_coord), &fe, stiffness ? &ke : nullptr,
                           roundoff ? &re : nullptr);
    full->segment<kN>(e.first_coord) -= fe;
    // The element's own bound, and the rounding of adding it to the node.
    if (roundoff) roundoff->segment<kN>(e.first_coord) += re + kEps * fe.cwiseAbs();
    size = std::max(size, fe.template lpNorm<Eigen::Infinity>());
    if (!stiffness) continue;
    const int* slots = &element_slots_[kN2 * k];
    const double* factors = &element_factors_[kN2 * k];
    const double* kv = ke.data();  // symmetric, so layout order does not matter
    for (int t = 0; t < kN2; ++t) {
      if (slots[t] >= 0) values[slots[t]] += stiffness_scale * factors[t] * kv[t];
    }
  }
  return size;
}

double MultibodyModel::NetForce(const VectorXd& q, double load_factor, VectorXd* f,
                                SkylineLdlt* stiffness, double stiffness_scale,
                                VectorXd* roundoff) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  VectorXd& full = scratch_full_;
  full = load_factor * constant_force_;
  // A torque T on a body: its virtual work T . dphi, with de_k = dphi x e_k,
  // is done by the generalized forces (1/2) T x e_k on the axes (spatial),
  // and T_z perp(u) on u (planar), on the unit, orthogonal axes the
  // constraints keep. Their derivative is skew-symmetric, so the symmetric
  // Newton matrix leaves it out (Newton then converges linearly, at a rate
  // of order h^2 |T| / J, instead of quadratically).
  for (const TorqueLoad& t : torques_) {
    const int c = bodies_[t.body].coord;
    if (dim_ == 2) {
      const double tz = load_factor * t.torque.z();
      full(c + 2) -= tz * q(c + 3);
      full(c + 3) += tz * q(c + 2);
    } else {
      for (int k = 0; k < 3; ++k) {
        const Vector3d e = q.segment<3>(c + 3 + 3 * k);
        full.segment<3>(c + 3 + 3 * k) += 0.5 * load_factor * t.torque.cross(e);
      }
    }
  }
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

void MultibodyModel::Constraints(const VectorXd& q, VectorXd* phi, SparseRows* jac) const {
  int slot = 0;
  double grad[kMaxRowCoords];
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    (*phi)(i) = RowValue(row, q);
    if (!jac) continue;
    RowGradient(row, q, grad);
    for (int k = row.coord_begin; k < row.coord_end; ++k) {
      const int coord = row_coord_[k];
      if (j_[coord] < 0) continue;
      jac->value[slot++] = grad[k - row.coord_begin] * s_(coord);
    }
  }
}

void MultibodyModel::AddConstraintHessian(const VectorXd& q, const VectorXd& lambda, double scale,
                                          SkylineLdlt* a) const {
  // The Hessians are constant; `q` is kept for the interface.
  (void)q;
  double* values = a->values();
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    const double f = scale * lambda(i);
    // Slots are looked up in `a` (any pattern containing envelope()).
    for (int k = row.mono_begin; k < row.mono_end; ++k)
      if (mono_row_[k] >= 0) values[a->Slot(mono_row_[k], mono_col_[k])] += f * mono_factor_[k];
  }
}

void MultibodyModel::ConstraintGamma(const VectorXd& q, const VectorXd& qdot,
                                     VectorXd* gamma) const {
  (void)q;
  for (size_t i = 0; i < rows_.size(); ++i) {
    const Row& row = rows_[i];
    const int* coord = &row_coord_[row.coord_begin];
    double acc = 0;
    for (int k = row.mono_begin; k < row.mono_end; ++k)
      acc += mono_w_[k] * qdot(coord[mono_a_[k]]) * qdot(coord[mono_b_[k]]);
    (*gamma)(i) = -2 * acc;
  }
}

template <int D>
void MultibodyModel::ElementEnergy(const VectorXd& q, const VectorXd& qdot,
                                   EnergySample* en) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  for (const ElementData<D>& e : elements) {
    const auto qe = q.segment<kN>(e.first_coord);
    const auto ve = qdot.segment<kN>(e.first_coord);
    en->kinetic += 0.5 * ve.dot(e.element.MassMatrix(e.mass_per_length) * ve);
    const auto se = e.element.StrainEnergy(qe);
    en->axial += se.axial;
    en->bending += se.bending;
  }
}

EnergySample MultibodyModel::Energy(const VectorXd& q, const VectorXd& qdot,
                                    double load_factor) const {
  EnergySample en;
  if (dim_ == 2) {
    ElementEnergy<2>(q, qdot, &en);
  } else {
    ElementEnergy<3>(q, qdot, &en);
  }
  const int D = dim_;
  for (const BodyData& b : bodies_) {
    en.kinetic += 0.5 * b.mass * qdot.segment(b.coord, D).squaredNorm();
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k)
      en.kinetic += 0.5 * b.jbar(k) * qdot.segment(b.coord + D + D * k, D).squaredNorm();
  }
  // Gravity and point loads are constant forces on q: V = -F . q. Element
  // gravity is exactly -Q_g . e (MODEL.md section 2).
  en.potential = -load_factor * constant_force_.dot(q);
  // Torques: their work so far (AccumulateTorqueWork).
  en.potential -= torque_work_;
  en.total = en.kinetic + en.potential + en.axial + en.bending;
  return en;
}

void MultibodyModel::AccumulateTorqueWork(const VectorXd& q_before, const VectorXd& q_after,
                                          double load_factor) {
  for (const TorqueLoad& t : torques_) {
    const int c = bodies_[t.body].coord;
    if (dim_ == 2) {
      // Exact for a constant torque: T_z times the angle turned.
      const Eigen::Vector2d u0 = q_before.segment<2>(c + 2), u1 = q_after.segment<2>(c + 2);
      torque_work_ += load_factor * t.torque.z() *
                      std::atan2(u0.x() * u1.y() - u0.y() * u1.x(), u0.dot(u1));
    } else {
      // T . phi with phi the rotation vector of the step (exact when the
      // rotation axis is fixed over the step, second order otherwise).
      Eigen::Matrix3d before, after;
      for (int k = 0; k < 3; ++k) {
        before.col(k) = q_before.segment<3>(c + 3 + 3 * k);
        after.col(k) = q_after.segment<3>(c + 3 + 3 * k);
      }
      const Eigen::AngleAxisd delta(Eigen::Matrix3d(after * before.transpose()));
      torque_work_ += load_factor * t.torque.dot(delta.angle() * delta.axis());
    }
  }
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
