// AncfCableElement's terms evaluated point by point without forming their
// element matrices: the axial damping force (Newton's residual-only
// iterations) and the directional added mass's kinetic energy (every
// output frame). In a file of their own, as ancf_cable_element_force.h
// says of the elastic loop: in ancf_cable_element.cc they changed the
// compiler's inlining of the other Gauss-point loops (Eigen's 3-vector
// sums outlined: +9 % of the OC4 mooring's instructions, callgrind).

#include "engine/elements/ancf_cable_element.h"

namespace cablesim {

template <int D>
bool AncfCableElement<D>::AddAxialDampingForce(const Coords& e, const Coords& edot,
                                               double axial_s, double bending_s, Coords* force,
                                               double* power) const {
  if (bending_ != BendingModel::kNone && ei_ * bending_s != 0) return false;
  const double ca = ea_ * axial_s;
  double p = 0;
  for (int g = 0; g < rule_.n; ++g) {
    Point u = Point::Zero(), ud = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      u += d1_[g][k] * e.template segment<D>(k * D);
      ud += d1_[g][k] * edot.template segment<D>(k * D);
    }
    // AddDampingMatrix's huu = cs u u^T times udot.
    const double a = u.squaredNorm();
    const double cs = ca * (axial_law_ != AxialLaw::kGreenLagrange && a > 0 ? 1 / a : 1.0);
    const double rate = u.dot(ud);
    const double wl = rule_.weight[g] * length_;
    const double sigma = wl * cs * rate;  // [N m]: the point's share of C edot along u
    for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) -= (sigma * d1_[g][k]) * u;
    p += sigma * rate;
  }
  *power = p;
  return true;
}

template <int D>
double AncfCableElement<D>::DirectionalKineticEnergy(const Coords& e, const Coords& edot,
                                                     const double* a_n,
                                                     const double* a_t) const {
  double twice = 0;
  for (int g = 0; g < rule_.n; ++g) {
    if (a_n[g] == 0 && a_t[g] == 0) continue;
    const double* s0 = s0_[g];
    Point u = Point::Zero(), v = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      u += d1_[g][k] * e.template segment<D>(k * D);
      v += s0[k] * edot.template segment<D>(k * D);
    }
    double vav = a_n[g] * v.squaredNorm();
    // A collapsed point has no axis: a_n in every direction.
    const double uu = u.squaredNorm();
    if (uu > 0) {
      const double tv = u.dot(v);
      vav += (a_t[g] - a_n[g]) * tv * tv / uu;
    }
    twice += rule_.weight[g] * length_ * vav;
  }
  return 0.5 * twice;
}

template bool AncfCableElement<2>::AddAxialDampingForce(const Coords&, const Coords&, double,
                                                        double, Coords*, double*) const;
template bool AncfCableElement<3>::AddAxialDampingForce(const Coords&, const Coords&, double,
                                                        double, Coords*, double*) const;
template double AncfCableElement<2>::DirectionalKineticEnergy(const Coords&, const Coords&,
                                                              const double*,
                                                              const double*) const;
template double AncfCableElement<3>::DirectionalKineticEnergy(const Coords&, const Coords&,
                                                              const double*,
                                                              const double*) const;

}  // namespace cablesim
