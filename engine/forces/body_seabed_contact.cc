#include "engine/forces/body_seabed_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "engine/linear/rounding.h"

namespace cablesim {

BodySeabedContact::BodySeabedContact(const Seabed& bed, std::vector<Body> bodies, int dim)
    : bed_(bed), bodies_(std::move(bodies)), dim_(dim) {}

template <int D>
double BodySeabedContact::Terms(Term term, const Eigen::VectorXd& q,
                                const Eigen::VectorXd* other, ForceOutput* out) const {
  constexpr int S = D == 2 ? 4 : 12;  // the body's natural coordinates
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  using Point = Eigen::Matrix<double, D, 1>;
  using Block = Eigen::Matrix<double, D, D>;
  using Local = Eigen::Matrix<double, S, 1>;
  Eigen::VectorXd* full = out ? out->full : nullptr;
  Eigen::VectorXd* roundoff = out ? out->roundoff : nullptr;
  SkylineLdlt* a = out ? out->matrix : nullptr;
  const double bed_size = std::abs(bed_.Height(Eigen::Vector3d::Zero()));
  double result = 0;
  for (const Body& c : bodies_) {
    if (term == Term::kDissipation && c.c == 0 && c.mu == 0) continue;
    if (term == Term::kStaticFriction && c.mu == 0) continue;
    const Local qb = q.segment<S>(c.coord);
    Local force = Local::Zero(), bound = Local::Zero();
    Eigen::Matrix<double, S, S> matrix = Eigen::Matrix<double, S, S>::Zero();
    for (const Eigen::Vector3d& p : c.points) {
      // r = B q_b: planar r_c + p_x u + p_y perp(u), spatial r_c + sum p_k e_k.
      Eigen::Matrix<double, D, S> b = Eigen::Matrix<double, D, S>::Zero();
      b.template leftCols<D>().setIdentity();
      if constexpr (D == 2) {
        b(0, 2) = b(1, 3) = p.x();
        b(0, 3) = -p.y();
        b(1, 2) = p.y();
      } else {
        for (int k = 0; k < 3; ++k) b.template block<3, 3>(0, 3 + 3 * k) = p(k) * Block::Identity();
      }
      const Point r = b * qb;
      Point f = Point::Zero();
      Block h = Block::Zero();
      if (term == Term::kPotential) {
        result += bed_.PointPotential<D>(r, c.k, &f, a ? &h : nullptr);
        f = -f;  // the force is minus the energy's gradient
        if (roundoff && f.squaredNorm() > 0)
          bound += (kEps * c.k * (bed_size + (b.cwiseAbs() * qb.cwiseAbs()).sum())) *
                   (b.cwiseAbs().transpose() * Point::Ones());
      } else if (term == Term::kDissipation) {
        const Point v = b * other->segment<S>(c.coord);
        result += bed_.PointDissipation<D>(r, v, c.k, c.c, c.mu, &f, a ? &h : nullptr);
      } else {
        const Local qb0 = other->segment<S>(c.coord);
        const Point r0 = b * qb0;
        bed_.PointStaticFriction<D>(r, r0, c.k, c.mu, &f, (a || roundoff) ? &h : nullptr);
        // The displacement r - r0 = B (q_b - q_b0) is known to a few eps
        // (kSumRounding) times |B| (|q_b| + |q_b0|), and the regularised law
        // turns that into up to |h| times as much force, per point (tested
        // against random roundings of q: seabed_body_test.cc).
        if (roundoff)
          bound += kSumRounding * (b.cwiseAbs().transpose() * h.cwiseAbs() * b.cwiseAbs()) *
                   (qb.cwiseAbs() + qb0.cwiseAbs());
      }
      force.noalias() += b.transpose() * f;
      if (a) matrix.noalias() += b.transpose() * h * b;
    }
    if (out) out->size = std::max(out->size, force.template lpNorm<Eigen::Infinity>());
    if (full) full->segment<S>(c.coord) += force;
    if (roundoff) roundoff->segment<S>(c.coord) += bound + kEps * force.cwiseAbs();
    if (a) out->map.ScatterRange(c.coord, S, matrix.data(), S, out->scale, a);
  }
  return result;
}

double BodySeabedContact::Dispatch(Term term, const Eigen::VectorXd& q,
                                   const Eigen::VectorXd* other, ForceOutput* out) const {
  return dim_ == 2 ? Terms<2>(term, q, other, out) : Terms<3>(term, q, other, out);
}

void BodySeabedContact::AddConservative(const ForceState& s, ForceOutput* out) const {
  Dispatch(Term::kPotential, *s.q, nullptr, out);
}

void BodySeabedContact::AddDissipative(const ForceState& s, ForceOutput* out) const {
  // The dissipative pass gives no rounding bound of its own.
  ForceOutput local = *out;
  local.roundoff = nullptr;
  Dispatch(Term::kDissipation, *s.q, s.qdot, &local);
  out->size = local.size;
}

double BodySeabedContact::StoredEnergy(const ForceState& s) const {
  return Dispatch(Term::kPotential, *s.q, nullptr, nullptr);
}

void BodySeabedContact::AddDissipatedPower(const ForceState& s, double* power) const {
  *power += Dispatch(Term::kDissipation, *s.q, s.qdot, nullptr);
}

bool BodySeabedContact::dissipates() const {
  for (const Body& c : bodies_)
    if (c.c != 0 || c.mu != 0) return true;
  return false;
}

bool BodySeabedContact::has_static_friction() const {
  for (const Body& c : bodies_)
    if (c.mu != 0) return true;
  return false;
}

void BodySeabedContact::AddStaticFriction(const Eigen::VectorXd& q,
                                          const Eigen::VectorXd& q_start,
                                          ForceOutput* out) const {
  Dispatch(Term::kStaticFriction, q, &q_start, out);
}

std::unique_ptr<BodySeabedContact> MakeBodySeabedContact(const Scene& scene,
                                                         const std::vector<int>& body_coord,
                                                         int dim) {
  // SceneFromProto refuses contact points without a seabed.
  if (!scene.seabed.enabled) return nullptr;
  std::vector<BodySeabedContact::Body> bodies;
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    if (body.contact_points_m.empty()) continue;
    BodySeabedContact::Body contact;
    contact.coord = body_coord[b];
    contact.points = body.contact_points_m;
    contact.k = body.contact_stiffness_n_m;
    contact.c = body.contact_damping_n_s_m;
    contact.mu = body.contact_friction;
    bodies.push_back(std::move(contact));
  }
  if (bodies.empty()) return nullptr;
  return std::make_unique<BodySeabedContact>(Seabed(scene.seabed), std::move(bodies), dim);
}

}  // namespace cablesim
