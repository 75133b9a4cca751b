#include "engine/forces/body_fluid_load.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include <Eigen/Geometry>

#include "engine/linear/rounding.h"

namespace cablesim {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

BodyFluidLoad::BodyFluidLoad(const Params& p, int coord, int dim)
    : p_(p), coord_(coord), dim_(dim) {
  area_ = std::numbers::pi * p.diameter_m * p.diameter_m / 4;
  up_.setZero();
  up_.head(dim) = p.up.head(dim);
  up_.normalize();
  // T: r_p = r_c + c_1 e1 + c_2 e2 + c_3 e3 (spatial), r_c + c_x u + c_y J u
  // (planar, J u = e_z x u = (-u_y, u_x)).
  const Vector3d& c = p.center_body;
  has_offset_ = dim == 2 ? (c.x() != 0 || c.y() != 0) : !c.isZero(0);
  t_.topLeftCorner(dim, dim).setIdentity();
  if (dim == 2) {
    t_.block<2, 2>(0, 2) << c.x(), -c.y(), c.y(), c.x();
  } else {
    for (int k = 0; k < 3; ++k) t_.block<3, 3>(0, 3 + 3 * k) = c(k) * Matrix3d::Identity();
  }
}

Vector3d BodyFluidLoad::MapPoint(const VectorXd& x) const {
  Vector3d r = Vector3d::Zero();
  if (!has_offset_) {
    r.head(dim_) = x.segment(coord_, dim_);
    return r;
  }
  const int n = stride();
  for (int k = 0; k < n; ++k) r += t_.col(k) * x(coord_ + k);
  return r;
}

BodyFluidLoad::Generalized BodyFluidLoad::Spread(const Vector3d& f) const {
  Generalized g = Generalized::Zero();
  g.head(stride()) = t_.leftCols(stride()).transpose() * f;
  return g;
}


BodyFluidLoad::GeneralizedMatrix BodyFluidLoad::Spread(const Matrix3d& c) const {
  GeneralizedMatrix g = GeneralizedMatrix::Zero();
  const int n = stride();
  g.topLeftCorner(n, n) = t_.leftCols(n).transpose() * c * t_.leftCols(n);
  return g;
}

void BodyFluidLoad::AddForce(const Vector3d& f, VectorXd* full) const {
  if (!has_offset_) {
    for (int d = 0; d < dim_; ++d) (*full)(coord_ + d) += f(d);
    return;
  }
  const Generalized g = Spread(f);
  for (int k = 0; k < stride(); ++k) (*full)(coord_ + k) += g(k);
}

void BodyFluidLoad::AddRounding(const Vector3d& size, VectorXd* roundoff) const {
  if (!has_offset_) {
    for (int d = 0; d < dim_; ++d) (*roundoff)(coord_ + d) += kSumRounding * size(d);
    return;
  }
  // Entry k of T^T f sums T_dk f_d: its terms' sizes add to (|T|^T size)_k.
  const int n = stride();
  for (int k = 0; k < n; ++k)
    (*roundoff)(coord_ + k) += kSumRounding * t_.col(k).cwiseAbs().dot(size);
}

void BodyFluidLoad::ScatterTangent(const Matrix3d& k, const CoordinateMap& map, double scale,
                                   SkylineLdlt* matrix) const {
  if (!has_offset_) {
    map.ScatterBlock(coord_, k, scale, matrix);
    return;
  }
  const GeneralizedMatrix g = Spread(k);
  map.ScatterRange(coord_, stride(), g.data(), kMaxStride, scale, matrix);
}

Vector3d BodyFluidLoad::Axis(const VectorXd& q) const {
  if (!p_.along_axis) return up_;
  // The body's natural coordinates: [r_c, u] (planar, u its x axis) or
  // [r_c, e1, e2, e3] (spatial); a = R a_b (planar: a_bx u + a_by e_z x u,
  // both of length |u|). a_b = e_x gives u (e1) exactly.
  const Vector3d& ab = p_.axis_body;
  Vector3d a = Vector3d::Zero();
  if (dim_ == 2) {
    const Eigen::Vector2d u = q.segment<2>(coord_ + 2);
    a.head<2>() = ab.x() * u + ab.y() * Eigen::Vector2d(-u.y(), u.x());
  } else {
    for (int k = 0; k < 3; ++k) a += ab(k) * q.segment<3>(coord_ + 3 + 3 * k);
  }
  const double n = a.norm();
  return n > 0 ? Vector3d(a / n) : up_;
}

double BodyFluidLoad::Submerged(double z) const {
  return std::clamp(p_.height_m / 2 - z, 0.0, p_.height_m);
}

double BodyFluidLoad::Height(const VectorXd& q) const {
  double h = -p_.still_level_m;
  const Vector3d r = MapPoint(q);
  for (int d = 0; d < dim_; ++d) h += up_(d) * r(d);
  return h;
}

BodyFluidLoad::GeneralizedMatrix BodyFluidLoad::AddedMass(const VectorXd& q0) const {
  const double v = p_.density_kg_m3 * area_ * Submerged(Height(q0));
  const Vector3d axis = Axis(q0);
  const Matrix3d vertical = axis * axis.transpose();
  Matrix3d m = v * (p_.added_mass * (Matrix3d::Identity() - vertical) +
                    p_.heave_added_mass * vertical);
  // Planar: only the plane's block is used; zero the rest for clarity.
  if (dim_ == 2) {
    m.row(2).setZero();
    m.col(2).setZero();
  }
  return Spread(m);
}

double BodyFluidLoad::AddHydrostatic(const VectorXd& q, double scale, VectorXd* force,
                                     Matrix3d* stiffness) const {
  const double z = Height(q);
  const double f = scale * p_.density_kg_m3 * p_.g_m_s2 * area_ * Submerged(z);
  AddForce(f * up_, force);
  if (stiffness != nullptr && z > -p_.height_m / 2 && z < p_.height_m / 2)
    *stiffness += scale * p_.density_kg_m3 * p_.g_m_s2 * area_ * up_ * up_.transpose();
  return std::abs(f);
}

double BodyFluidLoad::HydrostaticEnergy(const VectorXd& q, double scale) const {
  const double z = Height(q), h = p_.height_m;
  double p = 0;  // P(z), -P'(z) = s(z)
  if (z >= h / 2) {
    p = 0;
  } else if (z > -h / 2) {
    p = 0.5 * (z - h / 2) * (z - h / 2);
  } else {
    p = 0.5 * h * h - h * (z + h / 2);
  }
  return scale * p_.density_kg_m3 * p_.g_m_s2 * area_ * p;
}

bool BodyFluidLoad::dynamic(bool has_waves) const {
  return p_.drag != 0 || p_.heave_drag != 0 || has_area_drag() || has_waves;
}

namespace {

// [e]x, the matrix of e x.
Matrix3d CrossMatrix(const Vector3d& e) {
  Matrix3d m;
  m << 0, -e.z(), e.y(), e.z(), 0, -e.x(), -e.y(), e.x(), 0;
  return m;
}

// k times the symmetric part of d(B |x| x)/dx = B (|x| I + x x^T / |x|).
Matrix3d QuadraticTangent(double k, const Matrix3d& b, const Vector3d& x) {
  const double n = x.norm();
  if (!(n > 0)) return Matrix3d::Zero();
  const Matrix3d c = k * b * (n * Matrix3d::Identity() + x * x.transpose() / n);
  return 0.5 * (c + c.transpose());
}

}  // namespace

void BodyFluidLoad::AreaDrag(const VectorXd& q, const VectorXd& qdot, double t,
                             const WaveField* waves, Generalized* force,
                             GeneralizedMatrix* damping) const {
  force->setZero();
  if (damping != nullptr) damping->setZero();
  if (!has_area_drag()) return;
  // The wetted fraction: the cylinder's, or all of a body without one.
  const double f = p_.height_m > 0 ? Submerged(Height(q)) / p_.height_m : 1;
  if (!(f > 0)) return;
  const double k = 0.5 * p_.density_kg_m3 * f;
  Vector3d r = Vector3d::Zero(), v = Vector3d::Zero();
  r.head(dim_) = q.segment(coord_, dim_);
  v.head(dim_) = qdot.segment(coord_, dim_);
  Vector3d u = p_.current_m_s;
  if (waves != nullptr) u += waves->At(r, t).velocity_m_s;
  // The body's axes R = [e1 e2 e3] and angular velocity.
  Matrix3d rot;
  Vector3d omega = Vector3d::Zero();
  Vector3d axis_u = Vector3d::Zero(), axis_udot = Vector3d::Zero();  // planar
  if (dim_ == 2) {
    axis_u.head(2) = q.segment(coord_ + 2, 2);
    axis_udot.head(2) = qdot.segment(coord_ + 2, 2);
    const Vector3d e1 = axis_u.normalized();
    rot.col(0) = e1;
    rot.col(1) = Vector3d::UnitZ().cross(e1);
    rot.col(2) = Vector3d::UnitZ();
    omega.z() = axis_u.cross(axis_udot).z() / axis_u.squaredNorm();
  } else {
    for (int a = 0; a < 3; ++a) {
      rot.col(a) = q.segment<3>(coord_ + 3 + 3 * a);
      omega += 0.5 * rot.col(a).cross(qdot.segment<3>(coord_ + 3 + 3 * a));
    }
  }
  Vector3d vr = u - v;
  if (dim_ == 2) vr.z() = 0;
  const Matrix3d b = rot * p_.drag_area.asDiagonal() * rot.transpose();
  const Vector3d drag = k * vr.norm() * (b * vr);
  force->head(dim_) = drag.head(dim_);
  if (damping != nullptr) {
    damping->topLeftCorner(dim_, dim_) = QuadraticTangent(k, b, vr).topLeftCorner(dim_, dim_);
  }
  if (p_.rotational_drag_area.isZero(0)) return;
  const Matrix3d bw = rot * p_.rotational_drag_area.asDiagonal() * rot.transpose();
  const Vector3d moment = -k * omega.norm() * (bw * omega);
  if (dim_ == 2) {
    // T e_z x u / |u|^2 on u (omega = p . udot with the same p).
    const Vector3d p = Vector3d::UnitZ().cross(axis_u) / axis_u.squaredNorm();
    force->segment<2>(2) = moment.z() * p.head(2);
    if (damping != nullptr) {
      damping->block<2, 2>(2, 2) = 2 * k * p_.rotational_drag_area.z() * std::abs(omega.z()) *
                                   p.head(2) * p.head(2).transpose();
    }
    return;
  }
  Eigen::Matrix<double, 3, 9> s;
  for (int a = 0; a < 3; ++a) {
    const Matrix3d sa = CrossMatrix(rot.col(a));
    s.block<3, 3>(0, 3 * a) = sa;
    force->segment<3>(3 + 3 * a) = -0.5 * sa * moment;  // (1/2) M x e_a
  }
  if (damping != nullptr) {
    damping->block<9, 9>(3, 3) = 0.25 * s.transpose() * QuadraticTangent(k, bw, omega) * s;
  }
}

Vector3d BodyFluidLoad::DynamicForce(const VectorXd& q, const VectorXd& qdot, double t,
                                     const WaveField* waves, Matrix3d* damping) const {
  const Vector3d r = MapPoint(q), v = MapPoint(qdot);
  const double rho = p_.density_kg_m3;
  const double z = Height(q);
  const double s = Submerged(z);
  // The split's direction: the vertical, or the body's axis.
  const Vector3d axis = Axis(q);
  Vector3d u = p_.current_m_s, dudt = Vector3d::Zero();
  Vector3d force = Vector3d::Zero();
  if (waves != nullptr) {
    const WaveField::Kinematics k = waves->At(r, t);
    u += k.velocity_m_s;
    dudt = k.acceleration_m_s2;
    // The wave's change of the buoyancy: the level rises by eta.
    force += rho * p_.g_m_s2 * area_ * (Submerged(z - k.elevation_m) - s) * up_;
    // Froude-Krylov and added-mass inertia on the wetted volume.
    const double a_up = axis.dot(dudt);
    const Vector3d a_h = dudt - a_up * axis;
    force +=
        rho * area_ * s * ((1 + p_.added_mass) * a_h + (1 + p_.heave_added_mass) * a_up * axis);
  }
  if (damping != nullptr) damping->setZero();
  if (s > 0 && (p_.drag != 0 || p_.heave_drag != 0)) {
    const Vector3d vr = u - v;
    const double vr_up = axis.dot(vr);
    const Vector3d vh = vr - vr_up * axis;
    const double kh = 0.5 * rho * p_.drag * p_.diameter_m * s;
    const double kv = 0.5 * rho * p_.heave_drag * area_;
    const double nh = vh.norm();
    force += kh * nh * vh + kv * std::abs(vr_up) * vr_up * axis;
    if (damping != nullptr) {
      if (nh > 0) {
        const Matrix3d across = Matrix3d::Identity() - axis * axis.transpose();
        *damping += kh * (nh * across + vh * vh.transpose() / nh);
      }
      *damping += 2 * kv * std::abs(vr_up) * axis * axis.transpose();
    }
  }
  if (dim_ == 2) force.z() = 0;
  return force;
}

void BodyFluidForces::AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
  for (const BodyFluidLoad& b : loads_) {
    Matrix3d k = Matrix3d::Zero();
    const double f = b.AddHydrostatic(*s.q, s.load_factor, out->full, out->matrix ? &k : nullptr);
    // Its size and rounding on their own: at a floating body's draft F_s
    // cancels the weight in the same entries (MultibodyModel::NetForce).
    out->size = std::max(out->size, f);
    if (out->roundoff) b.AddRounding(Vector3d::Constant(f), out->roundoff);
    if (out->matrix) b.ScatterTangent(k, out->map, out->scale, out->matrix);
  }
}

