#ifndef CABLESIM_ENGINE_MODEL_MULTIBODY_MODEL_H_
#define CABLESIM_ENGINE_MODEL_MULTIBODY_MODEL_H_

// The multibody model of a scene, planar (D = 2) or spatial (D = 3): ANCF
// cable elements (4 D coordinates each, MODEL.md sections 1-3), rigid bodies
// (section 6), joints, gravity and constant loads (section 4).
//
// Coordinates. The full coordinate vector q holds, cable by cable and node
// by node, [r, r_x] (position [m] and slope [-], D each), then per body its
// natural coordinates [m], [-]:
//   planar:  [r_c, u]           (4)   body axes e1 = u, e2 = perp(u)
//   spatial: [r_c, u, v, w]     (12)  body axes e1 = u, e2 = v, e3 = w
// where r_c is the centre of mass and u, v, w the body's x, y, z axes in the
// world. A body point p (body frame) is at r_c + p_x e1 + p_y e2 (+ p_z e3):
// linear in q. The kinetic energy is then (1/2) qdot^T M qdot with a constant
// mass matrix diag(m I, Jb_x I, Jb_y I, Jb_z I), Jb_k = int rho p_k^2 dV =
// (I_1 + I_2 + I_3) / 2 - I_k from the principal moments (planar: only u,
// with Jb = I_z), so the body has no velocity-dependent (gyroscopic) forces
// in these coordinates: rotation is carried by the axes and the unit and
// orthogonality constraints of the axes (1 row planar, 6 spatial). Why
// natural coordinates: the mass matrix stays constant as for the cable, so
// every stepper treats bodies and cables alike, and every joint row is at
// most quadratic in q (QuadraticForm). A planar scene run in the spatial
// model follows the same discrete trajectory (w stays e_z, v = perp(u)).
//
// Coordinates that a joint to ground fixes are removed: q = c + S z, where
// z are the unknowns (dofs) and each full coordinate is either a constant or
// a multiple of one unknown. A pinned node loses its position; a clamped
// (FIXED to ground) node also keeps its slope along its initial direction
// d0, r_x = alpha d0 with alpha unknown (the cable may still stretch there);
// a body welded to ground loses all its coordinates, a body pinned to ground
// at its centre of mass loses r_c. Every other joint is a constraint
// Phi(q) = 0 with a Lagrange multiplier.
//
// The unknowns are ordered along each cable, and a body's right after the
// first cable node it is joined to, so the Newton matrix on z is banded
// (see SkylineLdlt).
//
// All vectors of size dofs() are "reduced"; of size coordinates() "full".

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/applied_loads.h"
#include "engine/forces/body_damping.h"
#include "engine/forces/body_fluid_load.h"
#include "engine/forces/body_seabed_contact.h"
#include "engine/forces/cable_damping.h"
#include "engine/forces/cable_added_mass.h"
#include "engine/forces/force_contributor.h"
#include "engine/forces/seabed.h"
#include "engine/forces/sheaves.h"
#include "engine/forces/wave_load.h"
#include "engine/forces/winch_inertia.h"
#include "engine/constraints/constraint.h"
#include "engine/constraints/joint_rows.h"
#include "engine/constraints/prescribed_motion.h"
#include "engine/constraints/quadratic_form.h"
#include "engine/scene/run_control.h"
#include "engine/scene/scene.h"
#include "engine/output/results.h"
#include "engine/linear/skyline_ldlt.h"
#include "engine/forces/sliding_joint.h"
#include "engine/linear/sparse_rows.h"

namespace cablesim {

class ModelBuilder;

class MultibodyModel {
 public:
  // Builds the mesh (a node wherever a joint, load or probe sits), the
  // coordinate map, and the constraint pattern, by the steps of
  // ModelBuilder (model_builder.h), in order. InvalidArgument names the
  // scene field when the scene cannot be assembled (for example joint sides
  // that do not coincide at t = 0). `should_stop` (empty: never) is asked
  // between the steps and within the long ones (ModelBuilder): Cancelled
  // when it said stop.
  static absl::StatusOr<MultibodyModel> Build(const Scene& scene,
                                              const std::function<bool()>& should_stop = {});
  // How many models Build has started in this process (a diagnostic: the
  // server builds one per Run request, tests/request_costing_test.cc).
  static int64_t BuildsStarted();

  // 2 (planar) or 3 (spatial), chosen by ChooseDimension (model_choice.h).
  int dimension() const { return dim_; }
  int coordinates() const { return static_cast<int>(c_.size()); }
  int dofs() const { return dofs_; }
  int multipliers() const { return joint_rows_->size(); }
  int elements() const { return static_cast<int>(elements2_.size() + elements3_.size()); }
  // Nodes of the mesh; a node split where a cable without bending
  // stiffness kinks (ModelBuilder::MeshCables) counts once.
  int nodes() const { return num_nodes_ - split_nodes_; }
  ModelInfo Info() const;

  // Initial unknowns and their rates: the scene's rigid initial motion,
  // projected onto the joints (ProjectInitialVelocity in the .cc); the
  // largest change the projection made [m/s or 1/s].
  double initial_velocity_correction() const { return initial_velocity_correction_; }
  const Eigen::VectorXd& initial_z() const { return z0_; }
  const Eigen::VectorXd& initial_v() const { return v0_; }

  // Starts the motion from unknowns z instead of the scene's layout (its
  // static equilibrium, say): the scene's rigid initial velocity is taken
  // at that configuration and projected onto the joints as in Build.
  void SetInitialState(const Eigen::VectorXd& z);
  // Starts the motion at time t [s] from unknowns z with rates v as they
  // are (a model rebuilt mid-run, JointRelease), and with the external
  // work done so far; a stepper made then starts its clock at t.
  void SetInitialState(const Eigen::VectorXd& z, const Eigen::VectorXd& v, double external_work,
                       double t) {
    z0_ = z;
    v0_ = v;
    initial_velocity_correction_ = 0;
    external_work_ = external_work;
    initial_time_ = t;
  }
  // The time [s] the motion starts at (0 but after the call above).
  double initial_time() const { return initial_time_; }

