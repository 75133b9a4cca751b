#include "engine/elements/ancf_cable_element.h"

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

#include <Eigen/Geometry>

#include "engine/elements/ancf_cable_element_force.h"
#include "engine/elements/hermite_shape.h"

namespace cablesim {
namespace {

// upper += wl S^T h S on the node blocks k <= j of a 4D x 4D matrix whose
// node block (k, j) is sum over points of (wl s_k s_j) h: the symmetric
// element matrices' (added mass, drag tangent) upper blocks, each
// coefficient and product as a sum over all 16 blocks forms it.
template <int D>
void AddUpperShapeBlocks(double wl, const double* s, const Eigen::Matrix<double, D, D>& h,
                         Eigen::Matrix<double, 4 * D, 4 * D>* upper) {
  for (int k = 0; k < 4; ++k)
    for (int j = k; j < 4; ++j) upper->template block<D, D>(k * D, j * D) += (wl * s[k] * s[j]) * h;
}

// m += U with U's blocks k <= j and their transposes below: 10 of the 16
// block sums, the lower 6 mirrored (each the upper block's transpose, equal
// to its own sum up to the rounding of s_j s_k against s_k s_j and of h's
// asymmetry by an ulp; the Newton matrix reads only the upper blocks).
template <int D>
void AddMirroredUpperBlocks(const Eigen::Matrix<double, 4 * D, 4 * D>& upper,
                            Eigen::Matrix<double, 4 * D, 4 * D>* m) {
  for (int k = 0; k < 4; ++k) {
    m->template block<D, D>(k * D, k * D) += upper.template block<D, D>(k * D, k * D);
    for (int j = k + 1; j < 4; ++j) {
      m->template block<D, D>(k * D, j * D) += upper.template block<D, D>(k * D, j * D);
      m->template block<D, D>(j * D, k * D) += upper.template block<D, D>(k * D, j * D).transpose();
    }
  }
}

}  // namespace

template <int D>
AncfCableElement<D>::AncfCableElement(double length_m, double ea_n, double ei_n_m2,
                                      BendingModel bending, int gauss_points,
                                      AxialLaw axial_law,
                                      std::shared_ptr<const TensionTable> table)
    : length_(length_m), ea_(ea_n), ei_(ei_n_m2), bending_(bending), axial_law_(axial_law),
      table_(std::move(table)), rule_(MakeGaussRule(gauss_points)) {
  set_length(length_m);
}

template <int D>
void AncfCableElement<D>::set_length(double length_m) {
  length_ = length_m;
  for (int g = 0; g < rule_.n; ++g) {
    HermiteShape(rule_.xi[g], length_, s0_[g]);
    HermiteShapeD1(rule_.xi[g], length_, d1_[g]);
    HermiteShapeD2(rule_.xi[g], length_, d2_[g]);
  }
}

template <int D>
Eigen::Matrix4d AncfCableElement<D>::ScalarMassMatrix(double length_m,
                                                      double mass_per_length_kg_m) {
  const double l = length_m;
  const double m = mass_per_length_kg_m * l;
  Eigen::Matrix4d c;
  c << 156, 22 * l, 54, -13 * l,
       22 * l, 4 * l * l, 13 * l, -3 * l * l,
       54, 13 * l, 156, -22 * l,
       -13 * l, -3 * l * l, -22 * l, 4 * l * l;
  c *= m / 420;
  return c;
}

template <int D>
typename AncfCableElement<D>::Matrix AncfCableElement<D>::MassMatrix(
    double mass_per_length_kg_m) const {
  const Eigen::Matrix4d c = ScalarMassMatrix(length_, mass_per_length_kg_m);
  Matrix mass = Matrix::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int d = 0; d < D; ++d) mass(i * D + d, j * D + d) = c(i, j);
  return mass;
}

template <int D>
typename AncfCableElement<D>::Coords AncfCableElement<D>::GravityForceOfLength(
    double length_m, double mass_per_length_kg_m, const Point& g) {
  const double l = length_m;
  const double m = mass_per_length_kg_m * l;
  Coords q;
  q.template segment<D>(0) = m * g / 2;
  q.template segment<D>(D) = m * l * g / 12;
  q.template segment<D>(2 * D) = m * g / 2;
  q.template segment<D>(3 * D) = -m * l * g / 12;
  return q;
}

template <int D>
typename AncfCableElement<D>::Coords AncfCableElement<D>::GravityForce(
    double mass_per_length_kg_m, const Point& g) const {
  return GravityForceOfLength(length_, mass_per_length_kg_m, g);
}

