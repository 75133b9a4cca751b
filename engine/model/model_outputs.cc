// MultibodyModel's reports on a state (multibody_model.h): energy (in
// total and per part), angular momentum, cable positions, node positions,
// probes and the forces force probes report.

#include "engine/model/multibody_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "engine/forces/cable_buoyancy.h"

namespace cablesim {


using Eigen::Vector3d;
using Eigen::VectorXd;

namespace {

// The element k in [begin, end) of a cable that holds arc length s [m],
// and s's place in it, xi in [0, 1] (a node: the element before it).
template <class Elements>
void LocateOnCable(const Elements& elements, int begin, int end, double s, int* k, double* xi) {
  double start = 0;
  *k = begin;
  for (; *k + 1 < end; ++*k) {
    const double l = elements[*k].element.length();
    if (s <= start + l) break;
    start += l;
  }
  *xi = std::clamp((s - start) / elements[*k].element.length(), 0.0, 1.0);
}

}  // namespace

template <int D>
void MultibodyModel::ElementEnergy(const VectorXd& q, const VectorXd& qdot, EnergySample* en,
                                   EnergyParts* parts) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  // The totals are summed element by element, the parts apart (so the
  // parts' sums check the totals, and the totals are those of a run
  // without parts, bit for bit).
  size_t cable = 0;
  for (size_t k = 0; k < elements.size(); ++k) {
    const ElementData<D>& e = elements[k];
    const auto qe = q.segment<kN>(e.first_coord);
    const auto ve = qdot.segment<kN>(e.first_coord);
    // T = 1/2 ve^T (mbar (x) I_D) ve, from the element's 4 x 4 scalar mass
    // matrix (not its full mass matrix, rebuilt by quadrature each call).
    double kinetic = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        kinetic += e.mbar(a, b) * ve.template segment<D>(D * a).dot(ve.template segment<D>(D * b));
    kinetic *= 0.5;
    // The added mass that is not the constant mass matrix's isotropic part
    // (along the line, CaAx != Ca; none where the line is out of the water:
    // engine/forces/cable_added_mass.h): 1/2 ve^T (int S^T Dm S dx) ve, from
    // the same quadrature as its inertia force f = -int S^T Dm S a dx).
    if (cable_added_mass_ && cable_added_mass_->ActsOn(static_cast<int>(k))) {
      kinetic += cable_added_mass_->KineticEnergy<D>(e.element, static_cast<int>(k),
                                                     ElementCoords<D>(qe), ve, time_);
    }
    const auto se = e.element.StrainEnergy(qe);
    en->kinetic += kinetic;
    en->axial += se.axial;
    en->bending += se.bending;
    if (!potential_terms_.empty()) {
      const ElementAt<D> at{e.element, static_cast<int>(k), time_, e.first_coord, &q, &qdot};
      for (const ElementTerm* t : potential_terms_)
        t->AddElementEnergy(at, ElementCoords<D>(qe), &en->contact);
    }
    if (parts == nullptr) continue;
    while (static_cast<int>(k) >= cable_element_begin_[cable + 1]) ++cable;
    PartEnergy* part = &parts->cables[cable];
    part->kinetic += kinetic;
    part->axial += se.axial;
    part->bending += se.bending;
  }
}