  // q = c + S z, and qdot = S zdot.
  void ToFull(const Eigen::VectorXd& z, Eigen::VectorXd* q) const;
  void RateToFull(const Eigen::VectorXd& zdot, Eigen::VectorXd* qdot) const;
  // Unknowns from a full vector, by least squares through q = c + S z
  // (exact for a full vector the map can produce; c is ignored, so this is
  // for rates and for positions whose fixed coordinates are c).
  Eigen::VectorXd Reduce(const Eigen::VectorXd& full) const;

  // The skyline envelope of the Newton matrix on z (mass, stiffness and
  // constraint Hessians all fit in it).
  const std::vector<int>& envelope() const { return envelope_; }

  // The constant reduced mass matrix S^T M S, in the layout of envelope().
  const SkylineLdlt& mass() const { return mass_; }

  // f = load_factor * Q_a(q) - Q_k(q) on the unknowns: gravity and applied
  // loads (scaled) minus elastic forces. `q` is the full configuration.
  // When `stiffness` is not null, also adds stiffness_scale * d(-f)/dz (the
  // elastic tangent stiffness K_T; the skew-symmetric derivative of torque
  // loads is left out, see NetForce in the .cc) to it; its pattern is
  // envelope(). One pass over the elements does both.
  // Returns the size of the terms that were added, max(|Q_a|_inf, |Q_k|_inf)
  // over the coordinates that move: the scale against which Newton residuals
  // are small (the two nearly cancel at equilibrium).
  // When `roundoff` is not null, it receives per unknown a bound on the
  // rounding error of f: the elements' bounds (AncfCableElement::
  // ElasticForce: coordinates known to eps |q| only, amplified by the
  // stiffness) plus eps times every term summed into the entry. This is the
  // floor below which no Newton iteration can push the residual.
  double NetForce(const Eigen::VectorXd& q, double load_factor, Eigen::VectorXd* f,
                  SkylineLdlt* stiffness = nullptr, double stiffness_scale = 0,
                  Eigen::VectorXd* roundoff = nullptr);

  // The energy-momentum stepper's elastic force (energy_momentum_stepper.h):
  // with f = NetForce(qm) at qm = (q0 + q1) / 2, subtracting the cable
  // elements' AncfCableElement::AddDiscreteGradientCorrection(q0, q1) from
  // the reduced f turns its elastic part into the discrete gradient of the
  // strain energy. Allocates nothing.
  void SubtractDiscreteGradientCorrection(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                                          Eigen::VectorXd* f);

  // Damping (velocity-dependent forces), only in a scene that asks for it:
  // per cable Kelvin-Voigt and Rayleigh damping (AncfCableElement::
  // AddDampingMatrix, with times axial_s + beta and bending_s + beta, plus
  // alpha times the element mass matrix), per body -c v on the centre of
  // mass and a torque -c omega, which in natural coordinates is the force
  // -c udot on the planar axis u, and -(c / 2) edot_k on each spatial axis
  // (for orthonormal axes |omega|^2 = (1/2) sum_k |edot_k|^2). All are
  // Q_d = -C(q) qdot with C symmetric positive semi-definite. Morison drag
  // on cables in a fluid (AncfCableElement::AddDrag) is quadratic in the
  // velocity relative to the current; C is then its velocity derivative,
  // also symmetric positive semi-definite. With waves (WaveLoad) the drag
  // is on the velocity relative to current plus waves, and the flow's
  // inertia joins the force (not C: it does not depend on qdot); both are
  // evaluated at the time of SetTime.
  bool has_damping() const { return has_damping_; }

  // Adds the damping force -C(q) qdot to the reduced force `f` (as
  // NetForce left it); when `tangent` is not null, adds tangent_scale * C
  // (on z) to it: d(-f)/d(zdot). The derivative of C(q) qdot in q is not
  // symmetric and is left out of the Newton matrix (Newton then contracts
  // at a rate of order h |C'(q) qdot| / |M / h + C|, small unless the
  // damping is strong and the motion fast). When `roundoff` is not null,
  // adds a bound of the rounding of these terms (eps times the sums of
  // absolute values). Returns the largest damping force entry [N].
  // `position_scale` (the scale the stepper gives NetForce's tangent; 0:
  // none) adds position_scale times the q-derivatives that element terms
  // do give (ElementAt::position_tangent: the seabed damping's moving
  // contact ends, which are large where a cable touches down at a small
  // angle; engine/forces/seabed.h).
  double DampingForce(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Eigen::VectorXd* f,
                      SkylineLdlt* tangent = nullptr, double tangent_scale = 0,
                      Eigen::VectorXd* roundoff = nullptr, double position_scale = 0);

  // The cables' added mass where it is not the constant mass matrix's
  // (engine/forces/cable_added_mass.h: an axial coefficient apart, or none
  // above the free surface); only the alpha-family steppers take it.
  bool has_added_mass_correction() const { return cable_added_mass_ != nullptr; }
  // Adds the inertia force -D(q) S zdd of that term, reduced, to `f` (zdd
  // the unknowns' accelerations, q the full configuration, at the time of
  // SetTime) and, when `matrix` is not null, scale * S^T D S to it (the
  // force's derivative -d(f)/d(zdd), in the mass's place in the Newton
  // matrix). Returns the largest force entry [N]. Nothing without the term.
  double AddedMassCorrection(const Eigen::VectorXd& q, const Eigen::VectorXd& zdd,
                             Eigen::VectorXd* f, SkylineLdlt* matrix = nullptr, double scale = 0);

