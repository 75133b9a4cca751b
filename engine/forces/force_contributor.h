#ifndef CABLESIM_ENGINE_FORCES_FORCE_CONTRIBUTOR_H_
#define CABLESIM_ENGINE_FORCES_FORCE_CONTRIBUTOR_H_

// The one shape of a force beyond the cable elements' own strain force: a
// ForceContributor. The model (engine/model/multibody_model.h) holds the
// list of the contributors a scene uses, built by each feature's Make...
// function next to its class, and assembles over that list; it names no
// force. A scene without a feature builds no contributor for it, so the
// feature costs nothing there (MuJoCo's rule: nothing is evaluated,
// nothing allocated).
//
// One contributor holds every instance of its feature (all sliders, all
// fluid-loaded bodies), so the model makes one virtual call per feature per
// evaluation, never one per element or point.
//
// What a contributor gives, on the full coordinates q (the model maps them
// onto its unknowns z through q = c + S z, CoordinateMap):
//
//  - AddAppliedLoad: forces that count with the applied loads (gravity,
//    point loads): scaled by the load factor, summed before the elements,
//    and whose size and rounding are the applied terms' (the model takes
//    both from the sum). Optionally k_scale * (-df/dq) into the matrix.
//  - AddConservative: position-dependent forces f(q) = -dU/dq summed after
//    the elements (contact, penalties), with k_scale * (-df/dq) into the
//    matrix, their rounding bound into `roundoff`, and their size (largest
//    entry) into ForceOutput::size: the scale of the Newton residual.
//  - AddDissipative: velocity-dependent forces f(q, qdot), with c_scale *
//    (-df/dqdot) into the matrix (its q-derivative is left out of Newton,
//    as for damping) and the rounding and size as above.
//  - StoredEnergy U(q) of the conservative parts [J], in the energy bucket
//    bucket() (the loads' potential, or contact, or the potential alone
//    for gravity, whose per-part shares AddEnergyParts reports).
//  - AddEnergyParts: its share of the energy per cable and per body
//    (EnergyParts, output/results.h), for a contributor whose energy is
//    not all the loads' (gravity: per cable and body).
//  - AddDissipatedPower: -f_d . qdot [W] of the dissipative part (the
//    model's energy.damped integrates it); equals -f . qdot of
//    AddDissipative.
//  - AddStepWork: work done over a step by external agents that have no
//    potential (torques, time-varying loads) [J].
//  - AddExternalPower: the power [W] an agent that drives the contributor's
//    time dependence feeds into the energy (a winch reeling its cable):
//    the model integrates it over each step (MultibodyModel::ExternalPower).
//  - AddStaticFriction: its share of static friction (STATIC analyses).
//  - SetTime: time-dependent data at time t.
//  - name(): its energy column's name (per-feature energy reporting).
//
// Every contributor is checked in one place against finite differences of
// itself (tests/contributor_conformance_test.cc): a new contributor adds one
// line there.
//
// Methods are const (a contributor may keep a warm-start cache, as the
// sliding joint does). Nothing here allocates.

#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/elements/ancf_cable_element.h"
#include "engine/linear/coordinate_map.h"
#include "engine/linear/skyline_ldlt.h"