template <int D>
typename AncfCableElement<D>::Point AncfCableElement<D>::Position(const Coords& e,
                                                                  double xi) const {
  double s[4];
  HermiteShape(xi, length_, s);
  Point r = Point::Zero();
  for (int k = 0; k < 4; ++k) r += s[k] * e.template segment<D>(k * D);
  return r;
}

template <int D>
typename AncfCableElement<D>::Point AncfCableElement<D>::Slope(const Coords& e,
                                                               double xi) const {
  double s[4];
  HermiteShapeD1(xi, length_, s);
  Point r = Point::Zero();
  for (int k = 0; k < 4; ++k) r += s[k] * e.template segment<D>(k * D);
  return r;
}

template <int D>
typename AncfCableElement<D>::BMatrix AncfCableElement<D>::B(int g) const {
  BMatrix b = BMatrix::Zero();
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < D; ++d) {
      b(d, k * D + d) = d1_[g][k];
      b(D + d, k * D + d) = d2_[g][k];
    }
  return b;
}

template <int D>
typename AncfCableElement<D>::Energy AncfCableElement<D>::StrainEnergy(const Coords& e) const {
  // One loop per kind of law (a table's call inside the others' loop cost
  // them 12 % of this function, measured by callgrind on a chain's statics).
  auto loop = [&](auto table_law) {
    Energy energy;
    for (int g = 0; g < rule_.n; ++g) {
      Point u = Point::Zero(), w = Point::Zero();
      for (int k = 0; k < 4; ++k) {
        u += d1_[g][k] * e.template segment<D>(k * D);
        w += d2_[g][k] * e.template segment<D>(k * D);
      }
      const double a = u.squaredNorm(), b = u.dot(w), c = w.squaredNorm();
      const double wl = rule_.weight[g] * length_;
      if constexpr (decltype(table_law)::value) {
        energy.axial += wl * (visco_ ? visco_->StoredEnergy(visco_first_ + g, std::sqrt(a) - 1)
                                     : table_->Energy(std::sqrt(a) - 1));
      } else {
        const double eps =
            axial_law_ == AxialLaw::kEngineering ? std::sqrt(a) - 1 : (a - 1) / 2;
        energy.axial += wl * 0.5 * ea_ * eps * eps;
      }
      double kappa2 = 0;
      if (bending_ == BendingModel::kExact) {
        kappa2 = (a * c - b * b) / (a * a * a);
      } else if (bending_ == BendingModel::kLinear) {
        kappa2 = c;
      }
      energy.bending += wl * 0.5 * ei_ * kappa2;
    }
    return energy;
  };
  return axial_law_ == AxialLaw::kTable || axial_law_ == AxialLaw::kViscoelastic
             ? loop(std::true_type{})
             : loop(std::false_type{});
}

template <int D>
void AncfCableElement<D>::AxialStrains(const Coords& e, double* out) const {
  for (int g = 0; g < rule_.n; ++g) {
    Point u = Point::Zero();
    for (int k = 0; k < 4; ++k) u += d1_[g][k] * e.template segment<D>(k * D);
    out[g] = u.norm() - 1;
  }
}

// The TABLE and VISCOELASTIC laws' loops are instantiated in
// ancf_cable_element_table.cc.
extern template void AncfCableElement<2>::ElasticForceWith<AxialLaw::kTable>(
    const Coords&, Coords*, Matrix*, Coords*) const;
extern template void AncfCableElement<3>::ElasticForceWith<AxialLaw::kTable>(
    const Coords&, Coords*, Matrix*, Coords*) const;
extern template void AncfCableElement<2>::ElasticForceWith<AxialLaw::kViscoelastic>(
    const Coords&, Coords*, Matrix*, Coords*) const;
extern template void AncfCableElement<3>::ElasticForceWith<AxialLaw::kViscoelastic>(
    const Coords&, Coords*, Matrix*, Coords*) const;

template <int D>
void AncfCableElement<D>::ElasticForce(const Coords& e, Coords* force, Matrix* tangent,
                                       Coords* roundoff) const {
  // The law chosen once per element, not per Gauss point (the hot loop).
  if (axial_law_ == AxialLaw::kEngineering)
    ElasticForceWith<AxialLaw::kEngineering>(e, force, tangent, roundoff);
  else if (axial_law_ == AxialLaw::kTable)
    ElasticForceWith<AxialLaw::kTable>(e, force, tangent, roundoff);
  else if (axial_law_ == AxialLaw::kViscoelastic)
    ElasticForceWith<AxialLaw::kViscoelastic>(e, force, tangent, roundoff);
  else
    ElasticForceWith<AxialLaw::kGreenLagrange>(e, force, tangent, roundoff);
}

