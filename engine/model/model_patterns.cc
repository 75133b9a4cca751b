// ModelBuilder's pattern steps (model_builder.h): per element its slots
// in the Newton matrix, the skyline envelope that holds every coupling
// (elements, bodies, rows, sliders, wheels a body carries), the constant
// reduced mass matrix, and the constraint rows' pattern on z.

#include "engine/model/model_builder.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace cablesim {

using Eigen::VectorXd;

template <int D>
void ModelBuilder::SetupElementSlots(const std::vector<MultibodyModel::ElementData<D>>& elements) {
  MultibodyModel& m = model_;
  constexpr int kN = 4 * D, kN2 = kN * kN;
  m.element_slots_.resize(kN2 * elements.size());
  m.element_factors_.resize(kN2 * elements.size());
  m.element_scatter_.clear();
  m.element_scatter_begin_.assign(elements.size() + 1, 0);
  for (size_t k = 0; k < elements.size(); ++k) {
    if (k % 65536 == 0 && Stopped()) return;
    const MultibodyModel::ElementData<D>& e = elements[k];
    for (int a = 0; a < kN; ++a) {
      for (int b = 0; b < kN; ++b) {
        const int ia = e.first_coord + a, ib = e.first_coord + b;
        const int ja = m.j_[ia], jb = m.j_[ib];
        // A(ja, jb) with ja > jb is stored once; the diagonal takes every
        // (a, b) with ja == jb (both orders of a != b), as the sum requires.
        const int slot = (ja >= 0 && jb >= 0 && ja >= jb) ? m.mass_.Slot(ja, jb) : -1;
        m.element_slots_[kN2 * k + kN * a + b] = slot;
        m.element_factors_[kN2 * k + kN * a + b] = slot < 0 ? 0 : m.s_(ia) * m.s_(ib);
      }
    }
    for (int t = 0; t < kN2; ++t)
      if (m.element_slots_[kN2 * k + t] >= 0)
        m.element_scatter_.push_back(
            {m.element_slots_[kN2 * k + t], t, m.element_factors_[kN2 * k + t]});
    m.element_scatter_begin_[k + 1] = static_cast<int>(m.element_scatter_.size());
    const auto me = e.element.MassMatrix(e.mass_per_length);
    for (int t = 0; t < kN2; ++t) {
      const int slot = m.element_slots_[kN2 * k + t];
      if (slot >= 0)
        m.mass_.values()[slot] += m.element_factors_[kN2 * k + t] * me(t / kN, t % kN);
    }
  }
}

void ModelBuilder::EnvelopeAndMass() {
  MultibodyModel& m = model_;
  const int D = m.dim_, bs = m.body_stride_;
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
  for (const MultibodyModel::BodyData& b : m.bodies_) {
    std::vector<int> idx(bs);
    for (int k = 0; k < bs; ++k) idx[k] = b.coord + k;
    couple(idx.data(), bs);
  }
  for (int i = 0; i < m.joint_rows_->size(); ++i) {
    const JointRows::Row& row = m.joint_rows_->row(i);
    couple(m.joint_rows_->coords(row), m.joint_rows_->coord_count(row));
  }

  // The first `count` coordinates of a body coupled with every element of
  // a cable (a slider, a wheel the body carries).
  auto couple_body_with_cable = [&](int body, int count, int cable) {
    int cable_lo = std::numeric_limits<int>::max(), body_lo = cable_lo;
    const int first = NodeCoord(mesh_.first_node[cable]);
    const int last = NodeCoord(mesh_.first_node[cable + 1]);
    for (int i = first; i < last; ++i)
      if (m.j_[i] >= 0) cable_lo = std::min(cable_lo, m.j_[i]);
    for (int k = 0; k < count; ++k)
      if (m.j_[BodyCoord(body) + k] >= 0) body_lo = std::min(body_lo, m.j_[BodyCoord(body) + k]);
    for (int k = 0; k < count; ++k) {
      const int j = m.j_[BodyCoord(body) + k];
      if (j >= 0) m.envelope_[j] = std::min(m.envelope_[j], cable_lo);
    }
    for (int i = first; i < last; ++i) {
      const int j = m.j_[i];
      if (j >= 0 && j > body_lo) m.envelope_[j] = std::min(m.envelope_[j], body_lo);
    }
  };
  // A slider couples its body with every element of its cable.
  for (const JointSpec& joint : scene_.joints) {
    if (joint.type != JointType::kSlide) continue;
    const int cable = joint.a.cable >= 0 ? joint.a.cable : joint.b.cable;
    const int body = joint.a.body >= 0 ? joint.a.body : joint.b.body;
    couple_body_with_cable(body, bs, cable);
  }
  // A wheel on a body couples the body's centre with the cables it touches.
  for (const SheaveSpec& wheel : scene_.sheaves) {
    if (wheel.body < 0) continue;
    for (int cable = 0; cable < static_cast<int>(scene_.cables.size()); ++cable)
      if (wheel.Touches(cable)) couple_body_with_cable(wheel.body, D, cable);
  }

  // The reduced mass matrix, with the element scatter tables.
  m.mass_.SetPattern(m.envelope_);
  if (D == 2) {
    SetupElementSlots(m.elements2_);
  } else {
    SetupElementSlots(m.elements3_);
  }
  for (const MultibodyModel::BodyData& b : m.bodies_) {
    for (int k = 0; k < bs; ++k) {
      const int j = m.j_[b.coord + k];
      if (j < 0) continue;
      const double diag = k < D ? b.mass : b.jbar((k - D) / D);
      m.mass_.values()[m.mass_.Slot(j, j)] += m.s_(b.coord + k) * m.s_(b.coord + k) * diag;
    }
    if (b.has_added_mass) {
      m.Map().ScatterRange(b.coord, bs, b.added_mass.data(), BodyFluidLoad::kMaxStride, 1.0,
                           &m.mass_);
    }
  }
}

void ModelBuilder::ConstraintPattern() {
  MultibodyModel& m = model_;
  m.joint_rows_->SetupPattern(m.Map(), m.dofs_, &m.jac_pattern_);
  // The families the scene uses, in the order they are summed: the rows
  // first (they write their values), then the supports' time law.
  if (m.joint_rows_->size() > 0) m.families_.push_back(m.joint_rows_.get());
  if (m.motion_) m.families_.push_back(m.motion_.get());
  m.families_view_.assign(m.families_.begin(), m.families_.end());
}

}  // namespace cablesim
