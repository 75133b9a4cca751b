#include "engine/forces/wave_load.h"

#include <utility>

#include "engine/elements/gauss_quadrature.h"

namespace cablesim {

WaveLoad::WaveLoad(WaveField field, const Eigen::Vector3d& current, bool free_surface,
                   CurrentProfile profile)
    : field_(std::move(field)), current_(current), profile_(std::move(profile)) {
  surface_.enabled = free_surface;
  surface_.up = field_.up();
  surface_.level_m = field_.surface();
}

template <int D>
void WaveLoad::Add(const AncfCableElement<D>& element,
                   const typename AncfCableElement<D>::Coords& e,
                   const typename AncfCableElement<D>::Coords& edot, double t, double kn,
                   double kt, double mi_n, double mi_t,
                   typename AncfCableElement<D>::Coords* force,
                   typename AncfCableElement<D>::Matrix* c) const {
  using Point = typename AncfCableElement<D>::Point;
  Point velocity[GaussRule::kMaxPoints], acceleration[GaussRule::kMaxPoints];
  bool wet[GaussRule::kMaxPoints];
  Eigen::Vector3d r = Eigen::Vector3d::Zero();
  for (int g = 0; g < element.gauss_points(); ++g) {
    r.head<D>() = element.GaussPosition(e, g);
    const WaveField::Kinematics k = field_.At(r, t);
    velocity[g] =
        (profile_.empty() ? current_ : profile_.At(r, t)).head<D>() + k.velocity_m_s.head<D>();
    acceleration[g] = k.acceleration_m_s2.head<D>();
    wet[g] = surface_.Wet(r, k.elevation_m);
  }
  element.AddMorison(e, edot, velocity, acceleration, kn, kt, mi_n, mi_t,
                     surface_.enabled ? wet : nullptr, force, c);
}

template void WaveLoad::Add<2>(const AncfCableElement<2>&, const AncfCableElement<2>::Coords&,
                               const AncfCableElement<2>::Coords&, double, double, double,
                               double, double, AncfCableElement<2>::Coords*,
                               AncfCableElement<2>::Matrix*) const;
template void WaveLoad::Add<3>(const AncfCableElement<3>&, const AncfCableElement<3>::Coords&,
                               const AncfCableElement<3>::Coords&, double, double, double,
                               double, double, AncfCableElement<3>::Coords*,
                               AncfCableElement<3>::Matrix*) const;

}  // namespace cablesim