  // The power the damping dissipates, -Q_d . qdot [W]: qdot^T C(q) qdot >= 0
  // without drag; a current or waves may make the fluid's share negative
  // (the flow then does work on the cable). At the time of SetTime.
  double DampingPower(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) const;
  // Whether DampingPower can be nonzero: damping, or a viscoelastic line
  // (whose dashpots dissipate inside its axial law, not through
  // DampingForce).
  bool has_dissipated_power() const { return has_damping_ || visco_ != nullptr; }

  // Viscoelastic lines (AxialLaw::kViscoelastic,
  // engine/elements/viscoelastic_history.h): the law's state at every Gauss
  // point of their elements. Until StartViscoelastic, and after
  // RelaxViscoelastic, the law is the relaxed T = EA e (statics, modal
  // analysis). A dynamic run starts it at its first state (reduced z, time
  // t) and commits every accepted step's end state; SetTime gives the
  // elements the law of the step to that time. Nothing without such lines.
  bool has_viscoelastic() const { return visco_ != nullptr; }
  void StartViscoelastic(const Eigen::VectorXd& z, double t);
  void CommitViscoelastic(const Eigen::VectorXd& z, double t);
  void RelaxViscoelastic();
  // The mean-load law's changes of stored energy at its stiffness updates
  // [J] (ViscoelasticHistory::Commit), which external_work() includes.
  double viscoelastic_work() const { return visco_work_; }
  // Takes over `old`'s viscoelastic state and its share of the external
  // work (a model rebuilt when a joint lets go, whose elements and Gauss
  // points are old's); false when the two do not match point for point.
  bool AdoptViscoelastic(const MultibodyModel& old);

  // The energy [J] below which a change of the total energy is rounding:
  // sum over elements of (EA + EI / l^2) l d^2, d = 16 eps (1 + |q0|_inf) / l,
  // the strain energy of the strain (and curvature) that coordinates known
  // only to their last bits can hold. The energy checks of a dynamic run
  // ignore rises below it (a cable at rest stays at rest silently).
  double energy_roundoff() const { return energy_roundoff_; }

  // Constraint values Phi(q) [multipliers()] and Jacobian dPhi/dz.
  void Constraints(const Eigen::VectorXd& q, Eigen::VectorXd* phi, SparseRows* jac) const;
  // An empty Jacobian with the constraint pattern (values to be filled).
  const SparseRows& jacobian_pattern() const { return jac_pattern_; }

  // Adds scale * sum_i lambda_i d^2 Phi_i / dz^2 to `a`.
  void AddConstraintHessian(const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                            double scale, SkylineLdlt* a) const;

  // gamma_i = -qdot^T (d^2 Phi_i / dq^2) qdot - 2 Phi_i,qt qdot -
  // d^2 Phi_i / dt^2, the right-hand side of the acceleration-level
  // constraints Phi_z zdd = gamma (eq. 30), at the time of SetTime. Only
  // the rows of moving supports depend on time: Phi_i = r_i - p_i - d_i(t),
  // so their -Phi_tt = d_i''(t); and those of turning supports, Phi_i =
  // n(t) . x, so theirs is -2 n' . xdot - n'' . x.
  void ConstraintGamma(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                       Eigen::VectorXd* gamma) const;

  // Time. Prescribed motions (rows Phi_i(q, t) = r_i(q) - p_i - d_i(t) of a
  // joint to ground whose ground point moves by d(t)) and time-varying
  // loads are evaluated at the time set here; Constraints, NetForce and
  // ConstraintGamma use it. A scene without either has nothing to
  // evaluate (is_time_dependent() false) and SetTime only stores t.
  void SetTime(double t);
  double time() const { return time_; }
  bool is_time_dependent() const { return time_dependent_; }

  // Energy of a full state; potential includes the constant loads, and
  // minus the work the external agents have done so far
  // (AccumulateExternalWork): torques, time-varying loads and moving
  // supports. `total` is then what the exact solution conserves.
  // When `parts` is not null it also receives the energy per cable and per
  // body (EnergyParts, output/results.h), each part summed over its own
  // elements, gravity and loads apart from the total's single dot product,
  // so that the parts' sums check the totals to rounding; `parts->loads` is
  // the constant loads' potential minus the external work. Its vectors are
  // resized (no allocation once they have the size).
  EnergySample Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, double load_factor,
                      EnergyParts* parts = nullptr) const;