void BodyFluidForces::AddDissipative(const ForceState& s, ForceOutput* out) const {
  const bool waves = s.waves != nullptr;
  for (const BodyFluidLoad& b : loads_) {
    if (!b.dynamic(waves)) continue;
    Matrix3d c;
    const Vector3d force = b.DynamicForce(*s.q, *s.qdot, s.time, s.waves,
                                          out->matrix ? &c : nullptr);
    out->size = std::max(out->size, force.lpNorm<Eigen::Infinity>());
    b.AddForce(force, out->full);
    if (out->roundoff) b.AddRounding(force.cwiseAbs(), out->roundoff);
    if (out->matrix) b.ScatterTangent(c, out->map, out->scale, out->matrix);
    if (!b.has_area_drag()) continue;
    BodyFluidLoad::Generalized area;
    BodyFluidLoad::GeneralizedMatrix area_c;
    b.AreaDrag(*s.q, *s.qdot, s.time, s.waves, &area, out->matrix ? &area_c : nullptr);
    const int n = b.stride();
    for (int k = 0; k < n; ++k) {
      (*out->full)(b.coord() + k) += area(k);
      if (out->roundoff) (*out->roundoff)(b.coord() + k) += kSumRounding * std::abs(area(k));
    }
    out->size = std::max(out->size, area.head(n).lpNorm<Eigen::Infinity>());
    if (out->matrix)
      out->map.ScatterRange(b.coord(), n, area_c.data(), BodyFluidLoad::kMaxStride, out->scale,
                            out->matrix);
  }
}