EnergySample MultibodyModel::Energy(const VectorXd& q, const VectorXd& qdot, double load_factor,
                                    EnergyParts* parts) const {
  EnergySample en;
  if (parts != nullptr) {
    parts->cables.assign(cable_names_.size(), PartEnergy());
    parts->bodies.assign(bodies_.size(), PartEnergy());
  }
  if (dim_ == 2) {
    ElementEnergy<2>(q, qdot, &en, parts);
  } else {
    ElementEnergy<3>(q, qdot, &en, parts);
  }
  const int D = dim_;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const BodyData& b = bodies_[i];
    double translation = 0.5 * b.mass * qdot.segment(b.coord, D).squaredNorm();
    if (b.has_added_mass) {
      // (1/2) qdot_b^T M_a qdot_b over the body's coordinates (only r_c's
      // D x D block unless a fluid part is off the centre of mass).
      const int n = body_stride_;
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < n; ++k)
          if (b.added_mass(i, k) != 0)
            translation += 0.5 * b.added_mass(i, k) * qdot(b.coord + i) * qdot(b.coord + k);
    }
    en.kinetic += translation;
    double kinetic = translation;
    const int axes = D == 2 ? 1 : 3;
    for (int k = 0; k < axes; ++k) {
      const double rotation = 0.5 * b.jbar(k) * qdot.segment(b.coord + D + D * k, D).squaredNorm();
      en.kinetic += rotation;
      kinetic += rotation;
    }
    if (parts != nullptr) {
      PartEnergy& part = parts->bodies[i];
      part.kinetic = kinetic;
    }
  }
  // Torques, time-varying loads, moving supports: their work so far
  // (AccumulateExternalWork). Subtracted first, so that with gravity's
  // energy added next the sum is gravity's minus the work, as ever
  // (a + b = b + a exactly).
  en.potential = -external_work_;
  // Contributors' stored energies, each in its bucket (the potential, also
  // the loads' part, or contact).
  double loads_energy = 0;
  if (!contributors_.empty()) {
    const ForceState state = StateAt(q, &qdot, load_factor);
    for (const auto& c : contributors_) {
      const double u = c->StoredEnergy(state);
      if (c->bucket() == EnergyBucket::kContact) {
        en.contact += u;
      } else {
        en.potential += u;
        if (c->bucket() == EnergyBucket::kLoads) loads_energy += u;
      }
    }
  }
  en.total = en.kinetic + en.potential + en.axial + en.bending + en.contact;
  if (parts != nullptr) {
    parts->loads = loads_energy - external_work_;
    // Contributors' own shares of the parts (gravity per cable and body).
    if (!contributors_.empty()) {
      const ForceState state = StateAt(q, &qdot, load_factor);
      for (const auto& c : contributors_) c->AddEnergyParts(state, parts);
    }
  }
  return en;
}

template <int D>
Eigen::Vector3d MultibodyModel::ElementAngularMomentum(const VectorXd& q,
                                                      const VectorXd& qdot) const {
  Vector3d l = Vector3d::Zero();
  // L_e = sum_a r_a x (sum_b mbar_ab v_b): the rates weighted by the
  // element's scalar mass matrix first, then four cross products (not
  // sixteen; computed at every output frame).
  for (const ElementData<D>& e : Elements<D>()) {
    for (int a = 0; a < 4; ++a) {
      Vector3d ra = Vector3d::Zero(), wa = Vector3d::Zero();
      ra.head<D>() = q.segment<D>(e.first_coord + D * a);
      for (int b = 0; b < 4; ++b)
        wa.head<D>() += e.mbar(a, b) * qdot.segment<D>(e.first_coord + D * b);
      l += ra.cross(wa);
    }
  }
  return l;
}

Eigen::Vector3d MultibodyModel::AngularMomentum(const VectorXd& q, const VectorXd& qdot) const {
  Vector3d l = dim_ == 2 ? ElementAngularMomentum<2>(q, qdot) : ElementAngularMomentum<3>(q, qdot);
  const int D = dim_;
  auto vec = [D](const VectorXd& x, int i) {
    Vector3d v = Vector3d::Zero();
    v.head(D) = x.segment(i, D);
    return v;
  };
  for (const BodyData& b : bodies_) {
    l += b.mass * vec(q, b.coord).cross(vec(qdot, b.coord));
    if (D == 2) {
      // Both axes u and perp(u) carry Jb_x + Jb_y = I_z: I_z u x udot.
      l += b.jbar(0) * vec(q, b.coord + 2).cross(vec(qdot, b.coord + 2));
    } else {
      for (int k = 0; k < 3; ++k)
        l += b.jbar(k) * vec(q, b.coord + 3 + 3 * k).cross(vec(qdot, b.coord + 3 + 3 * k));
    }
  }
  return l;
}