  // Work that is not a potential's is summed step by step: call this after
  // every accepted step (or load increment) with the full configurations,
  // times and multipliers before and after it.
  //  - a torque on a body (not a constant force in these coordinates): its
  //    mean over the step times the rotation vector of the step; exact in
  //    the plane for a constant torque, in space when the rotation axis is
  //    fixed, second order otherwise;
  //  - a time-varying force F(t) at a point x: (F(t0) + F(t1)) / 2 . (x1 -
  //    x0), the trapezoidal rule (second order);
  //  - a moving support: the force it exerts on the system is -lambda_i
  //    along row i, and the support point moves by d_i(t1) - d_i(t0), so
  //    W = -(lambda_i0 + lambda_i1) / 2 (d_i(t1) - d_i(t0)) (second order);
  //  - a turning support: generally the work of a rheonomic row is
  //    int lambda_i Phi_i,t dt (since Phi_q qdot = -Phi_t), here
  //    W = (lambda_i0 + lambda_i1) / 2 (n(t1) - n(t0)) . (x0 + x1) / 2
  //    (second order; the moving support's formula is its case Phi_t =
  //    -d').
  bool has_external_work() const {
    return has_step_work_ || motion_ != nullptr;
  }
  void AccumulateExternalWork(const Eigen::VectorXd& q_before, const Eigen::VectorXd& q_after,
                              double t_before, double t_after,
                              const Eigen::VectorXd& lambda_before,
                              const Eigen::VectorXd& lambda_after, double load_factor);
  // The winches' power [W] at (q, qdot) and the time of SetTime: what a
  // reel that prescribes L(t) feeds into the energy Energy() reports.
  // Derivation (docs/model.md, "Winches"): that energy is
  // E = 1/2 qdot^T M(t) qdot + V(q, t), V the strain, contact and gravity
  // energies with the winch elements at l(t) = L(t) / N, and the motion
  // obeys M qddot = -dV/dq + f_w + f_d - Phi_q^T lambda (f_w the winch
  // cables' convective force -cv edot - ce e, f_d the damping). So
  //   dE/dt = 1/2 qdot^T Mdot qdot + dV/dt|_q + qdot . (f_w + f_d)
  //           - lambda^T Phi_q qdot,
  // whose last term is the moving supports' (AccumulateExternalWork) and
  // f_d . qdot = -P_d except on winch cables, whose damping acts on the
  // material velocity (energy.damped integrates P_d). With
  // qdot^T cv qdot = qdot^T Mdot qdot (the skew ldot (G - G^T) drops out),
  //   P_w = dV/dt|_q - 1/2 edot^T Mdot edot - edot^T ce e + (f_d . edot + P_d)
  // summed over the winch elements, and
  //   d/dt (E + damped - W_supports - W_winch) = 0, W_winch = int P_w dt.
  // Physically P_w is the drive's work on the modelled line (the line
  // tension at the drum times the paid-in speed, with the energy the
  // material carries through the drum) as this discretisation sees it:
  // it books exactly what the semi-discrete equations exchange. dV/dt|_q
  // = ldot dV/dl per element: the strain and contact energies' by central
  // differences in l extrapolated to fourth order (WinchPotentialRate),
  // gravity's exactly (GravityLoads::AddExternalPower). 0 without
  // winches.
  double ExternalPower(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) const;
  bool has_external_power() const { return !winches_.empty(); }
  // Adds work [J] to the external work's sum (ExternalWork's integral of
  // ExternalPower over a step).
  void AddExternalWork(double work) { external_work_ += work; }
  // Starts the sum over (a new run of the same model).
  void ResetExternalWork() { external_work_ = 0; }
  double external_work() const { return external_work_; }

  // Angular momentum about the world origin [kg m^2/s], exact for the
  // discretised mass: sum over elements of mbar_ab r_a x rdot_b (r_a the
  // element's nodal vectors, mbar its scalar mass matrix), plus per body
  // m r_c x rdot_c + sum_k Jb_k e_k x edot_k. Planar models return (0, 0, L_z).
  Eigen::Vector3d AngularMomentum(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) const;

  // The position [m] at undeformed arc length s [m] along cable `cable`
  // (scene order), from full coordinates q: the element's cubic there;
  // its slope dr/ds [-] into `slope` when not null.
  Eigen::Vector3d CablePosition(const Eigen::VectorXd& q, int cable, double s,
                                Eigen::Vector3d* slope = nullptr) const;

  // The scene's wave load (engine/forces/wave_load.h), or null: a scene
  // without waves holds none and its elements take AddDrag's uniform current.
  const WaveLoad* wave_load() const { return wave_load_.get(); }
  // The run's stop poll (null: none), asked in the element loops of the
  // forces: once it says stop, the forces still to be computed are
  // not-a-number (the step fails at once; the run says "cancelled").
  void set_stop_poll(StopPoll* poll) { stop_poll_ = poll; }
  StopPoll* stop_poll() const { return stop_poll_; }
  bool stop_requested() const { return stop_poll_ != nullptr && stop_poll_->stopped(); }

  // The fluid's loads on bodies (engine/forces/body_fluid_load.h): the
  // hydrostatic part in NetForce (scaled with gravity by the load factor,
  // its energy in the loads' part), the drag, inertia and wave buoyancy in
  // DampingForce (their work in the damping power).
  const std::vector<BodyFluidLoad>& body_fluid_loads() const;

  // The scene's seabed (engine/forces/seabed.h), or null: a scene without
  // one holds no seabed object, and its force loops only test this.
  const Seabed* seabed() const { return cable_seabed_ ? &cable_seabed_->bed() : nullptr; }

  // Bodies with seabed contact points (BodySpec::contact_points_m): their
  // count. A scene without any holds none and its loops only test this.
  int body_contacts() const { return body_contact_ ? body_contact_->count() : 0; }

  // STATIC analyses only: the seabed's static friction (Seabed::
  // AddStaticFriction, on cables and body contact points) at full q,
  // opposing the displacement from q_start (where the analysis started).
  // Adds its generalized force to the reduced `f` and scale times its
  // matrix (symmetric, positive semi-definite; on z) to `matrix` when not
  // null. has_static_friction(): whether there is any (else this does
  // nothing and costs nothing). `roundoff` (reduced, when not null): adds
  // the friction's rounding floor (cables' and body contact points'), as
  // NetForce's (see the .cc).
  bool has_static_friction() const;
  void StaticFriction(const Eigen::VectorXd& q, const Eigen::VectorXd& q_start,
                        Eigen::VectorXd* f, SkylineLdlt* matrix, double scale,
                        Eigen::VectorXd* roundoff = nullptr);
  // Whether frames carry energy.contact (a seabed or sheaves).
  bool has_contact() const { return has_element_contact_; }

  // The scene's sheaves (engine/forces/sheave.h), none in most scenes.
  const std::vector<Sheave>& sheaves() const;

  // Whether frames carry the nodes' positions (the scene's output.shape).
  bool shape() const { return shape_; }
  // Every cable node's position [m] from full coordinates q (a split node
  // once), in the order of ModelInfo::node_s; from a rate, the nodes'
  // velocities. `out` is resized (no allocation once it has the size).
  void NodePositions(const Eigen::VectorXd& q, std::vector<Eigen::Vector3d>* out) const;