namespace cablesim {

class WaveField;
struct EnergyParts;

// The state a contributor is evaluated at. `qdot` is null in the
// position-only passes; `waves` the scene's wave field (null: none).
struct ForceState {
  const Eigen::VectorXd* q = nullptr;
  const Eigen::VectorXd* qdot = nullptr;
  double load_factor = 1;
  double time = 0;
  const WaveField* waves = nullptr;
};

// Where a contributor adds its terms. Any pointer may be null: then that
// part is not wanted. `full` and `roundoff` are full-size; `matrix` is the
// Newton matrix on z (through `map`), to which scale times the tangent is
// added. `size` is raised to the largest force entry added.
struct ForceOutput {
  Eigen::VectorXd* full = nullptr;
  Eigen::VectorXd* roundoff = nullptr;
  SkylineLdlt* matrix = nullptr;
  double scale = 0;
  CoordinateMap map;
  double size = 0;
};

// The two ends of an accepted step (or load increment): full
// configurations and times (StepWork).
struct StepEnds {
  const Eigen::VectorXd* q_before = nullptr;
  const Eigen::VectorXd* q_after = nullptr;
  double t_before = 0, t_after = 0;
  double load_factor = 1;
};

// Where a contributor's stored energy is reported.
enum class EnergyBucket {
  kLoads,    // energy.potential and EnergyParts::loads
  kContact,  // energy.contact
  // energy.potential alone; the contributor reports its EnergyParts shares
  // itself (AddEnergyParts): gravity, per cable and per body.
  kPotential,
};

class ForceContributor {
 public:
  virtual ~ForceContributor() = default;

  virtual std::string_view name() const = 0;
  virtual EnergyBucket bucket() const { return EnergyBucket::kLoads; }

  // Whether SetTime changes anything (the model's is_time_dependent()).
  virtual bool time_dependent() const { return false; }
  virtual void SetTime(double t) { (void)t; }

  virtual void AddAppliedLoad(const ForceState& s, ForceOutput* out) const {
    (void)s;
    (void)out;
  }
  // The applied load over the full coordinates [N] when it is the same at
  // every q and t (gravity without winches, constant point loads), else
  // nullptr. The model sums such loads once when it is built, and its force
  // starts from load_factor times that sum in one pass; AddAppliedLoad is
  // then not called for this contributor in the step loop (it must add the
  // same load, scaled, for callers that assemble by hand).
  virtual const Eigen::VectorXd* ConstantAppliedLoad() const { return nullptr; }
  virtual void AddConservative(const ForceState& s, ForceOutput* out) const {
    (void)s;
    (void)out;
  }
  virtual void AddDissipative(const ForceState& s, ForceOutput* out) const {
    (void)s;
    (void)out;
  }
  virtual double StoredEnergy(const ForceState& s) const {
    (void)s;
    return 0;
  }
  // Its shares of the energy parts at s (after the model has set the loads'
  // sum: parts->loads is the kLoads contributors' energy minus the external
  // work).
  virtual void AddEnergyParts(const ForceState& s, EnergyParts* parts) const {
    (void)s;
    (void)parts;
  }
  // Adds its dissipated power -f_d . qdot [W] to *power (a running sum,
  // so that the model's total is summed term by term as before).
  virtual void AddDissipatedPower(const ForceState& s, double* power) const {
    (void)s;
    (void)power;
  }
  // Adds the work external agents did through it over a step [J] (a
  // running sum, as the power's).
  virtual void AddStepWork(const StepEnds& e, double* work) const {
    (void)e;
    (void)work;
  }
  // Adds the power [W] a prescribed time dependence feeds into the energy at
  // s (at the time of SetTime): the explicit rate dU/dt|_q of its stored
  // energy, plus, for a velocity-dependent force f_v that is not all
  // dissipation, f_v . qdot + its dissipated power (what the agent supplies
  // besides). A running sum. Needs s.qdot.
  virtual void AddExternalPower(const ForceState& s, double* power) const {
    (void)s;
    (void)power;
  }
  // Whether AddDissipative adds anything (the model's has_damping()).
  virtual bool dissipates() const { return false; }