template <int D>
Eigen::Vector3d MultibodyModel::CablePositionOf(const VectorXd& q, int cable, double s,
                                                Vector3d* slope) const {
  constexpr int kN = 4 * D;
  const auto& elements = Elements<D>();
  Vector3d r = Vector3d::Zero();
  const int begin = cable_element_begin_[cable], end = cable_element_begin_[cable + 1];
  double start = 0;
  for (int k = begin; k < end; ++k) {
    const ElementData<D>& e = elements[k];
    const double l = e.element.length();
    if (s <= start + l || k + 1 == end) {
      const double xi = std::clamp((s - start) / l, 0.0, 1.0);
      r.head<D>() = e.element.Position(q.segment<kN>(e.first_coord), xi);
      if (slope) {
        slope->setZero();
        slope->head<D>() = e.element.Slope(q.segment<kN>(e.first_coord), xi);
      }
      return r;
    }
    start += l;
  }
  return r;
}

Eigen::Vector3d MultibodyModel::CablePosition(const VectorXd& q, int cable, double s,
                                              Vector3d* slope) const {
  return dim_ == 2 ? CablePositionOf<2>(q, cable, s, slope)
                   : CablePositionOf<3>(q, cable, s, slope);
}

void MultibodyModel::NodePositions(const VectorXd& q, std::vector<Vector3d>* out) const {
  out->resize(shape_coord_.size());
  for (size_t k = 0; k < shape_coord_.size(); ++k) {
    Vector3d& r = (*out)[k];
    r.setZero();
    r.head(dim_) = q.segment(shape_coord_[k], dim_);
  }
}

void MultibodyModel::Probes(const VectorXd& q, const VectorXd& qdot, const VectorXd& qddot,
                            std::vector<ProbeSample>* out) const {
  out->resize(probe_names_.size());
  for (size_t p = 0; p < probe_names_.size(); ++p) {
    ProbeSample& s = (*out)[p];
    for (int d = 0; d < 3; ++d) {
      const int r = 3 * static_cast<int>(p) + d;
      double x = probe_const_[r], v = 0, a = 0;
      for (int k = probe_term_begin_[r]; k < probe_term_begin_[r + 1]; ++k) {
        const ProbeTerm& t = probe_terms_[k];
        x += t.coeff * q(t.coord);
        v += t.coeff * qdot(t.coord);
        a += t.coeff * qddot(t.coord);
      }
      s.position_m(d) = x;
      s.velocity_m_s(d) = v;
      s.acceleration_m_s2(d) = a;
    }
  }
}

void MultibodyModel::ProbeForces(const VectorXd& q, const VectorXd& lambda,
                                 std::vector<Eigen::Vector3d>* out) const {
  out->resize(force_probes_.size());
  for (size_t k = 0; k < force_probes_.size(); ++k) {
    Eigen::Vector3d& force = (*out)[k];
    force.setZero();
    if (!probe_winch_.empty() && probe_winch_[force_probes_[k]] >= 0) {
      const int w = probe_winch_[force_probes_[k]];
      force = dim_ == 2 ? WinchTension<2>(q, w) : WinchTension<3>(q, w);
      continue;
    }
    for (int d = 0; d < 3; ++d) {
      const int row = probe_force_rows_[force_probes_[k]][d];
      if (row >= 0) force(d) = -lambda(row);
    }
  }
}

void MultibodyModel::Reactions(const VectorXd& q, const VectorXd* lambda,
                               std::vector<JointReaction>* out) const {
  const size_t n = joint_reaction_values_.size();
  reaction_forces_.assign(n, Eigen::Vector3d::Zero());
  reaction_moments_.assign(n, Eigen::Vector3d::Zero());
  if (lambda)
    for (const ConstraintFamily* f : families_)
      f->AddReactions(q, *lambda, &reaction_forces_, &reaction_moments_);
  out->resize(n);
  for (size_t j = 0; j < n; ++j) {
    (*out)[j].values = joint_reaction_values_[j];
    (*out)[j].force = reaction_forces_[j];
    (*out)[j].moment = reaction_moments_[j];
  }
}

Eigen::Matrix3d MultibodyModel::BodyRotation(const VectorXd& q, int body) const {
  const int c = bodies_[body].coord;
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  if (dim_ == 2) {
    const Eigen::Vector2d u = q.segment<2>(c + 2).normalized();
    r.topLeftCorner<2, 2>() << u.x(), -u.y(), u.y(), u.x();
    return r;
  }
  for (int i = 0; i < 3; ++i) r.col(i) = q.segment<3>(c + 3 + 3 * i);
  return r;
}

