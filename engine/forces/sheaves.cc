#include "engine/forces/sheaves.h"

#include <bit>
#include <utility>

#include "engine/forces/sliding_joint.h"
#include "engine/linear/rounding.h"

namespace cablesim {

Sheaves::Sheaves(std::vector<Sheave> wheels, std::vector<int> centre_coord,
                 std::vector<uint64_t> mask)
    : wheels_(std::move(wheels)), centre_coord_(std::move(centre_coord)), mask_(std::move(mask)) {
  for (const Sheave& w : wheels_)
    if (w.dissipates()) dissipates_ = true;
}

namespace {

// A body wheel's terms over x = [e; c] as a slider's local terms.
template <int D, typename Force>
SlidingJoint::Local BodyLocal(int first_coord, int centre, const Force& force) {
  constexpr int kN = 4 * D, kX = 5 * D;
  SlidingJoint::Local local;
  local.n = kX;
  for (int k = 0; k < kN; ++k) local.coord[k] = first_coord + k;
  for (int k = 0; k < D; ++k) local.coord[kN + k] = centre + k;
  local.force = force;
  return local;
}

}  // namespace

template <int D>
double Sheaves::Potential(const ElementAt<D>& at, const ElementCoords<D>& e,
                          ElementCoords<D>* gradient, ElementMatrix<D>* hessian,
                          ElementCoords<D>* roundoff) const {
  constexpr int kX = 5 * D;
  const double length = at.element.length();
  double u = 0;
  for (uint64_t bits = mask_[at.index]; bits != 0; bits &= bits - 1) {
    const int i = std::countr_zero(bits);
    const Sheave& wheel = wheels_[i];
    if (wheel.body() < 0) {
      u += wheel.AddPotential<D>(e, length, gradient, hessian, roundoff);
      continue;
    }
    // A body's wheel: its force, tangent and rounding over the element and
    // the body's centre, scattered like a slider's.
    ForceOutput* out = at.coupled;
    const int centre = centre_coord_[i];
    Eigen::Matrix<double, kX, 1> x, g = Eigen::Matrix<double, kX, 1>::Zero(),
                                    rounding = Eigen::Matrix<double, kX, 1>::Zero();
    x << e, at.q->template segment<D>(centre);
    Eigen::Matrix<double, kX, kX> h;
    if (out->matrix) h.setZero();
    const double ui = wheel.AddPotentialOnBody<D>(x, length, &g, out->matrix ? &h : nullptr,
                                                  out->roundoff ? &rounding : nullptr);
    if (ui == 0) continue;
    u += ui;
    SlidingJoint::Local local = BodyLocal<D>(at.first_coord, centre, -g);
    if (out->matrix) local.matrix = h;
    local.rounding = rounding.maxCoeff();
    AddLocalTerms(local, out);
  }
  return u;
}

template <int D>
void Sheaves::Energy(const ElementAt<D>& at, const ElementCoords<D>& e, double* energy) const {
  const double length = at.element.length();
  for (uint64_t bits = mask_[at.index]; bits != 0; bits &= bits - 1) {
    const int i = std::countr_zero(bits);
    const Sheave& wheel = wheels_[i];
    if (wheel.body() >= 0) {
      Eigen::Matrix<double, 5 * D, 1> x;
      x << e, at.q->template segment<D>(centre_coord_[i]);
      *energy += wheel.AddPotentialOnBody<D>(x, length, nullptr, nullptr);
    } else {
      *energy += wheel.Energy<D>(e, length);
    }
  }
}

template <int D>
double Sheaves::Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e,
                            const ElementCoords<D>& edot, ElementCoords<D>* force,
                            ElementMatrix<D>* c) const {
  constexpr int kX = 5 * D;
  const double length = at.element.length();
  double power = 0;
  for (uint64_t bits = mask_[at.index]; bits != 0; bits &= bits - 1) {
    const int i = std::countr_zero(bits);
    const Sheave& wheel = wheels_[i];
    if (wheel.body() < 0) {
      power += wheel.AddDissipation<D>(e, edot, length, force, c);
      continue;
    }
    // A body's wheel: its damping and friction over the element and the
    // body's centre, scattered like a slider's; its power to coupled_power.
    ForceOutput* out = at.coupled;
    const int centre = centre_coord_[i];
    Eigen::Matrix<double, kX, 1> x, xdot, f = Eigen::Matrix<double, kX, 1>::Zero();
    x << e, at.q->template segment<D>(centre);
    xdot << edot, at.qdot->template segment<D>(centre);
    Eigen::Matrix<double, kX, kX> cx;
    if (out->matrix) cx.setZero();
    const double p = wheel.AddDissipationOnBody<D>(x, xdot, length, &f, out->matrix ? &cx : nullptr);
    if (at.coupled_power) *at.coupled_power += p;
    power += p;
    if (out->full == nullptr || p == 0) continue;
    SlidingJoint::Local local = BodyLocal<D>(at.first_coord, centre, f);
    if (out->matrix) local.matrix = cx;
    local.rounding = kSumRounding * f.cwiseAbs().maxCoeff();
    AddLocalTerms(local, out);
  }
  return power;
}

std::unique_ptr<Sheaves> MakeSheaves(const Scene& scene, const std::vector<int>& cable_element_begin,
                                     const std::vector<int>& body_coord) {
  if (scene.sheaves.empty()) return nullptr;
  std::vector<Sheave> wheels;
  std::vector<int> centre;
  std::vector<uint64_t> mask(cable_element_begin.back(), 0);
  for (size_t i = 0; i < scene.sheaves.size(); ++i) {
    const SheaveSpec& spec = scene.sheaves[i];
    wheels.emplace_back(spec);
    centre.push_back(wheels.back().body() >= 0 ? body_coord[wheels.back().body()] : -1);
    for (int cable = 0; cable < static_cast<int>(scene.cables.size()); ++cable) {
      if (!spec.Touches(cable)) continue;
      for (int k = cable_element_begin[cable]; k < cable_element_begin[cable + 1]; ++k)
        mask[k] |= uint64_t{1} << i;
    }
  }
  return std::make_unique<Sheaves>(std::move(wheels), std::move(centre), std::move(mask));
}

}  // namespace cablesim
