// ModelBuilder's joint steps (model_builder.h): the rows of every joint,
// the turning supports' direction rows, the check of the sides at t = 0,
// which rows the elimination leaves movable (and the supports' time law,
// PrescribedMotion), and the check of the moving supports.

#include "engine/model/model_builder.h"

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include <Eigen/Dense>

#include "absl/strings/str_format.h"

namespace cablesim {

using Eigen::Vector3d;
using Eigen::VectorXd;

absl::Status ModelBuilder::Joints() {
  const int D = model_.dim_, bs = model_.body_stride_;
  const int num_nodes = model_.num_nodes_;
  elimination_.grounded.assign(q0_.size(), false);
  elimination_.clamp_dir.assign(num_nodes, Vector3d::Zero());
  elimination_.clamped.assign(num_nodes, false);
  std::vector<bool>& grounded = elimination_.grounded;
  pending_.clear();
  for (int ji = 0; ji < static_cast<int>(scene_.joints.size()); ++ji) {
    const JointSpec& joint = scene_.joints[ji];
    if (joint.type == JointType::kSlide) {
      // A force (Sliders), not rows: one side a body, the other a cable.
      if (!((joint.a.body >= 0 && joint.b.cable >= 0) ||
            (joint.b.body >= 0 && joint.a.cable >= 0))) {
        return absl::InvalidArgumentError(absl::StrCat(
            "joints[", ji, "].type: SLIDE joins a body (one side) to a cable (the other)"));
      }
      continue;
    }
    if (joint.released) continue;  // let go (JointRelease): no rows, its reaction reads 0
    Attachment a = joint.a, b = joint.b;
    if (a.IsGround()) std::swap(a, b);
    if (a.IsGround()) {
      return absl::InvalidArgumentError(
          absl::StrCat("joints[", ji, "].a: a joint needs a cable or a body on one side"));
    }
    const bool fixed = joint.type == JointType::kFixed;
    // A joint that may let go keeps its rows: their multipliers are its force.
    const bool reactions = scene_.output.reactions || joint.HasRelease();
    if (b.IsGround() && (joint.HasMotion() || joint.HasRotation() || reactions)) {
      // A moving support: its point stays as rows (below); FIXED keeps the
      // orientation by elimination, as a fixed support does, or, when the
      // support turns, by rows whose normals turn with it. With
      // output.reactions every support is kept as rows (their multipliers
      // are its reaction), FIXED by rows with constant normals.
      if (joint.HasRotation()) {
        AddTurningRows(ji, a);
      } else if (fixed && reactions) {
        AddTurningRows(ji, a, /*turning=*/false);
      } else if (fixed && a.cable >= 0) {
        const int node = mesh_.Node(a);
        elimination_.clamped[node] = true;
        elimination_.clamp_dir[node] = AtStart(NodeSlope(node)).normalized();
      } else if (fixed) {
        const int i = BodyCoord(a.body);
        for (int k = D; k < bs; ++k) grounded[i + k] = true;
      }
      const LinearVector pa = PointOf(a);
      const Vector3d p0 = AtStart(pa);
      for (int d = 0; d < D; ++d) {
        LinearForm diff = pa[d];
        diff.c -= p0(d);
        PendingRow row{QuadraticForm::FromLinear(diff), Row::kPosition, ji, -1};
        // (A support kept as rows only for its reaction has no time law.)
        if (joint.HasMotion() || joint.HasRotation()) row.motion_axis = d;
        row.axis = d;
        pending_.push_back(row);
      }
      continue;
    }
    if (b.IsGround()) {
      if (a.cable >= 0) {
        const int node = mesh_.Node(a);
        for (int d = 0; d < D; ++d) grounded[NodeCoord(node) + d] = true;
        if (fixed) {
          elimination_.clamped[node] = true;
          elimination_.clamp_dir[node] = AtStart(NodeSlope(node)).normalized();
        }
        continue;
      }
      const int i = BodyCoord(a.body);
      if (fixed) {
        for (int k = 0; k < bs; ++k) grounded[i + k] = true;
        continue;
      }
      if (a.point_body_m.norm() == 0) {
        for (int d = 0; d < D; ++d) grounded[i + d] = true;
        continue;
      }
    }
    // Points coincide: D rows.
    const LinearVector pa = PointOf(a);
    const LinearVector pb = b.IsGround() ? Constant(AtStart(pa)) : PointOf(b);
    for (int d = 0; d < D; ++d) {
      LinearForm diff = pa[d];
      diff += pb[d].Scaled(-1);
      PendingRow row{QuadraticForm::FromLinear(diff), Row::kPosition, ji, -1};
      row.axis = d;
      pending_.push_back(row);
    }
    if (!fixed || b.IsGround()) continue;
    if (absl::Status s = AddOrientationRows(ji, a, b); !s.ok()) return s;
  }
  // A FIXED joint's direction and slope rows: side a's vectors, for its moment.
  for (PendingRow& r : pending_) {
    if (r.joint < 0 || r.kind == Row::kPosition) continue;
    std::tie(r.side_begin, r.side_end) = SideVectors(scene_.joints[r.joint]);
  }
  // Each body's axes stay unit and orthogonal.
  for (int b = 0; b < static_cast<int>(scene_.bodies.size()); ++b) {
    const auto e = BodyAxes(b);
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k) {
      QuadraticForm f = Dot(e[k], e[k], D);
      f.c -= 1;
      pending_.push_back({f, Row::kAxes, -1, b});
    }
    for (int k = 0; k < axes; ++k)
      for (int l = k + 1; l < axes; ++l)
        pending_.push_back({Dot(e[k], e[l], D), Row::kAxes, -1, b});
  }
  return absl::OkStatus();
}