template <int D>
void AncfCableElement<D>::AddUpperBlocks(int g, double wl, const Block& huu, const Block& huw,
                                         const Block& hww, Matrix* tangent) const {
  // B's node block k is [s_k' I; s_k'' I], so block (k, m) of B^T H B is
  // s_k' s_m' H_uu + s_k' s_m'' H_uw + s_k'' s_m' H_wu + s_k'' s_m'' H_ww.
  const double* s1 = d1_[g];
  const double* s2 = d2_[g];
  if (huw.isZero(0) && hww.isZero(0)) {
    AddUpperAxialBlocks(g, wl, huu, tangent);
    return;
  }
  for (int k = 0; k < 4; ++k) {
    const double p1 = wl * s1[k], p2 = wl * s2[k];
    for (int m = k; m < 4; ++m) {
      const double q1 = s1[m], q2 = s2[m];
      tangent->template block<D, D>(k * D, m * D) +=
          (p1 * q1) * huu + (p1 * q2) * huw + (p2 * q1) * huw.transpose() + (p2 * q2) * hww;
    }
  }
}

template <int D>
void AncfCableElement<D>::AddUpperAxialBlocks(int g, double wl, const Block& huu,
                                              Matrix* tangent) const {
  // No curvature terms (bending NONE, a mooring line's usual model): the
  // sums of AddUpperBlocks without their exact-zero products, a quarter of
  // the work.
  const double* s1 = d1_[g];
  for (int k = 0; k < 4; ++k) {
    const double p1 = wl * s1[k];
    for (int m = k; m < 4; ++m) tangent->template block<D, D>(k * D, m * D) += (p1 * s1[m]) * huu;
  }
}

template <int D>
void AncfCableElement<D>::MirrorUpperBlocks(Matrix* tangent) {
  for (int k = 0; k < 4; ++k)
    for (int m = k + 1; m < 4; ++m)
      tangent->template block<D, D>(m * D, k * D) =
          tangent->template block<D, D>(k * D, m * D).transpose();
}

template <int D>
void AncfCableElement<D>::AddDampingMatrix(const Coords& e, double axial_s, double bending_s,
                                           Matrix* c) const {
  // Rows of the curvature vector: 1 in the plane, 3 in space.
  constexpr int kRows = D == 2 ? 1 : 3;
  using GBlock = Eigen::Matrix<double, kRows, D>;
  const double ca = ea_ * axial_s, cb = bending_ == BendingModel::kNone ? 0.0 : ei_ * bending_s;
  // Two passes, as AddMorison: the points' blocks (a division each,
  // independent), then the sums in the points' order (the same roundings).
  Block huu[GaussRule::kMaxPoints], huw[GaussRule::kMaxPoints], hww[GaussRule::kMaxPoints];
  for (int g = 0; g < rule_.n; ++g) {
    Point u = Point::Zero(), w = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      u += d1_[g][k] * e.template segment<D>(k * D);
      w += d2_[g][k] * e.template segment<D>(k * D);
    }
    // Engineering strain: d eps/dt = u.udot / |u|.
    const double axial_scale =
        axial_law_ != AxialLaw::kGreenLagrange && u.squaredNorm() > 0 ? 1 / u.squaredNorm() : 1.0;
    // (ca s u) u^T entry by entry: Eigen's outer product, rounding for
    // rounding, without its 3-vector temporary (a 16-byte load of two
    // 8-byte stores, which stalled store forwarding: a third of this
    // function's time on the OC4 mooring).
    const double cs = ca * axial_scale;
    for (int i = 0; i < D; ++i) {
      const double cu = cs * u(i);
      for (int j = 0; j < D; ++j) huu[g](i, j) = cu * u(j);
    }
    if (cb == 0) continue;
    // k = u x w / a^(3/2), a = u.u: dk/dw = [u]x / a^(3/2),
    // dk/du = -[w]x / a^(3/2) - 3 k u^T / a.
    const double a = u.squaredNorm(), ia15 = 1 / (a * std::sqrt(a));
    GBlock gu, gw;
    if constexpr (D == 2) {
      const double k = (u.x() * w.y() - u.y() * w.x()) * ia15;
      gu << w.y() * ia15, -w.x() * ia15;
      gu -= (3 * k / a) * u.transpose();
      gw << -u.y() * ia15, u.x() * ia15;
    } else {
      const Point k = u.cross(w) * ia15;
      Block wx, ux;
      wx << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
      ux << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;
      gu = -ia15 * wx - (3 / a) * k * u.transpose();
      gw = ia15 * ux;
    }
    huu[g] += cb * gu.transpose() * gu;
    huw[g] = cb * gu.transpose() * gw;
    hww[g] = cb * gw.transpose() * gw;
  }
  Matrix upper = Matrix::Zero();
  for (int g = 0; g < rule_.n; ++g) {
    const double wl = rule_.weight[g] * length_;
    // Without bending the curvature blocks are zero by construction:
    // AddUpperBlocks' own test for that (18 compares), skipped.
    if (cb == 0) {
      AddUpperAxialBlocks(g, wl, huu[g], &upper);
    } else {
      AddUpperBlocks(g, wl, huu[g], huw[g], hww[g], &upper);
    }
  }
  MirrorUpperBlocks(&upper);
  *c += upper;
}