  // Probes from full position, velocity and acceleration.
  void Probes(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
              const Eigen::VectorXd& qddot, std::vector<ProbeSample>* out) const;
  // The force [N] a moving support exerts on what it holds, -lambda of its
  // position rows, per probe placed on such a joint
  // (ModelInfo::force_probe_names).
  // A probe at a winch's end (the cable's last point) reports the line
  // tension instead: the force [N] the winch exerts on the cable, EA eps
  // r_s at s = L(t) (eps the Green-Lagrange strain there, r_s the slope,
  // pointing into the winch; |force| is the tension). `q`: full positions.
  void ProbeForces(const Eigen::VectorXd& q, const Eigen::VectorXd& lambda,
                   std::vector<Eigen::Vector3d>* out) const;
  // With output.reactions (reactions()), every joint's reaction from full
  // positions q and the multipliers (ConstraintFamily::AddReactions): the
  // force on its side a and, FIXED, the moment about its point. `out` is
  // resized to the scene's joints (no allocation once it has the size).
  // `lambda` null (no multipliers at hand, MODAL): zeros (a row keeps its
  // size).
  bool reactions() const { return !joint_reaction_values_.empty(); }
  // Per joint of ModelInfo::release_joints: 1 when it has let go (the model
  // was rebuilt without it, JointRelease), else 0 (Frame::joint_released).
  const std::vector<double>& joint_released() const { return joint_released_; }
  void Reactions(const Eigen::VectorXd& q, const Eigen::VectorXd* lambda,
                 std::vector<JointReaction>* out) const;
  // With output.tension (tension()): the cable's axial force [N] at every
  // probe on a cable (ModelInfo::tension_probe_names) and, with shape,
  // at every node of NodePositions, from full positions q at load factor
  // `load_factor` (1 but in statics' load steps): the section force that
  // the elements' equations hold at the nodes (model_outputs.cc, Tensions,
  // says how and what it leaves out), its component along the tangent;
  // compression negative. `probes` and `nodes` are resized. With `qdot`
  // (full rates; a dynamic state), the section force also carries the
  // cables' material damping (Kelvin-Voigt: damping.axial_time and
  // bending_time, Rayleigh beta; CableDamping::AddMaterialForce), as
  // MoorDyn's and OrcaFlex's line tensions carry their axial damping;
  // without it, the elastic force alone (statics, modal shapes).
  bool tension() const { return tension_; }
  void Tensions(const Eigen::VectorXd& q, double load_factor, std::vector<double>* probes,
                std::vector<double>* nodes, const Eigen::VectorXd* qdot = nullptr) const;
  // With output.bending_moment (bending_moment()): the bending moment [N m]
  // at every probe on a cable (ModelInfo::bending_moment_probe_names), from
  // the elements' slope rows as Tensions reads their position rows: the
  // moment u x Q_u the cable beyond the probe exerts on the cable before
  // it, averaged over the two elements at a node; planar: about z,
  // spatial: its size. `out` is resized.
  // `qdot` as for Tensions (the bending damping's moment).
  bool bending_moment() const { return bending_moment_; }
  void BendingMoments(const Eigen::VectorXd& q, double load_factor, std::vector<double>* out,
                      const Eigen::VectorXd* qdot = nullptr) const;
  // The same at each node of cable `cable` (its elements' ends, in order).
  std::vector<double> CableNodeTensions(const Eigen::VectorXd& q, int cable, double load_factor,
                                        const Eigen::VectorXd* qdot = nullptr) const;
  // With output.orientation (orientation()): per body 10 values
  // (Frame::body_orientation) from full q and qdot. The body's axes are its
  // natural coordinates (e1 = u, e2 = v, e3 = w, the columns of R), so
  // R = [u v w]; the quaternion is R's (qw >= 0), roll/pitch/yaw its
  // Z-Y-X angles, and the angular velocity omega = (1/2) sum_i e_i x de_i/dt
  // (from dR/dt = [omega]x R). Planar: angle = atan2(u_y, u_x) about z,
  // omega_z = (u x udot)_z / |u|^2. `out` is resized (no allocation once
  // it has the size).
  bool orientation() const { return orientation_; }
  // Body `body`'s rotation R = [u v w] from full q (planar: about z, from
  // u; not re-orthogonalised: the axes' rows hold them to the solver's
  // tolerance).
  Eigen::Matrix3d BodyRotation(const Eigen::VectorXd& q, int body) const;
  void Orientations(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                    std::vector<double>* out) const;
  // The number of probes on a moving support or a winch's end (ProbeForces' size).
  int force_probe_count() const { return static_cast<int>(force_probes_.size()); }

  // Sliding joints (SlidingJoint, a penalty force): their number, and
  // where each slider is now, its arc length on its cable [m] as of the
  // last evaluation.
  int sliders() const { return sliders_ ? sliders_->count() : 0; }
  double SliderArcLength(int i) const { return sliders_->slider(i).s(); }

  // The force contributors the scene uses (engine/forces/force_contributor.h),
  // in the order the model sums them.
  const std::vector<std::unique_ptr<ForceContributor>>& contributors() const {
    return contributors_;
  }
  // The per-element force terms the scene uses (ElementTerm).
  const std::vector<std::unique_ptr<ElementTerm>>& element_terms() const {
    return element_terms_;
  }
  // What made a non-finite force at q (qdot null: positions only), for
  // a failure message: each term evaluated on its own, in the model's
  // order (a non-finite state, the elements' elastic force, the element
  // terms, the contributors), the first one with a non-finite entry and
  // where ("non-finite force from contributor 'seabed' (cables[1] node
  // 7)", "elastic force, cables[0] element 3"); empty when every term is
  // finite, or once a stop was requested (set_stop_poll's NaN). Only on a
  // failure path: it allocates.
  std::string DescribeNonFinite(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot,
                                double load_factor) const;
  // Full coordinate i as a scene place: "cables[c] node n", "bodies[b]".
  std::string DescribeCoordinate(int i) const;
  // Appends a force contributor after the scene's (summed last): a
  // caller's own force on a built model (the tests inject one this way).
  void AddContributor(std::unique_ptr<ForceContributor> c);
  // The contributor called `name`, or null.
  const ForceContributor* FindContributor(std::string_view name) const;