double BodyFluidForces::StoredEnergy(const ForceState& s) const {
  double energy = 0;
  for (const BodyFluidLoad& b : loads_) energy += b.HydrostaticEnergy(*s.q, s.load_factor);
  return energy;
}

void BodyFluidForces::AddDissipatedPower(const ForceState& s, double* power) const {
  for (const BodyFluidLoad& b : loads_) {
    if (!b.dynamic(s.waves != nullptr)) continue;
    // -F . v_p, v_p = T qdot_b the velocity of the part's centre.
    const Vector3d force = b.DynamicForce(*s.q, *s.qdot, s.time, s.waves, nullptr);
    const Vector3d v = b.MapPoint(*s.qdot);
    for (int d = 0; d < b.dim(); ++d) *power -= force(d) * v(d);
    if (!b.has_area_drag()) continue;
    BodyFluidLoad::Generalized area;
    b.AreaDrag(*s.q, *s.qdot, s.time, s.waves, &area, nullptr);
    for (int k = 0; k < b.stride(); ++k) *power -= area(k) * (*s.qdot)(b.coord() + k);
  }
}

bool BodyFluidForces::dynamic(bool has_waves) const {
  for (const BodyFluidLoad& b : loads_)
    if (b.dynamic(has_waves)) return true;
  return false;
}