std::pair<int, int> ModelBuilder::SideVectors(const JointSpec& joint) const {
  const Attachment& a = joint.a.IsGround() ? joint.b : joint.a;
  const int D = model_.dim_;
  if (a.cable >= 0) {
    const int slope = NodeCoord(mesh_.Node(a)) + D;
    return {slope, slope + D};
  }
  const int c = BodyCoord(a.body);
  return {c + D, c + model_.body_stride_};
}

void ModelBuilder::AddTurningRows(int ji, Attachment a, bool turning) {
  const int D = model_.dim_;
  // One row n . x = 0 per pair (x, n) of a held direction x and a normal
  // n of its initial direction: a clamped slope r_x keeps n . r_x = 0 for
  // the D - 1 normals of d0 (its length, the stretch, stays free); a body
  // keeps u . v0 = 0 (planar) or u . v0 = u . w0 = v . w0 = 0 (spatial),
  // which with its unit and orthogonality rows fix its axes to R(t) e0.
  auto add = [&](int coord, const Vector3d& n0) {
    LinearForm f;
    // Placeholders for a turning support (SetTime writes n(t)).
    for (int d = 0; d < D; ++d) f.terms[coord + d] = turning ? 1 : n0(d);
    PendingRow row{QuadraticForm::FromLinear(f), Row::kDirection, ji, -1};
    if (turning) {
      row.turn_coord = coord;
      row.turn_n0 = n0;
    }
    pending_.push_back(row);
  };
  auto at_start = [&](int coord) {
    Vector3d x = Vector3d::Zero();
    x.head(D) = q0_.segment(coord, D);
    return x;
  };
  if (a.cable >= 0) {
    const int slope = NodeCoord(mesh_.Node(a)) + D;
    const Vector3d d0 = at_start(slope).normalized();
    if (D == 2) {
      add(slope, Vector3d(-d0.y(), d0.x(), 0));
    } else {
      const Vector3d n1 = d0.unitOrthogonal();
      add(slope, n1);
      add(slope, d0.cross(n1));
    }
    return;
  }
  const int c = BodyCoord(a.body);
  if (D == 2) {
    add(c + 2, Vector3d(-q0_(c + 3), q0_(c + 2), 0));
  } else {
    add(c + 3, at_start(c + 6));
    add(c + 3, at_start(c + 9));
    add(c + 6, at_start(c + 9));
  }
}

absl::Status ModelBuilder::AddOrientationRows(int ji, Attachment a, Attachment b) {
  const int D = model_.dim_;
  if (a.cable < 0 && b.cable >= 0) std::swap(a, b);  // a node first
  if (a.cable >= 0 && b.cable >= 0) {
    // Two cables welded end to end: the slopes stay equal, r_x,b = c r_x,a
    // with c = |r_x,b| / |r_x,a| at t = 0 (1 for a cable split at the
    // joint): D linear rows, of full rank in every configuration. (Rows
    // (r_x,a x r_x,b) . m with fixed m lose rank once the tangent turns
    // onto m.) The stretch on both sides is thereby tied; that is exact for
    // a uniform cable without a point load at the joint.
    const LinearVector ta = NodeSlope(mesh_.Node(a)), tb = NodeSlope(mesh_.Node(b));
    const Vector3d t0a = AtStart(ta), t0b = AtStart(tb);
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
      pending_.push_back({QuadraticForm::FromLinear(diff), Row::kSlope, ji, -1});
    }
  } else if (a.cable >= 0) {
    // A cable tangent along the body's x axis: t . e2 = 0 (and t . e3 = 0).
    const LinearVector t = NodeSlope(mesh_.Node(a));
    pending_.push_back({Dot(t, BodyAxis(b.body, 1), D), Row::kDirection, ji, -1});
    if (D == 3) pending_.push_back({Dot(t, BodyAxis(b.body, 2), D), Row::kDirection, ji, -1});
  } else {
    // Two bodies welded: with B0 = A0 R0 at t = 0, b's axes must stay
    // A R0: e2_b . u_hat = 0, e3_b . u_hat = 0, e3_b . v_hat = 0 where
    // u_hat, v_hat are A R0 e_x, A R0 e_y (planar: the first only).
    const Eigen::Matrix3d r0 = frame0_[a.body].transpose() * frame0_[b.body];
    const auto ea = BodyAxes(a.body);
    const LinearVector u_hat =
        Combination({{r0(0, 0), ea[0]}, {r0(1, 0), ea[1]}, {r0(2, 0), ea[2]}});
    const LinearVector v_hat =
        Combination({{r0(0, 1), ea[0]}, {r0(1, 1), ea[1]}, {r0(2, 1), ea[2]}});
    pending_.push_back({Dot(BodyAxis(b.body, 1), u_hat, D), Row::kDirection, ji, -1});
    if (D == 3) {
      pending_.push_back({Dot(BodyAxis(b.body, 2), u_hat, D), Row::kDirection, ji, -1});
      pending_.push_back({Dot(BodyAxis(b.body, 2), v_hat, D), Row::kDirection, ji, -1});
    }
  }
  return absl::OkStatus();
}

