#include "engine/forces/cable_fluid_load.h"

#include <cmath>
#include <utility>

#include "engine/elements/gauss_quadrature.h"

namespace cablesim {

template <int D>
double CableFluidLoad::Dissipation(const ElementAt<D>& at, const ElementCoords<D>& e,
                           const ElementCoords<D>& edot, ElementCoords<D>* force,
                           ElementMatrix<D>* c) const {
  const Element& p = elements_[at.index];
  if (!p.any()) return 0;
  const ElementCoords<D> before = *force;
  if (p.tips()) AddTips<D>(at, e, edot, force, c);
  if (!p.distributed()) {
    // Tip loads alone.
  } else if (waves_) {
    waves_->Add<D>(at.element, e, edot, at.time, p.drag_n, p.drag_t, p.fluid_inertia,
                   p.fluid_inertia_axial, force, c);
  } else if (surface_.enabled || !profile_.empty()) {
    // The current (by depth, with a profile) at each Gauss point, on the
    // points under the still level only (with the free surface).
    using Point = typename AncfCableElement<D>::Point;
    Point velocity[GaussRule::kMaxPoints];
    bool wet[GaussRule::kMaxPoints];
    surface_.WetPoints<D>(at.element, e, nullptr, at.time, wet);
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (int g = 0; g < at.element.gauss_points(); ++g) {
      if (profile_.empty()) {
        velocity[g] = current_.head<D>();
      } else {
        r.head<D>() = at.element.GaussPosition(e, g);
        velocity[g] = profile_.At(r, at.time).template head<D>();
      }
    }
    at.element.AddMorison(e, edot, velocity, nullptr, p.drag_n, p.drag_t, 0, 0,
                          surface_.enabled ? wet : nullptr, force, c);
  } else {
    at.element.AddDrag(e, edot, current_.head<D>(), p.drag_n, p.drag_t, force, c);
  }
  return -edot.dot(*force - before);
}

template <int D>
void CableFluidLoad::AddTips(const ElementAt<D>& at, const ElementCoords<D>& e,
                             const ElementCoords<D>& edot, ElementCoords<D>* force,
                             ElementMatrix<D>* c) const {
  const Element& p = elements_[at.index];
  for (int end = 0; end < 2; ++end) {
    if (p.tip_drag[end] == 0 && p.tip_inertia[end] == 0) continue;
    const int i = 2 * D * end;  // the node's position coordinates
    Eigen::Vector3d r = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero(),
                    t = Eigen::Vector3d::Zero();
    r.head<D>() = e.template segment<D>(i);
    v.head<D>() = edot.template segment<D>(i);
    t.head<D>() = e.template segment<D>(i + D);
    const double stretch = t.norm();
    if (!(stretch > 0)) continue;  // a degenerate slope has no tangent
    t /= stretch;
    Eigen::Vector3d u = profile_.empty() ? current_ : profile_.At(r, at.time);
    Eigen::Vector3d du = Eigen::Vector3d::Zero();
    bool wet = true;
    if (waves_) {
      const WaveField::Kinematics k = waves_->field().At(r, at.time);
      u += k.velocity_m_s;
      du = k.acceleration_m_s2;
      wet = waves_->surface().Wet(r, k.elevation_m);
    } else {
      wet = surface_.Wet(r, 0.0);
    }
    if (!wet) continue;
    const double w = (u - v).dot(t);
    const Eigen::Vector3d f =
        (p.tip_drag[end] * std::abs(w) * w + p.tip_inertia[end] * du.dot(t)) * t;
    force->template segment<D>(i) += f.head<D>();
    if (c != nullptr && p.tip_drag[end] != 0) {
      const Eigen::Matrix3d tt = t * t.transpose();
      c->template block<D, D>(i, i) +=
          (2 * p.tip_drag[end] * std::abs(w)) * tt.topLeftCorner<D, D>();
    }
  }
}

template double CableFluidLoad::Dissipation<2>(const ElementAt<2>&, const ElementCoords<2>&,
                                       const ElementCoords<2>&, ElementCoords<2>*,
                                       ElementMatrix<2>*) const;
template double CableFluidLoad::Dissipation<3>(const ElementAt<3>&, const ElementCoords<3>&,
                                       const ElementCoords<3>&, ElementCoords<3>*,
                                       ElementMatrix<3>*) const;

std::unique_ptr<CableFluidLoad> MakeCableFluidLoad(std::vector<CableFluidLoad::Element> elements,
                                                   std::shared_ptr<const WaveLoad> waves,
                                                   const Eigen::Vector3d& current,
                                                   const FreeSurface& surface,
                                                   CurrentProfile profile) {
  for (const CableFluidLoad::Element& e : elements)
    if (e.any())
      return std::make_unique<CableFluidLoad>(std::move(elements), std::move(waves), current,
                                              surface, std::move(profile));
  return nullptr;
}

}  // namespace cablesim