std::unique_ptr<BodyFluidForces> MakeBodyFluidForces(const Scene& scene,
                                                     const std::vector<int>& body_coord, int dim,
                                                     bool has_waves) {
  // SceneFromProto requires a fluid with body hydrodynamics, and gravity
  // with a cylinder (without gravity the vertical is z, unused).
  const FluidSpec& fluid = scene.fluid;
  const double g = scene.gravity_m_s2.norm();
  std::vector<BodyFluidLoad> loads;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    if (!body.has_hydrodynamics || !(fluid.density_kg_m3 > 0)) continue;
    for (const BodyFluidPart& part : body.hydro_parts) {
      if (!(g > 0) && part.height_m > 0) continue;
      BodyFluidLoad::Params p;
      p.density_kg_m3 = fluid.density_kg_m3;
      p.g_m_s2 = g;
      p.up = g > 0 ? Vector3d(-scene.gravity_m_s2 / g) : Vector3d::UnitZ();
      p.still_level_m = fluid.still_water_level_m;
      p.diameter_m = part.diameter_m;
      p.height_m = part.height_m;
      p.drag = part.drag;
      p.heave_drag = part.heave_drag;
      p.added_mass = part.added_mass;
      p.heave_added_mass = part.heave_added_mass;
      p.along_axis = part.along_axis;
      p.axis_body = part.axis_body;
      p.current_m_s = fluid.current_m_s;
      p.drag_area = part.drag_area_m2;
      p.rotational_drag_area = part.rotational_drag_area_m5;
      p.center_body = part.center_m;
      loads.emplace_back(p, body_coord[b], dim);
    }
  }
  if (loads.empty()) return nullptr;
  auto forces = std::make_unique<BodyFluidForces>(std::move(loads));
  forces->set_dissipates(forces->dynamic(has_waves));
  return forces;
}

}  // namespace cablesim