  // Winches (WinchSpec, docs/model.md "Winches"): an axially moving mesh
  // on each winch cable, whose N elements all have the length L(t) / N, so
  // the model's size is fixed while the free length L(t) changes. At
  // SetTime the winch cables' elements and their mass matrices (in
  // mass()) are evaluated at L(t), and so are the contributors' gravity
  // (forces/gravity_loads.h) and convective inertia and damping
  // (forces/winch_cables.h: velocity-dependent, so DampingForce adds them,
  // which every stepper calls; not dissipation: DampingPower leaves the
  // inertia out). A scene without
  // winches holds none and pays nothing. The total energy of a winch
  // scene is not conserved (the winch does work that is not summed), so
  // the dynamic run's energy guard is off there.
  int winches() const { return static_cast<int>(winches_.size()); }
  // Winch w's cable (scene order) and its free length L [m] at the time
  // of SetTime.
  int WinchCable(int w) const { return winches_[w].cable; }
  double WinchLength(int w) const { return winches_[w].length; }
  // A cable's mass [kg] from its elements' mass matrices at the time of
  // SetTime (rho A L(t) on a winch cable).
  double CableMass(int cable) const;

  // Which joint a constraint row belongs to (for messages), or -1 for a
  // body's own axis constraints.
  int RowJoint(int row) const { return joint_rows_->row(row).joint; }

  // The map q = c + S z as contributors and constraint families see it.
  CoordinateMap Map() const { return CoordinateMap{j_.data(), s_.data(), dim_}; }

  // The constraint families the scene uses (engine/constraints/constraint.h).
  const std::vector<const ConstraintFamily*>& constraint_families() const {
    return families_view_;
  }
  // The moving and turning supports' rows (null without any): a coupling
  // session (engine/run/coupling.h) sets its coupled supports' motions.
  PrescribedMotion* prescribed_motion() { return motion_.get(); }

 private:
  // Build's steps fill in the members below.
  friend class ModelBuilder;

  template <int D>
  struct ElementData {
    AncfCableElement<D> element;
    int first_coord = 0;  // full index of its first node's position
    double mass_per_length = 0;
    // The mass per length its weight acts on [kg/m] (less the displaced
    // fluid's): output.tension's section forces take its weight off
    // (ElementEndForces); the force itself is GravityLoads'.
    double weight_per_length = 0;
    Eigen::Matrix4d mbar;  // scalar mass matrix: M = mbar (x) I_D
  };
  struct BodyData {
    int coord = 0;  // full index of r_c
    double mass = 0;
    Eigen::Vector3d jbar = Eigen::Vector3d::Zero();  // per axis [kg m^2]
    // The fluid's added mass on the body's natural coordinates
    // (BodyFluidLoad::AddedMass, summed over the body's parts; [kg] on r_c,
    // the rest only for parts off the centre of mass), in the mass matrix
    // and the kinetic energy; only with has_added_mass.
    bool has_added_mass = false;
    BodyFluidLoad::GeneralizedMatrix added_mass = BodyFluidLoad::GeneralizedMatrix::Zero();
  };
  // A flat linear form sum coeff * q[coord].
  struct ProbeTerm {
    int coord = 0;
    double coeff = 0;
  };
  // A winch (WinchSpec) on a cable: what the model keeps of it, its
  // elements' length and mass (the mass matrix, which the steppers factor,
  // is the model's); its forces are contributors (forces/winch_cables.h,
  // and its gravity forces/gravity_loads.h).
  template <int D>
  double WinchPotentialRate(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot) const;
  struct WinchData {
    int cable = 0;
    int element_begin = 0, element_end = 0;  // the cable's elements
    WinchReel reel;
    double length = 0;                       // L at time_ [m]
    double mass_per_length = 0;              // rho A [kg/m]
    double ea = 0;                           // [N]
  };
  template <int D>
  double ElementForces(const Eigen::VectorXd& q, Eigen::VectorXd* full, SkylineLdlt* stiffness,
                       double stiffness_scale, Eigen::VectorXd* roundoff) const;
  template <int D>
  std::string DescribeNonFiniteElements(const Eigen::VectorXd& q,
                                        const Eigen::VectorXd* qdot) const;
  template <int D>
  void ElementDiscreteGradientCorrection(const Eigen::VectorXd& q0, const Eigen::VectorXd& q1,
                                         Eigen::VectorXd* full) const;
  template <int D>
  double ElementDamping(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                        Eigen::VectorXd* full, SkylineLdlt* tangent, double tangent_scale,
                        Eigen::VectorXd* roundoff, double* power,
                        double position_scale = 0) const;
  template <int D>
  double ElementAddedMass(const Eigen::VectorXd& q, const Eigen::VectorXd& qdd,
                          Eigen::VectorXd* full, SkylineLdlt* matrix, double scale) const;
  template <int D>
  void ElementEnergy(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, EnergySample* en,
                     EnergyParts* parts) const;
  // Tensions' and BendingMoments' parts: the section force at element k's
  // two ends (its internal force's end-position rows, with its material
  // damping's when qdot is given, less its weight's share) and, when asked
  // for, the moment u x Q_u of its end-slope rows (the same force vector,
  // computed once); the tension at (cable, s), and at every node of a cable
  // into out. `qdot` may be null (no damping term).
  template <int D>
  void ElementEndForces(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot, int k,
                        double load_factor, Eigen::Vector3d* start, Eigen::Vector3d* end,
                        Eigen::Vector3d* moment_start = nullptr,
                        Eigen::Vector3d* moment_end = nullptr) const;
  template <int D>
  double TensionOf(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot, int cable, double s,
                   double load_factor) const;
  // The bending moment vector at (cable, s) (model_outputs.cc).
  template <int D>
  Eigen::Vector3d BendingMomentOf(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot,
                                  int cable, double s, double load_factor) const;
  template <int D>
  void CableNodeTensionsOf(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot, int cable,
                           double load_factor, double* out) const;
  template <int D>
  Eigen::Vector3d CablePositionOf(const Eigen::VectorXd& q, int cable, double s,
                                  Eigen::Vector3d* slope) const;
  template <int D>
  Eigen::Vector3d ElementAngularMomentum(const Eigen::VectorXd& q,
                                         const Eigen::VectorXd& qdot) const;
  // An element's gravity force [N] at its current length, for the
  // outputs' section forces (the same numbers GravityLoads sums).
  template <int D>
  typename AncfCableElement<D>::Coords ElementWeight(const ElementData<D>& e) const {
    return AncfCableElement<D>::GravityForceOfLength(e.element.length(), e.weight_per_length,
                                                     gravity_.head<D>());
  }
  // The state contributors are evaluated at (time_ and the wave field).
  ForceState StateAt(const Eigen::VectorXd& q, const Eigen::VectorXd* qdot,
                     double load_factor) const {
    return ForceState{&q, qdot, load_factor, time_, waves_};
  }
  void ProjectInitialVelocity();
  // SetTime's share for the winches: their elements' length and mass at
  // time_.
  template <int D>
  void UpdateWinches();
  template <int D>
  Eigen::Vector3d WinchTension(const Eigen::VectorXd& q, int w) const;
  // The scene's rigid initial velocity at full configuration q (all nodes
  // and bodies; fixed coordinates are dropped by Reduce).
  void RigidVelocity(const Eigen::VectorXd& q, Eigen::VectorXd* qdot) const;
  template <int D>
  const std::vector<ElementData<D>>& Elements() const {
    if constexpr (D == 2) {
      return elements2_;
    } else {
      return elements3_;
    }
  }