void MultibodyModel::Orientations(const VectorXd& q, const VectorXd& qdot,
                                  std::vector<double>* out) const {
  out->resize(10 * bodies_.size());
  for (size_t b = 0; b < bodies_.size(); ++b) {
    const int c = bodies_[b].coord;
    double* o = out->data() + 10 * b;
    if (dim_ == 2) {
      const Eigen::Vector2d u = q.segment<2>(c + 2), ud = qdot.segment<2>(c + 2);
      const double angle = std::atan2(u.y(), u.x());  // (-pi, pi]: cos(angle / 2) >= 0
      o[0] = std::cos(angle / 2);
      o[1] = o[2] = 0;
      o[3] = std::sin(angle / 2);
      o[4] = o[5] = 0;
      o[6] = angle;
      o[7] = o[8] = 0;
      o[9] = (u.x() * ud.y() - u.y() * ud.x()) / u.squaredNorm();
      continue;
    }
    Eigen::Matrix3d r;
    Vector3d omega = Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      r.col(i) = q.segment<3>(c + 3 + 3 * i);
      omega += 0.5 * r.col(i).cross(qdot.segment<3>(c + 3 + 3 * i));
    }
    Eigen::Quaterniond rotation(r);
    rotation.normalize();
    if (rotation.w() < 0) rotation.coeffs() *= -1;
    o[0] = rotation.w();
    o[1] = rotation.x();
    o[2] = rotation.y();
    o[3] = rotation.z();
    o[4] = std::atan2(r(2, 1), r(2, 2));                     // roll
    o[5] = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));      // pitch
    o[6] = std::atan2(r(1, 0), r(0, 0));                     // yaw
    o[7] = omega.x();
    o[8] = omega.y();
    o[9] = omega.z();
  }
}

template <int D>
void MultibodyModel::ElementEndForces(const VectorXd& q, const VectorXd* qdot, int k,
                                      double load_factor, Vector3d* start, Vector3d* end,
                                      Vector3d* moment_start, Vector3d* moment_end) const {
  constexpr int kN = 4 * D;
  const ElementData<D>& e = Elements<D>()[k];
  Eigen::Matrix<double, kN, 1> f = Eigen::Matrix<double, kN, 1>::Zero();  // ElasticForce adds
  e.element.ElasticForce(q.segment<kN>(e.first_coord), &f, nullptr);
  // The material damping's force -C edot resists the stretching as the
  // elastic force does: the ends must supply C edot besides Q_k.
  if (qdot && cable_damping_) {
    Eigen::Matrix<double, kN, 1> damping = Eigen::Matrix<double, kN, 1>::Zero();
    cable_damping_->AddMaterialForce<D>(ElementAt<D>{e.element, k},
                                        q.segment<kN>(e.first_coord),
                                        qdot->segment<kN>(e.first_coord), &damping);
    f -= damping;
  }
  f -= load_factor * ElementWeight(e);
  // STATIC with a free surface: the buoyancy the element's sections lose
  // above the level is a load on it as its weight is (a line through the
  // level at a fairlead: without it the tension there was off by that
  // load, 13 N of 1 MN in tests/moordyn_chain_test.cc).
  if (const auto* surface = dynamic_cast<const CableSurfaceBuoyancy<D>*>(
          FindContributor("free_surface"))) {
    Eigen::Matrix<double, kN, 1> dry;
    if (surface->StaticLoadOfElement(k, StateAt(q, nullptr, load_factor), &dry)) f -= dry;
  }
  start->setZero();
  end->setZero();
  // Rows of the end positions (r_i, r_j) in the element's coordinates
  // (r_i, r_s,i, r_j, r_s,j): the force the element needs at each end.
  start->head<D>() = -f.template segment<D>(0);
  end->head<D>() = f.template segment<D>(2 * D);
  if (moment_start == nullptr) return;
  // The slope rows (u_i, u_j): u x Q_u at its end (the cable beyond acting
  // on the element) and, negated, at its start (the element acting on the
  // cable before it).
  Vector3d u = Vector3d::Zero(), g = Vector3d::Zero();
  u.head<D>() = q.segment<D>(e.first_coord + D);
  g.head<D>() = f.template segment<D>(D);
  *moment_start = -u.cross(g);
  u.head<D>() = q.segment<D>(e.first_coord + 3 * D);
  g.head<D>() = f.template segment<D>(3 * D);
  *moment_end = u.cross(g);
}