  virtual bool has_static_friction() const { return false; }
  // The static friction force at q opposing the displacement from q_start
  // into out->full, scale times its matrix into out->matrix, and (when
  // out->roundoff is set) its rounding floor into out->roundoff.
  virtual void AddStaticFriction(const Eigen::VectorXd& q, const Eigen::VectorXd& q_start,
                                 ForceOutput* out) const {
    (void)q;
    (void)q_start;
    (void)out;
  }
};

// A force on cable elements, evaluated element by element inside the
// model's one element loop (so that each element's terms are summed and
// scattered once, with the elastic force's): per element of undeformed
// length `length` at coordinates e (AncfCableElement<D> layout). Each
// method comes in the two fixed sizes (planar, spatial); a term overrides
// the ones it has. The model holds the terms the scene uses.
template <int D>
using ElementCoords = Eigen::Matrix<double, 4 * D, 1>;
template <int D>
using ElementMatrix = Eigen::Matrix<double, 4 * D, 4 * D>;

// Where an element term's dissipation is evaluated: the element (its
// current length, quadrature and shape functions: a winch cable's change
// with time), its index in the model's element list (cable by cable, in
// scene order; a term keeps per-element data by it) and the time of the
// model's SetTime.
//
// A term that couples the element with other coordinates (a sheave carried
// by a body) also gets the element's first full coordinate, the full state
// (qdot null in the position-only passes), where to add the terms that
// reach beyond the element (`coupled`: any pointer in it may be null, then
// that part is not wanted; null itself in the energy pass) and a running
// sum for the power those terms dissipate (null: not wanted).
template <int D>
struct ElementAt {
  const AncfCableElement<D>& element;
  int index = 0;
  double time = 0;
  int first_coord = 0;
  const Eigen::VectorXd* q = nullptr;
  const Eigen::VectorXd* qdot = nullptr;
  ForceOutput* coupled = nullptr;
  double* coupled_power = nullptr;
  // When not null, AddElementDissipation may add here the position tangent
  // -dQ_d/de of its velocity-dependent force (the model scales it as the
  // position-dependent forces' tangent); a term that leaves it out adds
  // nothing.
  ElementMatrix<D>* position_tangent = nullptr;
};

class ElementTerm {
 public:
  virtual ~ElementTerm() = default;
  virtual std::string_view name() const = 0;
  virtual EnergyBucket bucket() const { return EnergyBucket::kContact; }
  // Whether AddPotential and Energy add anything (false: the model leaves
  // the term out of its elastic loop, as it does for damping and drag).
  virtual bool has_potential() const { return true; }

  // Adds dU/de to `gradient` (minus the force, as the elastic force's
  // gradient), d^2U/de^2 to `hessian` and the gradient's rounding bound to
  // `roundoff` (either may be null); returns U [J].
  virtual double AddPotential(const ElementCoords<2>& e, double length,
                              ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                              ElementCoords<2>* roundoff) const {
    (void)e, (void)length, (void)gradient, (void)hessian, (void)roundoff;
    return 0;
  }
  virtual double AddPotential(const ElementCoords<3>& e, double length,
                              ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                              ElementCoords<3>* roundoff) const {
    (void)e, (void)length, (void)gradient, (void)hessian, (void)roundoff;
    return 0;
  }
  // AddPotential and Energy with the element itself (what the model
  // calls; the energy as a running sum, so that the model's total is summed
  // term by term): a term with per-element data, or that couples the
  // element with other coordinates, overrides these; the defaults forward.
  virtual double AddElementPotential(const ElementAt<2>& at, const ElementCoords<2>& e,
                                     ElementCoords<2>* gradient, ElementMatrix<2>* hessian,
                                     ElementCoords<2>* roundoff) const {
    return AddPotential(e, at.element.length(), gradient, hessian, roundoff);
  }
  virtual double AddElementPotential(const ElementAt<3>& at, const ElementCoords<3>& e,
                                     ElementCoords<3>* gradient, ElementMatrix<3>* hessian,
                                     ElementCoords<3>* roundoff) const {
    return AddPotential(e, at.element.length(), gradient, hessian, roundoff);
  }
  virtual void AddElementEnergy(const ElementAt<2>& at, const ElementCoords<2>& e,
                                double* energy) const {
    *energy += Energy(e, at.element.length());
  }
  virtual void AddElementEnergy(const ElementAt<3>& at, const ElementCoords<3>& e,
                                double* energy) const {
    *energy += Energy(e, at.element.length());
  }
  // U [J] alone.
  virtual double Energy(const ElementCoords<2>& e, double length) const {
    (void)e, (void)length;
    return 0;
  }
  virtual double Energy(const ElementCoords<3>& e, double length) const {
    (void)e, (void)length;
    return 0;
  }