  int dim_ = 2;
  int node_stride_ = 4;  // 2 D
  int body_stride_ = 4;  // 4 planar, 12 spatial

  // Coordinate map: q_i = c_i + s_i z_{j_i} (j_i = -1: constant).
  Eigen::VectorXd c_, s_;
  std::vector<int> j_;
  int dofs_ = 0;
  int num_nodes_ = 0;    // including the second half of each split node
  int split_nodes_ = 0;
  Eigen::VectorXd z0_, v0_;
  double initial_velocity_correction_ = 0;
  InitialVelocitySpec initial_velocity_;

  std::vector<ElementData<2>> elements2_;
  std::vector<ElementData<3>> elements3_;
  std::vector<BodyData> bodies_;
  // Per cable, its first element; one more entry, the element count.
  std::vector<int> cable_element_begin_;
  std::vector<std::string> cable_names_, body_names_;
  Eigen::Vector3d gravity_ = Eigen::Vector3d::Zero();  // [m/s^2], for the outputs
  // The cable nodes of ModelInfo: per distinct node its position's first
  // full coordinate; per cable the count; per node its arc length [m].
  bool shape_ = false;
  // Per scene joint its name, and with output.reactions the numbers of its
  // reaction in a row (ModelInfo::joint_reaction_values).
  std::vector<std::string> joint_names_;
  std::vector<int> joint_reaction_values_;
  // The scene joints that may let go (ModelInfo::release_joints) and, per
  // such joint, 1 when this model was built with it released, else 0.
  std::vector<int> release_joints_;
  std::vector<double> joint_released_;
  // output.tension: per probe on a cable, its probe, cable and arc length;
  // per cable its EA [N]; per shape node, its cable.
  bool tension_ = false;
  bool bending_moment_ = false;
  std::vector<int> tension_probe_, tension_cable_;
  std::vector<double> tension_s_, cable_ea_;
  std::vector<bool> cable_engineering_;  // per cable: AxialLaw::kEngineering
  bool orientation_ = false;  // output.orientation
  std::vector<int> node_cable_;
  // Reactions' work space, per joint.
  mutable std::vector<Eigen::Vector3d> reaction_forces_, reaction_moments_;
  std::vector<int> shape_coord_;
  std::vector<int> cable_nodes_;
  std::vector<double> node_s_;
  double energy_roundoff_ = 0;
  bool has_damping_ = false;
  // The per-element force terms the scene uses (ElementTerm; none in
  // most scenes), summed in this order inside the element loops (cable
  // damping, the fluid's load, the seabed, the sheaves); those with a potential and
  // those that dissipate; per element whether any dissipative term acts on
  // it (empty without any); whether any stores contact energy; the cable
  // seabed's typed view.
  std::vector<std::unique_ptr<ElementTerm>> element_terms_;
  std::vector<const ElementTerm*> potential_terms_, dissipative_terms_;
  std::vector<char> element_dissipates_;
  bool has_element_contact_ = false;
  const CableSeabed* cable_seabed_ = nullptr;
  // The cables' damping term (null: no cable is damped), for the material
  // damping in the tension outputs (ElementEndForces).
  const CableDamping* cable_damping_ = nullptr;
  // The viscoelastic lines' state (null: none), and the elements (in the
  // model's element list) whose Gauss points it holds, in its order.
  std::unique_ptr<ViscoelasticHistory> visco_;
  std::vector<int> visco_elements_;
  std::vector<double> visco_strains_;  // scratch: one strain per point
  std::vector<double> visco_jump_;     // scratch: one energy jump per point [J/m]
  double visco_work_ = 0;              // viscoelastic_work()
  template <int D>
  double ViscoelasticEnergyJump(const std::vector<double>& per_point) const;
  template <int D>
  void ViscoelasticStrains(const Eigen::VectorXd& z);
  template <int D>
  double ViscoelasticPower(const Eigen::VectorXd& q) const;
  // Scratch (full size) for StaticFriction (sized on first use).
  Eigen::VectorXd scratch_static_;
  Eigen::VectorXd scratch_static_roundoff_;
  // The sheaves' typed view (null without sheaves).
  const Sheaves* sheaves_ = nullptr;
  // Only in a scene whose fluid has waves (then it carries the current
  // too); shared with the cables' fluid load (CableFluidLoad). For the
  // outputs (wave_load()); the assembly only passes the field (waves_,
  // null without waves) to the contributors in ForceState.
  std::shared_ptr<const WaveLoad> wave_load_;
  const WaveField* waves_ = nullptr;
  // The cables' added mass beyond the mass matrix's (null: none) and its
  // scratch (full size: accelerations, force).
  std::unique_ptr<CableAddedMass> cable_added_mass_;
  Eigen::VectorXd scratch_qdd_, scratch_added_;
  // The stop poll's units of work per Gauss point in the damping pass: 1,
  // plus one per wave component the fluid's load sums there.
  int64_t damping_point_cost_ = 1;
  StopPoll* stop_poll_ = nullptr;
  // Counts `units` of work on the stop poll; true when the run should stop.
  // The elastic forces ask the stop poll once per this many elements.
  static constexpr size_t kPollElements = 64;
  bool StopNow(int64_t units) const { return stop_poll_ != nullptr && stop_poll_->Poll(units); }
  // The force contributors the scene uses (none in most scenes), summed in
  // this order; and typed views of some of them for the accessors above.
  std::vector<std::unique_ptr<ForceContributor>> contributors_;
  // NetForce's applied loads: the sum of the contributors' constant ones
  // (empty if none) and the contributors whose applied load varies, in the
  // list's order (ModelBuilder::Contributors).
  Eigen::VectorXd constant_applied_;
  std::vector<const ForceContributor*> varying_applied_;
  const BodyFluidForces* body_fluid_ = nullptr;
  const BodySeabedContact* body_contact_ = nullptr;
  const SlidingJoints* sliders_ = nullptr;
  bool has_step_work_ = false;  // a contributor whose work is summed per step