template <int D>
double MultibodyModel::TensionOf(const VectorXd& q, const VectorXd* qdot, int cable, double s,
                                 double load_factor) const {
  const auto& elements = Elements<D>();
  const int begin = cable_element_begin_[cable], end = cable_element_begin_[cable + 1];
  int k = 0;
  double xi = 0;
  LocateOnCable(elements, begin, end, s, &k, &xi);
  // The section force at each end of element k, averaged with the
  // neighbour's at a shared node.
  Vector3d at_start, at_end, other, unused;
  ElementEndForces<D>(q, qdot, k, load_factor, &at_start, &at_end);
  if (k > begin) {
    ElementEndForces<D>(q, qdot, k - 1, load_factor, &unused, &other);
    at_start = 0.5 * (at_start + other);
  }
  if (k + 1 < end) {
    ElementEndForces<D>(q, qdot, k + 1, load_factor, &other, &unused);
    at_end = 0.5 * (at_end + other);
  }
  const Vector3d force = (1 - xi) * at_start + xi * at_end;
  Vector3d tangent = Vector3d::Zero();
  tangent.head<D>() = elements[k].element.Slope(q.segment<4 * D>(elements[k].first_coord), xi);
  const double norm = tangent.norm();
  return norm > 0 ? force.dot(tangent) / norm : force.norm();
}

template <int D>
void MultibodyModel::CableNodeTensionsOf(const VectorXd& q, const VectorXd* qdot, int cable,
                                         double load_factor, double* out) const {
  const auto& elements = Elements<D>();
  const int begin = cable_element_begin_[cable], end = cable_element_begin_[cable + 1];
  Vector3d before = Vector3d::Zero(), t_before = Vector3d::Zero();
  for (int k = begin; k <= end; ++k) {
    Vector3d force = Vector3d::Zero(), tangent = Vector3d::Zero();
    int sides = 0;
    if (k > begin) {  // element k - 1 ends here
      force += before;
      tangent += t_before;
      ++sides;
    }
    if (k < end) {  // element k starts here
      constexpr int kN = 4 * D;
      const auto qe = q.segment<kN>(elements[k].first_coord);
      Vector3d at_start;
      ElementEndForces<D>(q, qdot, k, load_factor, &at_start, &before);
      force += at_start;
      Vector3d t = Vector3d::Zero();
      t.head<D>() = elements[k].element.Slope(qe, 0.0);
      tangent += t.normalized();
      t_before.setZero();
      t_before.head<D>() = elements[k].element.Slope(qe, 1.0);
      t_before.normalize();
      ++sides;
    }
    force /= sides;
    const double norm = tangent.norm();
    out[k - begin] = norm > 0 ? force.dot(tangent) / norm : force.norm();
  }
}

template <int D>
Vector3d MultibodyModel::BendingMomentOf(const VectorXd& q, const VectorXd* qdot, int cable,
                                         double s, double load_factor) const {
  const auto& elements = Elements<D>();
  const int begin = cable_element_begin_[cable], end = cable_element_begin_[cable + 1];
  int k = 0;
  double xi = 0;
  LocateOnCable(elements, begin, end, s, &k, &xi);
  // The moment at each end of element k (ElementEndForces), averaged with
  // the neighbour's at a shared node.
  Vector3d m_start, m_end, other, unused;
  ElementEndForces<D>(q, qdot, k, load_factor, &unused, &unused, &m_start, &m_end);
  if (k > begin) {
    ElementEndForces<D>(q, qdot, k - 1, load_factor, &unused, &unused, &unused, &other);
    m_start = 0.5 * (m_start + other);
  }
  if (k + 1 < end) {
    ElementEndForces<D>(q, qdot, k + 1, load_factor, &unused, &unused, &other, &unused);
    m_end = 0.5 * (m_end + other);
  }
  return (1 - xi) * m_start + xi * m_end;
}

