// MultibodyModel::DescribeNonFinite: which force term made a non-finite
// value. Called only on a run's failure path (a non-finite residual or
// acceleration), so it may allocate and evaluate every term on its own.

#include <cmath>
#include <string>

#include "absl/strings/str_format.h"
#include "engine/model/multibody_model.h"

namespace cablesim {

std::string MultibodyModel::DescribeCoordinate(int i) const {
  const auto where = [&](const auto& elements) -> std::string {
    const int kn = 4 * node_stride_ / 2;  // an element's coordinates
    for (size_t k = 0; k < elements.size(); ++k) {
      const int first = elements[k].first_coord;
      if (i < first || i >= first + kn) continue;
      int cable = 0;
      while (cable + 1 < static_cast<int>(cable_element_begin_.size()) &&
             cable_element_begin_[cable + 1] <= static_cast<int>(k))
        ++cable;
      const int node = static_cast<int>(k) - cable_element_begin_[cable] +
                       (i - first >= node_stride_ ? 1 : 0);
      return absl::StrFormat("cables[%d] node %d", cable, node);
    }
    for (size_t b = 0; b < bodies_.size(); ++b)
      if (i >= bodies_[b].coord && i < bodies_[b].coord + body_stride_)
        return absl::StrFormat("bodies[%d]", static_cast<int>(b));
    return absl::StrFormat("coordinate %d", i);
  };
  return dim_ == 2 ? where(elements2_) : where(elements3_);
}

template <int D>
std::string MultibodyModel::DescribeNonFiniteElements(const Eigen::VectorXd& q,
                                                      const Eigen::VectorXd* qdot) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  Eigen::VectorXd scratch = Eigen::VectorXd::Zero(q.size());
  ForceOutput coupled{&scratch, nullptr, nullptr, 0, Map()};
  typename AncfCableElement<D>::Coords fe, fd;
  typename AncfCableElement<D>::Matrix c;
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    int cable = 0;
    while (cable_element_begin_[cable + 1] <= static_cast<int>(k)) ++cable;
    const int local = static_cast<int>(k) - cable_element_begin_[cable];
    const auto qe = q.segment<kN>(e.first_coord);
    fe.setZero();
    e.element.ElasticForce(qe, &fe, nullptr, nullptr);
    if (!fe.allFinite())
      return absl::StrFormat("elastic force, cables[%d] element %d", cable, local);
    const ElementAt<D> at{e.element, static_cast<int>(k), time_, e.first_coord, &q, qdot,
                          &coupled};
    for (const ElementTerm* t : potential_terms_) {
      fe.setZero();
      scratch.setZero();
      t->AddElementPotential(at, qe, &fe, nullptr, nullptr);
      if (!fe.allFinite() || !scratch.allFinite())
        return absl::StrFormat("non-finite force from '%s' (cables[%d] element %d)", t->name(),
                               cable, local);
    }
    if (qdot == nullptr) continue;
    for (const ElementTerm* t : dissipative_terms_) {
      if (!t->DissipatesOn(static_cast<int>(k))) continue;
      fd.setZero();
      c.setZero();
      scratch.setZero();
      t->AddElementDissipation(at, qe, qdot->segment<kN>(e.first_coord), &fd, &c);
      if (!fd.allFinite() || !scratch.allFinite())
        return absl::StrFormat("non-finite force from '%s' (cables[%d] element %d)", t->name(),
                               cable, local);
    }
  }
  return "";
}

std::string MultibodyModel::DescribeNonFinite(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot,
                                              double load_factor) const {
  // A stop request fills the forces with NaN on purpose (set_stop_poll):
  // nothing to name, and no evaluation (it may be costly) once stopping.
  if (stop_requested()) return "";
  const auto first_bad = [](const Eigen::VectorXd& x) {
    for (int i = 0; i < x.size(); ++i)
      if (!std::isfinite(x(i))) return i;
    return -1;
  };
  if (int i = first_bad(q); i >= 0)
    return absl::StrFormat("non-finite position (%s)", DescribeCoordinate(i));
  if (qdot != nullptr) {
    if (int i = first_bad(*qdot); i >= 0)
      return absl::StrFormat("non-finite velocity (%s)", DescribeCoordinate(i));
  }
  const std::string element = dim_ == 2 ? DescribeNonFiniteElements<2>(q, qdot)
                                        : DescribeNonFiniteElements<3>(q, qdot);
  if (!element.empty()) return element;
  Eigen::VectorXd full(q.size());
  const ForceState state = StateAt(q, qdot, load_factor);
  for (const auto& c : contributors_) {
    full.setZero();
    ForceOutput out{&full, nullptr, nullptr, 0, Map()};
    c->AddAppliedLoad(state, &out);
    c->AddConservative(state, &out);
    if (qdot != nullptr) c->AddDissipative(state, &out);
    if (int i = first_bad(full); i >= 0) {
      return absl::StrFormat("non-finite force from contributor '%s' (%s)", c->name(),
                             DescribeCoordinate(i));
    }
  }
  return "";
}

template std::string MultibodyModel::DescribeNonFiniteElements<2>(const Eigen::VectorXd&,
                                                                 const Eigen::VectorXd*) const;
template std::string MultibodyModel::DescribeNonFiniteElements<3>(const Eigen::VectorXd&,
                                                                 const Eigen::VectorXd*) const;

}  // namespace cablesim