template <int D>
void AncfCableElement<D>::AddDrag(const Coords& e, const Coords& edot, const Point& current,
                                  double kn, double kt, Coords* force, Matrix* c) const {
  Point flow[GaussRule::kMaxPoints];
  for (int g = 0; g < rule_.n; ++g) flow[g] = current;
  AddMorison(e, edot, flow, nullptr, kn, kt, 0, 0, nullptr, force, c);
}

template <int D>
typename AncfCableElement<D>::Point AncfCableElement<D>::GaussPosition(const Coords& e,
                                                                       int g) const {
  Point r = Point::Zero();
  for (int k = 0; k < 4; ++k) r += s0_[g][k] * e.template segment<D>(k * D);
  return r;
}

template <int D>
void AncfCableElement<D>::AddMorison(const Coords& e, const Coords& edot,
                                     const Point* flow_velocity, const Point* flow_acceleration,
                                     double kn, double kt, double mi_n, double mi_t,
                                     const bool* wet, Coords* force, Matrix* c) const {
  // Two passes: first every point's load (three square roots and a
  // division, independent from point to point, so that the processor
  // overlaps them), then the sums into force and c in the order of the
  // points, as one pass would add them (the same roundings).
  FlowPoint points[GaussRule::kMaxPoints];
  for (int g = 0; g < rule_.n; ++g) {
    if (wet && !wet[g]) {
      points[g].kind = FlowPoint::kDry;
      continue;
    }
    FlowLoadAt(g, e, edot, flow_velocity[g],
               flow_acceleration ? &flow_acceleration[g] : nullptr, kn, kt, mi_n, mi_t,
               c != nullptr, &points[g]);
  }
  for (int g = 0; g < rule_.n; ++g) {
    const FlowPoint& p = points[g];
    if (p.kind == FlowPoint::kDry) continue;
    const double* s0 = s0_[g];
    const double wl = rule_.weight[g] * length_;
    if (p.kind == FlowPoint::kInertiaOnly) {
      for (int k = 0; k < 4; ++k)
        force->template segment<D>(k * D) += (wl * s0[k] * mi_n) * p.q;
      continue;
    }
    for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) += (wl * s0[k]) * p.q;
    if (!c) continue;
    // All 16 blocks, summed into c as they come: c holds other terms'
    // tangents on entry, and the upper blocks' sums in this order are
    // what the Newton matrix reads (summing the 10 upper blocks apart and
    // mirroring them, as AddDirectionalMass does, moved the OC4 mooring's
    // output by 1e-12 relative).
    for (int k = 0; k < 4; ++k)
      for (int m = 0; m < 4; ++m)
        c->template block<D, D>(k * D, m * D) += (wl * s0[k] * s0[m]) * p.h;
  }
}