absl::Status ModelBuilder::CheckJointsAtStart() const {
  std::vector<double> gap2(scene_.joints.size(), 0.0);
  for (const PendingRow& r : pending_) {
    const double v = r.f.Evaluate(q0_);
    if (r.kind == Row::kPosition) gap2[r.joint] += v * v;
    // (A turning support's rows hold at t = 0 by construction; f holds
    // placeholders until SetTime writes n(0).)
    if (r.kind == Row::kDirection && r.turn_coord < 0 && std::abs(v) > 1e-6) {
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
  return absl::OkStatus();
}

void ModelBuilder::KeepMovableRows() {
  MultibodyModel& m = model_;
  // A row that no unknown can change (both sides held by ground, say a
  // pinned node and a body pinned at its centre of mass, or the axes of a
  // welded body) is satisfied by construction, as far as
  // CheckJointsAtStart allows, and could never be corrected.
  // The test is the row's gradient on z at t = 0 (the rows are linear or
  // bilinear, so a row with a zero reduced gradient there is one that the
  // elimination has made constant, e.g. a clamped node welded to a body
  // welded to ground).
  std::vector<PrescribedMotion::MovingRow> moving_rows;
  std::vector<PrescribedMotion::TurningRow> turning_rows;
  for (const PendingRow& r : pending_) {
    VectorXd grad = VectorXd::Zero(m.dofs_);
    for (const auto& [i, v] : r.f.linear)
      if (m.j_[i] >= 0) grad(m.j_[i]) += v * m.s_(i);
    for (const auto& [ij, v] : r.f.quadratic) {
      if (m.j_[ij.first] >= 0) grad(m.j_[ij.first]) += v * m.s_(ij.first) * q0_(ij.second);
      if (m.j_[ij.second] >= 0) grad(m.j_[ij.second]) += v * m.s_(ij.second) * q0_(ij.first);
    }
    if (grad.lpNorm<Eigen::Infinity>() <= 1e-12) continue;
    m.joint_rows_->AddRow(r.f, r.kind, r.joint, r.body);
    m.joint_rows_->SetReactionData(r.axis, r.side_begin, r.side_end, m.dim_);
    if (r.motion_axis >= 0) {
      PrescribedMotion::MovingRow moving;
      moving.row = m.joint_rows_->size() - 1;
      moving.joint = r.joint;
      moving.axis = r.motion_axis;
      moving.c0 = r.f.c;
      moving.motion = scene_.joints[r.joint].motion[r.motion_axis];
      moving_rows.push_back(moving);
    }
    if (r.turn_coord >= 0) {
      PrescribedMotion::TurningRow turning;
      turning.row = m.joint_rows_->size() - 1;
      turning.coord = r.turn_coord;
      turning.joint = r.joint;
      turning.n0 = r.turn_n0;
      turning.axis = scene_.joints[r.joint].rotation_axis;
      turning.angle = scene_.joints[r.joint].rotation;
      turning_rows.push_back(turning);
    }
  }
  if (!moving_rows.empty() || !turning_rows.empty()) {
    m.motion_ = std::make_unique<PrescribedMotion>(m.joint_rows_.get(), std::move(moving_rows),
                                                   std::move(turning_rows), m.dim_);
  }
}

absl::Status ModelBuilder::CheckMovingRows() const {
  std::vector<int> kept(scene_.joints.size(), 0), wanted(scene_.joints.size(), 0);
  for (const PendingRow& r : pending_)
    if (r.motion_axis >= 0) ++wanted[r.joint];
  if (model_.motion_)
    for (const PrescribedMotion::MovingRow& m : model_.motion_->moving()) ++kept[m.joint];
  for (size_t j = 0; j < kept.size(); ++j) {
    if (kept[j] != wanted[j]) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "joints[%d].motion: the point it moves is also held by a fixed joint to ground",
          static_cast<int>(j)));
    }
  }
  return absl::OkStatus();
}

}  // namespace cablesim