  // Whether AddDissipation adds anything.
  virtual bool dissipates() const { return false; }
  // Adds the velocity-dependent force to `force` and its velocity tangent
  // -df/d(edot) to `c` (null: not wanted, and then not computed; the
  // model passes null when it needs the force or the power alone);
  // returns the power dissipated [W].
  virtual double AddDissipation(const ElementCoords<2>& e, const ElementCoords<2>& edot,
                                double length, ElementCoords<2>* force,
                                ElementMatrix<2>* c) const {
    (void)e, (void)edot, (void)length, (void)force, (void)c;
    return 0;
  }
  virtual double AddDissipation(const ElementCoords<3>& e, const ElementCoords<3>& edot,
                                double length, ElementCoords<3>* force,
                                ElementMatrix<3>* c) const {
    (void)e, (void)edot, (void)length, (void)force, (void)c;
    return 0;
  }
  // Whether AddElementDissipation adds anything on element `index` (the
  // model skips the elements no term acts on).
  virtual bool DissipatesOn(int index) const {
    (void)index;
    return dissipates();
  }
  // AddDissipation with the element itself (what the model calls): a term
  // whose data is per element, or that needs the element's quadrature or
  // the time, overrides these; the default forwards to AddDissipation.
  virtual double AddElementDissipation(const ElementAt<2>& at, const ElementCoords<2>& e,
                                       const ElementCoords<2>& edot, ElementCoords<2>* force,
                                       ElementMatrix<2>* c) const {
    return AddDissipation(e, edot, at.element.length(), force, c);
  }
  virtual double AddElementDissipation(const ElementAt<3>& at, const ElementCoords<3>& e,
                                       const ElementCoords<3>& edot, ElementCoords<3>* force,
                                       ElementMatrix<3>* c) const {
    return AddDissipation(e, edot, at.element.length(), force, c);
  }

  virtual bool has_static_friction() const { return false; }
  // AddStaticFriction on the element of index `index` in the model's
  // element list (what the model calls): a term whose data is per element
  // overrides these; the default forwards.
  virtual void AddElementStaticFriction(int index, const ElementCoords<2>& e,
                                        const ElementCoords<2>& e0, double length,
                                        ElementCoords<2>* force, ElementMatrix<2>* matrix) const {
    (void)index;
    AddStaticFriction(e, e0, length, force, matrix);
  }
  virtual void AddElementStaticFriction(int index, const ElementCoords<3>& e,
                                        const ElementCoords<3>& e0, double length,
                                        ElementCoords<3>* force, ElementMatrix<3>* matrix) const {
    (void)index;
    AddStaticFriction(e, e0, length, force, matrix);
  }
  // STATIC analyses: adds the static friction force (e0 where the analysis
  // started) to `force` and its matrix to `matrix` (may be null).
  virtual void AddStaticFriction(const ElementCoords<2>& e, const ElementCoords<2>& e0,
                                 double length, ElementCoords<2>* force,
                                 ElementMatrix<2>* matrix) const {
    (void)e, (void)e0, (void)length, (void)force, (void)matrix;
  }
  virtual void AddStaticFriction(const ElementCoords<3>& e, const ElementCoords<3>& e0,
                                 double length, ElementCoords<3>* force,
                                 ElementMatrix<3>* matrix) const {
    (void)e, (void)e0, (void)length, (void)force, (void)matrix;
  }
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_FORCE_CONTRIBUTOR_H_