template <int D>
void AncfCableElement<D>::FlowLoadAt(int g, const Coords& e, const Coords& edot,
                                     const Point& flow, const Point* accel, double kn, double kt,
                                     double mi_n, double mi_t, bool tangent,
                                     FlowPoint* point) const {
  const double* s0 = s0_[g];
  Point u = Point::Zero(), v = flow;
  for (int k = 0; k < 4; ++k) {
    u += d1_[g][k] * e.template segment<D>(k * D);
    v -= s0[k] * edot.template segment<D>(k * D);
  }
  const double un = u.norm();
  if (!(un > 0)) {
    // No tangent (a collapsed point): no drag, but the flow's inertia
    // acts (with the coefficient across the line: no axis to split on).
    point->kind = accel ? FlowPoint::kInertiaOnly : FlowPoint::kDry;
    if (accel) point->q = *accel;
    return;
  }
  point->kind = FlowPoint::kLoad;
  const Point t = u / un;
  const Point vt = t.dot(v) * t, vn = v - vt;
  const double an = vn.norm(), at = vt.norm();
  Point& q = point->q;
  q = kn * an * vn + kt * at * vt;
  if (accel) {
    // mi_n P du/dt + mi_t t t^T du/dt, P = I - t t^T (one product when
    // the two are equal, as they were before the split).
    if (mi_t == mi_n) {
      q += mi_n * *accel;
    } else {
      const Point a_t = t.dot(*accel) * t;
      q += mi_n * (*accel - a_t) + mi_t * a_t;
    }
  }
  if (!tangent) return;
  Block& h = point->h;
  h = (2 * kt * at) * t * t.transpose();
  if (an > 0) {
    h += (kn * an) * (Block::Identity() - t * t.transpose()) + (kn / an) * vn * vn.transpose();
  }
}

template <int D>
void AncfCableElement<D>::AddDirectionalMass(const Coords& e, const Coords& edd,
                                             const double* a_n, const double* a_t, Coords* force,
                                             Matrix* m) const {
  // Two passes: first every point's A_g and A_g r''(x_g) (a square root
  // and a division each, independent from point to point, so that the
  // processor overlaps them), then the sums into force and m in the order
  // of the points, as one pass would add them (the same roundings).
  Block a[GaussRule::kMaxPoints];
  Point q[GaussRule::kMaxPoints];
  Matrix upper;  // the matrix's blocks k <= j (`m` only)
  if (m) upper.setZero();
  for (int g = 0; g < rule_.n; ++g) {
    if (a_n[g] == 0 && a_t[g] == 0) continue;
    const double* s0 = s0_[g];
    Point u = Point::Zero(), acc = Point::Zero();
    for (int k = 0; k < 4; ++k) {
      u += d1_[g][k] * e.template segment<D>(k * D);
      acc += s0[k] * edd.template segment<D>(k * D);
    }
    const double un = u.norm();
    a[g] = a_n[g] * Block::Identity();
    // A collapsed point has no axis: a_n in every direction.
    if (un > 0) {
      const Point t = u / un;
      a[g] += (a_t[g] - a_n[g]) * t * t.transpose();
    }
    q[g] = a[g] * acc;
  }
  for (int g = 0; g < rule_.n; ++g) {
    if (a_n[g] == 0 && a_t[g] == 0) continue;
    const double* s0 = s0_[g];
    const double wl = rule_.weight[g] * length_;
    for (int k = 0; k < 4; ++k) force->template segment<D>(k * D) -= (wl * s0[k]) * q[g];
    if (!m) continue;
    // Symmetric: the blocks k <= j only, mirrored below.
    AddUpperShapeBlocks<D>(wl, s0, a[g], &upper);
  }
  if (m) AddMirroredUpperBlocks<D>(upper, m);
}

namespace {

// The element's Gram matrix G = E^T E (module doc of
// AddDiscreteGradientCorrection) and E.
template <int D>
void GramOf(const Eigen::Matrix<double, 4 * D, 1>& e, double l, Eigen::Matrix<double, D, 3>* ev,
            Eigen::Matrix3d* g) {
  ev->col(0) = (e.template segment<D>(2 * D) - e.template segment<D>(0)) / l;
  ev->col(1) = e.template segment<D>(D);
  ev->col(2) = e.template segment<D>(3 * D);
  *g = ev->transpose() * *ev;
}

}  // namespace