  // The constraint families: the joints' rows (always, possibly none) and
  // the supports' time law (only with moving or turning supports); the
  // families the scene uses, in the order they are summed.
  std::unique_ptr<JointRows> joint_rows_ = std::make_unique<JointRows>();
  std::unique_ptr<PrescribedMotion> motion_;
  std::vector<ConstraintFamily*> families_;
  std::vector<const ConstraintFamily*> families_view_;

  // Probes: per probe and component d < 3, a linear form over q (as flat
  // term lists); velocity and acceleration use the same coefficients.
  std::vector<int> probe_term_begin_;  // size 3 * probes + 1
  std::vector<ProbeTerm> probe_terms_;
  std::vector<double> probe_const_;    // 3 per probe
  std::vector<std::string> probe_names_;

  std::vector<int> envelope_;
  SkylineLdlt mass_;
  // Per element, the (4D)^2 skyline slots (or -1) and factors s_a s_b.
  std::vector<int> element_slots_;
  std::vector<double> element_factors_;
  // The same, only the entries with a slot (about half: the skyline holds
  // one triangle), in the order of t: element k's are
  // element_scatter_[element_scatter_begin_[k] .. element_scatter_begin_[k + 1]).
  struct ScatterEntry {
    int slot;
    int t;  // index into the element's (4D)^2 matrix data
    double factor;
  };
  std::vector<ScatterEntry> element_scatter_;
  std::vector<int> element_scatter_begin_;
  // Adds scale times element k's symmetric (4D)^2 matrix m (either storage
  // order) to the skyline `values` through those slots; kN2 = (4D)^2.
  // The entries without a slot are not visited (a test per entry cost the
  // OC4 mooring's damping, force and added-mass loops 6 % of its run);
  // the sums are the same, in the same order.
  template <int kN2>
  void ScatterElementMatrix(int k, const double* m, double scale, double* values) const {
    const ScatterEntry* entry = element_scatter_.data() + element_scatter_begin_[k];
    const ScatterEntry* end = element_scatter_.data() + element_scatter_begin_[k + 1];
    for (; entry < end; ++entry) values[entry->slot] += scale * entry->factor * m[entry->t];
  }
  SparseRows jac_pattern_;
  // Scratch (full size) for NetForce.
  Eigen::VectorXd scratch_full_, scratch_roundoff_;
  // Per probe on a moving support, its row per component (-1: none).
  std::vector<std::array<int, 3>> probe_force_rows_;
  std::vector<int> force_probes_;  // which probes (ascending)
  // Time dependence.
  double time_ = 0;
  bool time_dependent_ = false;
  // Work done by torques, time-varying loads and moving supports so far [J].
  double external_work_ = 0;
  double initial_time_ = 0;  // SetInitialState(z, v, work, t)
  // Winches (empty in most scenes: then nothing is evaluated).
  std::vector<WinchData> winches_;
  // mass_'s values without the winch elements' shares.
  std::vector<double> mass_base_;
  // Per probe: the winch at whose end it sits (ProbeForces), or -1.
  std::vector<int> probe_winch_;
  // Scratch (full size) for DampingForce (sized only when has_damping_).
  Eigen::VectorXd scratch_damping_, scratch_damping_roundoff_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_MODEL_MULTIBODY_MODEL_H_
