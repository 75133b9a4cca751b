#include "engine/forces/body_damping.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cablesim {

BodyDamping::BodyDamping(std::vector<Body> bodies, int dim)
    : bodies_(std::move(bodies)), dim_(dim), stride_(dim == 2 ? 4 : 12) {}

double BodyDamping::Coefficient(const Body& b, int k) const {
  if (k < dim_) return b.linear;
  // Planar: the torque -c omega on u is -c udot; spatial: -(c / 2) edot_k.
  return dim_ == 2 ? b.angular : 0.5 * b.angular;
}

void BodyDamping::AddDissipative(const ForceState& s, ForceOutput* out) const {
  const Eigen::VectorXd& qdot = *s.qdot;
  for (const Body& b : bodies_) {
    for (int k = 0; k < stride_; ++k) {
      const double c = Coefficient(b, k);
      if (c == 0) continue;
      const int i = b.coord + k;
      (*out->full)(i) -= c * qdot(i);
      out->size = std::max(out->size, std::abs(c * qdot(i)));
      if (out->matrix) out->map.Scatter(&i, 1, &c, 1, out->scale, out->matrix);
    }
  }
}

void BodyDamping::AddDissipatedPower(const ForceState& s, double* power) const {
  const Eigen::VectorXd& qdot = *s.qdot;
  for (const Body& b : bodies_)
    for (int k = 0; k < stride_; ++k)
      *power += Coefficient(b, k) * qdot(b.coord + k) * qdot(b.coord + k);
}

std::unique_ptr<BodyDamping> MakeBodyDamping(const Scene& scene,
                                             const std::vector<int>& body_coord, int dim) {
  std::vector<BodyDamping::Body> bodies;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    if (body.linear_damping_n_s_m == 0 && body.angular_damping_n_m_s == 0) continue;
    bodies.push_back({body_coord[b], body.linear_damping_n_s_m, body.angular_damping_n_m_s});
  }
  if (bodies.empty()) return nullptr;
  return std::make_unique<BodyDamping>(std::move(bodies), dim);
}

}  // namespace cablesim