template <int D>
void AncfCableElement<D>::AddDiscreteGradientCorrection(const Coords& e0, const Coords& e1,
                                                        Coords* correction) const {
  using EMatrix = Eigen::Matrix<double, D, 3>;
  const double l = length_;
  EMatrix ev0, ev1, evm;
  Eigen::Matrix3d g0, g1, gm;
  GramOf<D>(e0, l, &ev0, &g0);
  GramOf<D>(e1, l, &ev1, &g1);
  const Coords em = 0.5 * (e0 + e1);
  GramOf<D>(em, l, &evm, &gm);  // the Gram matrix of the midpoint
  // p_dg: the discrete gradient in G; p_mid: dUt/dG at G(em).
  Eigen::Matrix3d p_dg = Eigen::Matrix3d::Zero(), p_mid = Eigen::Matrix3d::Zero();
  const bool exact = bending_ == BendingModel::kExact;
  const double k = 0.5 * ei_;
  for (int gp = 0; gp < rule_.n; ++gp) {
    const Eigen::Vector3d al(l * d1_[gp][2], d1_[gp][1], d1_[gp][3]);
    const Eigen::Vector3d be(l * d2_[gp][2], d2_[gp][1], d2_[gp][3]);
    const Eigen::Matrix3d aa = al * al.transpose(), bb = be * be.transpose();
    const Eigen::Matrix3d ab = 0.5 * (al * be.transpose() + be * al.transpose());
    const double wl = rule_.weight[gp] * l;
    auto abc = [&](const Eigen::Matrix3d& g, double* a, double* b, double* c) {
      *a = al.dot(g * al);
      *b = al.dot(g * be);
      *c = be.dot(g * be);
    };
    double a0, b0, c0, a1, b1, c1, am, bm, cm;
    abc(g0, &a0, &b0, &c0);
    abc(g1, &a1, &b1, &c1);
    abc(gm, &am, &bm, &cm);
    // Axial psi_a = EA (a - 1) / 4 (linear in a: exact at the mean) and
    // LINEAR bending psi_c = EI / 2 (constant).
    double fa = 0.25 * ea_ * (0.5 * (a0 + a1) - 1), fb = 0, fc = 0;
    double ga = 0.25 * ea_ * (am - 1), gb = 0, gc = 0;
    if (axial_law_ == AxialLaw::kEngineering) {
      // psi = EA/2 (s - 1)^2, s = sqrt(a): the exact difference quotient
      // (psi(a1) - psi(a0)) / (a1 - a0) = EA/2 (s0 + s1 - 2) / (s0 + s1).
      const double s0 = std::sqrt(a0), s1 = std::sqrt(a1), sm = std::sqrt(am);
      fa = 0.5 * ea_ * (s0 + s1 - 2) / (s0 + s1);
      ga = 0.5 * ea_ * (sm - 1) / sm;
    } else if (axial_law_ == AxialLaw::kTable) {
      // psi = W(s - 1): (W(e1) - W(e0)) / (a1 - a0) = Tbar / (s0 + s1),
      // Tbar the table's exact mean tension over [e0, e1]; dpsi/da =
      // T / (2 s) at the midpoint.
      const double s0 = std::sqrt(a0), s1 = std::sqrt(a1), sm = std::sqrt(am);
      fa = table_->MeanTension(s0 - 1, s1 - 1) / (s0 + s1);
      ga = 0.5 * table_->At(sm - 1).tension / sm;
    }
    if (bending_ == BendingModel::kLinear) fc = gc = k;
    if (exact) {
      // psi = k (c A(a) - b^2 B(a)), A = a^-2, B = a^-3: the discrete
      // product rule with the exact difference quotients of A and B.
      const double i0 = 1 / a0, i1 = 1 / a1;
      const double abar = 0.5 * (i0 * i0 + i1 * i1), bbar = 0.5 * (i0 * i0 * i0 + i1 * i1 * i1);
      const double da = -(a0 + a1) * (i0 * i0) * (i1 * i1);
      const double db = -(a0 * a0 + a0 * a1 + a1 * a1) * (i0 * i0 * i0) * (i1 * i1 * i1);
      fa += k * (0.5 * (c0 + c1) * da - 0.5 * (b0 * b0 + b1 * b1) * db);
      fb += k * (-(b0 + b1) * bbar);
      fc += k * abar;
      const double ia = 1 / am, ia2 = ia * ia, ia3 = ia2 * ia, ia4 = ia2 * ia2;
      ga += k * (-2 * cm * ia3 + 3 * bm * bm * ia4);
      gb += k * (-2 * bm * ia3);
      gc += k * ia2;
    }
    p_dg += wl * (fa * aa + fb * ab + fc * bb);
    p_mid += wl * (ga * aa + gb * ab + gc * bb);
  }
  // Force on the three vectors 2 E P; on the coordinates through
  // d / l = (r_A - r_O) / l.
  const EMatrix fv = 2 * evm * (p_dg - p_mid);
  correction->template segment<D>(0) -= fv.col(0) / l;
  correction->template segment<D>(D) += fv.col(1);
  correction->template segment<D>(2 * D) += fv.col(0) / l;
  correction->template segment<D>(3 * D) += fv.col(2);
}

template class AncfCableElement<2>;
template class AncfCableElement<3>;

}  // namespace cablesim
