#include "engine/forces/gravity_loads.h"

#include <type_traits>
#include <utility>

#include "engine/elements/ancf_cable_element.h"

namespace cablesim {

using Eigen::VectorXd;

template <int D>
GravityLoads<D>::GravityLoads(std::vector<Element> elements, std::vector<Body> bodies,
                              const std::vector<std::pair<int, double>>& load_terms,
                              bool has_loads, const Eigen::Vector3d& g,
                              std::vector<Winch> winches, int coordinates)
    : elements_(std::move(elements)),
      bodies_(std::move(bodies)),
      g_(g),
      winches_(std::move(winches)) {
  constexpr int kN = 4 * D;
  const Eigen::Matrix<double, D, 1> gd = g_.head<D>();
  force_ = VectorXd::Zero(coordinates);
  gravity_.reserve(elements_.size());
  for (const Element& e : elements_) {
    gravity_.push_back(
        AncfCableElement<D>::GravityForceOfLength(e.length, e.weight_per_length, gd));
    force_.template segment<kN>(e.first_coord) += gravity_.back();
  }
  for (const Body& b : bodies_) force_.segment(b.coord, D) += b.mass * g_.head(D);
  if (has_loads) loads_ = VectorXd::Zero(coordinates);
  for (const auto& [i, f] : load_terms) {
    force_(i) += f;
    loads_(i) += f;
  }
  if (winches_.empty()) return;
  base_ = force_;
  for (const Winch& w : winches_)
    for (int k = w.element_begin; k < w.element_end; ++k)
      base_.template segment<kN>(elements_[k].first_coord) -= gravity_[k];
}

template <int D>
void GravityLoads<D>::SetTime(double t) {
  if (winches_.empty()) return;
  constexpr int kN = 4 * D;
  const Eigen::Matrix<double, D, 1> gd = g_.head<D>();
  force_ = base_;
  for (const Winch& w : winches_) {
    const double l = w.reel.At(t).length / (w.element_end - w.element_begin);
    for (int k = w.element_begin; k < w.element_end; ++k) {
      gravity_[k] =
          AncfCableElement<D>::GravityForceOfLength(l, elements_[k].weight_per_length, gd);
      force_.template segment<kN>(elements_[k].first_coord) += gravity_[k];
    }
  }
}

template <int D>
void GravityLoads<D>::AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
  *out->full += s.load_factor * force_;
}

template <int D>
double GravityLoads<D>::StoredEnergy(const ForceState& s) const {
  return -s.load_factor * force_.dot(*s.q);
}

template <int D>
void GravityLoads<D>::AddEnergyParts(const ForceState& s, EnergyParts* parts) const {
  constexpr int kN = 4 * D;
  const VectorXd& q = *s.q;
  const double load_factor = s.load_factor;
  // Element gravity is exactly -Q_g . e (MODEL.md section 2).
  for (size_t k = 0; k < elements_.size(); ++k) {
    parts->cables[elements_[k].cable].gravity -=
        gravity_[k].dot(q.template segment<kN>(elements_[k].first_coord));
  }
  for (PartEnergy& part : parts->cables) part.gravity *= load_factor;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    parts->bodies[i].gravity = -load_factor * b.mass * g_.head(D).dot(q.segment(b.coord, D));
  }
  if (loads_.size() > 0) parts->loads -= load_factor * loads_.dot(q);
}

template <int D>
void GravityLoads<D>::AddExternalPower(const ForceState& s, double* power) const {
  constexpr int kN = 4 * D;
  const Eigen::Matrix<double, D, 1> gd = g_.head<D>();
  for (const Winch& w : winches_) {
    const int n = w.element_end - w.element_begin;
    const WinchReel::State now = w.reel.At(s.time);
    const double l = now.length / n, ldot = now.rate / n;
    if (ldot == 0) continue;
    for (int k = w.element_begin; k < w.element_end; ++k) {
      const Coords dq_dl =
          AncfCableElement<D>::GravityForceOfLength(2 * l, elements_[k].weight_per_length, gd) /
          (2 * l);
      *power -= s.load_factor * ldot * dq_dl.dot(s.q->template segment<kN>(elements_[k].first_coord));
    }
  }
}

template class GravityLoads<2>;
template class GravityLoads<3>;

std::unique_ptr<ForceContributor> MakeGravityLoads(
    int dim, const Eigen::Vector3d& g, const std::vector<double>& element_weight,
    const std::vector<int>& element_first, const std::vector<double>& element_length,
    const std::vector<int>& element_cable, const std::vector<int>& body_coord,
    const std::vector<double>& body_mass, const std::vector<std::pair<int, double>>& load_terms,
    bool has_loads, const std::vector<std::pair<std::pair<int, int>, WinchReel>>& winches,
    int coordinates) {
  bool any_load = false;
  for (const auto& term : load_terms) any_load = any_load || term.second != 0;
  if (g.isZero(0) && !any_load) return nullptr;
  auto make = [&](auto tag) -> std::unique_ptr<ForceContributor> {
    using G = GravityLoads<decltype(tag)::value>;
    std::vector<typename G::Element> elements;
    for (size_t k = 0; k < element_weight.size(); ++k)
      elements.push_back({element_first[k], element_cable[k], element_weight[k], element_length[k]});
    std::vector<typename G::Body> bodies;
    for (size_t b = 0; b < body_coord.size(); ++b) bodies.push_back({body_coord[b], body_mass[b]});
    std::vector<typename G::Winch> reels;
    for (const auto& [range, reel] : winches) reels.push_back({range.first, range.second, reel});
    return std::make_unique<G>(std::move(elements), std::move(bodies), load_terms, has_loads, g,
                               std::move(reels), coordinates);
  };
  if (dim == 2) return make(std::integral_constant<int, 2>());
  return make(std::integral_constant<int, 3>());
}

}  // namespace cablesim