void MultibodyModel::BendingMoments(const VectorXd& q, double load_factor,
                                    std::vector<double>* out, const VectorXd* qdot) const {
  out->resize(tension_probe_.size());
  for (size_t k = 0; k < tension_probe_.size(); ++k) {
    const Vector3d m =
        dim_ == 2 ? BendingMomentOf<2>(q, qdot, tension_cable_[k], tension_s_[k], load_factor)
                  : BendingMomentOf<3>(q, qdot, tension_cable_[k], tension_s_[k], load_factor);
    (*out)[k] = dim_ == 2 ? m.z() : m.norm();
  }
}

std::vector<double> MultibodyModel::CableNodeTensions(const VectorXd& q, int cable,
                                                      double load_factor,
                                                      const VectorXd* qdot) const {
  std::vector<double> out(cable_element_begin_[cable + 1] - cable_element_begin_[cable] + 1);
  if (dim_ == 2) {
    CableNodeTensionsOf<2>(q, qdot, cable, load_factor, out.data());
  } else {
    CableNodeTensionsOf<3>(q, qdot, cable, load_factor, out.data());
  }
  return out;
}

void MultibodyModel::Tensions(const VectorXd& q, double load_factor, std::vector<double>* probes,
                              std::vector<double>* nodes, const VectorXd* qdot) const {
  // The section's axial force [N]: the force each element needs at its end
  // positions to hold its strain (its internal force's rows there) less its
  // own share of the weight (consistent load), averaged over the two
  // elements at a node, its component along the tangent.
  // Not the constitutive EA eps |r_s| read at the point: in a stiff line
  // the strain is tiny (2e-7 in the hanging steel cable of
  // tests/cable_statics_test.cc) and the cubic interpolation's slope error
  // at a point is of the same size, so that reading was off by 8 % (no
  // bending stiffness) to three times the tension (exact bending) there.
  // The end forces are what equilibrium fixes: at a support they are the
  // reaction, and between two nodes they differ by the load in between. In
  // statics under weight alone this is exact at every node; otherwise the
  // two-sided average leaves the difference of the two elements' other
  // distributed loads (inertia, drag, contact) at a node, and a cable end
  // one element's share of them (output.reactions holds a support's force
  // exactly). With qdot, the material damping's force joins the elastic
  // one (the tension MoorDyn reports, T + Td of a segment, and OrcaFlex's
  // wall tension with its axial damping term carry it too); Rayleigh
  // alpha, which acts on the mass, does not.
  probes->resize(tension_probe_.size());
  for (size_t k = 0; k < tension_probe_.size(); ++k) {
    (*probes)[k] = dim_ == 2 ? TensionOf<2>(q, qdot, tension_cable_[k], tension_s_[k], load_factor)
                             : TensionOf<3>(q, qdot, tension_cable_[k], tension_s_[k], load_factor);
  }
  if (!shape_) {
    nodes->clear();
    return;
  }
  nodes->resize(node_s_.size());
  size_t first = 0;
  for (int c = 0; c + 1 < static_cast<int>(cable_element_begin_.size()); ++c) {
    const size_t count = cable_element_begin_[c + 1] - cable_element_begin_[c] + 1;
    if (static_cast<size_t>(cable_nodes_[c]) != count) {
      // Not one node per element end (never so today): each node on its own.
      for (int k = 0; k < cable_nodes_[c]; ++k, ++first) {
        (*nodes)[first] = dim_ == 2 ? TensionOf<2>(q, qdot, c, node_s_[first], load_factor)
                                    : TensionOf<3>(q, qdot, c, node_s_[first], load_factor);
      }
      continue;
    }
    if (dim_ == 2) {
      CableNodeTensionsOf<2>(q, qdot, c, load_factor, nodes->data() + first);
    } else {
      CableNodeTensionsOf<3>(q, qdot, c, load_factor, nodes->data() + first);
    }
    first += count;
  }
}

}  // namespace cablesim
