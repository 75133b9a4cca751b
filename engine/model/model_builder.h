#ifndef CABLESIM_ENGINE_MODEL_MODEL_BUILDER_H_
#define CABLESIM_ENGINE_MODEL_MODEL_BUILDER_H_

// The steps that turn a Scene into a MultibodyModel (multibody_model.h
// describes the coordinates, the elimination q = c + S z and the ordering
// of the unknowns that these steps set up). MultibodyModel::Build runs them
// in the order they are declared here; each step needs the results of the
// steps before it, and keeps its own in a plainly named member that a test
// can read (tests/model_builder_test.cc).

#include <array>
#include <functional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "engine/forces/cable_added_mass.h"
#include "engine/forces/cable_buoyancy.h"
#include "engine/forces/cable_damping.h"
#include "engine/forces/cable_fluid_load.h"
#include "engine/forces/current_profile.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/gravity_loads.h"
#include "engine/forces/winch_cables.h"
#include "engine/model/multibody_model.h"
#include "engine/constraints/quadratic_form.h"
#include "engine/scene/scene.h"

namespace cablesim {

class ModelBuilder {
 public:
  // The cables' nodes, numbered cable by cable along each cable.
  struct Mesh {
    // Per cable, the arc length of each node [m], ascending, from 0 to the
    // cable's length; the two halves of a split node have the same s.
    std::vector<std::vector<double>> node_s;
    // Per cable, the number of its first node; one more entry, the total.
    std::vector<int> first_node;
    // Per node, the node whose position it shares (the first half of a
    // split pair), or -1.
    std::vector<int> twin_of;
    // Per cable, the distance [m] within which two arc lengths are one
    // node: 1e-9 of the cable's length.
    std::vector<double> snap_m;

    int nodes() const { return first_node.back(); }
    // The node at a cable attachment (the first half of a split node).
    int Node(const Attachment& at) const;
  };

  // What the joints to ground remove from the unknowns.
  struct Elimination {
    // Per full coordinate: held at its initial value by a joint to ground.
    std::vector<bool> grounded;
    // Per node: clamped (FIXED to ground), its slope then being alpha
    // times clamp_dir (unit [-], the initial tangent) with alpha unknown.
    std::vector<bool> clamped;
    std::vector<Eigen::Vector3d> clamp_dir;
  };

  // A constraint row before the rows no unknown can change are dropped.
  struct PendingRow {
    QuadraticForm f;
    JointRows::Row::Kind kind;
    int joint;  // scene joint, or -1 for a body's own axis constraint
    int body;   // the body of an axis constraint, or -1
    // A moving support's position row: the component of the joint's
    // motion subtracted from it in time (-1: none).
    int motion_axis = -1;
    // A turning support's direction row n(t) . x = 0 (x the D coordinates
    // from full index turn_coord: a clamped slope or a body axis; n(0) =
    // turn_n0); f then holds placeholder coefficients on all of x so that
    // the pattern has every slot n(t) may fill. -1: none.
    int turn_coord = -1;
    Eigen::Vector3d turn_n0 = Eigen::Vector3d::Zero();
    // The joint's reaction (JointRows::Row::axis, side_begin, side_end).
    int axis = -1;
    int side_begin = 0, side_end = 0;
  };

  // `should_stop` (empty: never) is asked between the steps, between cables
  // (MeshCables, InitialCoordinates) and every 65,536 nodes or elements of
  // the steps whose cost grows with them (OrderUnknowns, BuildElements,
  // EnvelopeAndMass): a stopped step returns early, and Stopped() tells the
  // caller to give the builder up. Measured on 2 million elements, no stretch
  // between two asks takes much more than 0.3 s.
  explicit ModelBuilder(const Scene& scene, std::function<bool()> should_stop = {})
      : scene_(scene), should_stop_(std::move(should_stop)) {}

  // Whether the caller asked to stop (once true, stays true).
  bool Stopped() {
    if (!stopped_ && should_stop_) stopped_ = should_stop_();
    return stopped_;
  }

  // Planar or spatial (ChooseDimension, model_choice.h), and with it the
  // strides of nodes (2 D coordinates) and bodies (4 or 12). Fails as
  // ChooseDimension does.
  absl::Status ChooseDimension();

  // Fails, naming the field, when a winch (CableSpec::winch) cannot be
  // modelled: its free length would reach 0 within solver.duration (at the
  // time named), its cable's last point is not held by a PIN or FIXED
  // joint to ground, something is attached inside the cable (joints,
  // loads and probes only at its two ends: its mesh moves through the
  // material), a sliding joint runs on it, the scene has a fluid or a
  // seabed (their loads on an axially moving mesh are not built), or the
  // integrator is ENERGY_MOMENTUM (its energy statement needs a constant
  // mass).
  absl::Status CheckWinches() const;

  // mesh(): per cable, `elements` uniform nodes plus a node at every joint
  // side, load and probe on it; arc lengths within Mesh::snap_m of one
  // another are one node, and of the cable's end, the end. A cable
  // without bending stiffness kinks where a PIN or a point load acts
  // inside it: the node there is split in two (a C0 node) that share
  // their position unknowns but not their slopes, so the elements on
  // either side meet at an angle (slopes continuous across it would round
  // the kink off over an element and shorten the sag at a hung body at
  // first order in the element length). Not where a FIXED joint acts on
  // that point: that joint is about the slope.
  void MeshCables();

  // q0(): the full initial coordinates: per node its point on the cable's
  // polyline [m] and slope (unit tangent times the polyline's length over
  // the cable's, [-]; the two halves of a split node take the tangents of
  // their sides); per body its centre of mass [m] and axes [-] from
  // BodySpec::axis. Also the model's body data (mass [kg], Jb [kg m^2]).
  // Fails when a spatial body's principal moments break the triangle
  // inequality (names bodies[i].inertia).
  absl::Status InitialCoordinates();

  // elimination(): the coordinates that joints to ground hold (a node's
  // position; a whole body welded to ground; a body's centre of mass when
  // pinned there) and the clamped nodes. A joint to ground with a motion
  // (a moving support) keeps its point as D rows r - p0 - d(t) instead
  // (rheonomic: MultibodyModel::SetTime); FIXED still clamps a node's
  // slope to its initial direction, or a body's axes to their initial
  // ones. pending_rows(): every other joint
  // as constraint rows (points coincide: D rows; FIXED also ties slopes or
  // axes), then each body's axes unit and orthogonal (1 row planar, 6
  // spatial). Fails for a joint with ground on both sides, and for FIXED
  // between two cables whose tangents are not parallel in the same sense.
  absl::Status Joints();

  // Fails when a joint kept as rows is not satisfied by q0: FIXED with the
  // cable tangent off the other side's axis (sine > 1e-6), or two points
  // more than 1e-6 m apart. The messages name the joint.
  absl::Status CheckJointsAtStart() const;

  // The coordinate map q = c + S z: unknowns numbered along each cable,
  // node by node (position unless grounded, the shared position of a
  // split node's first half, then the slope: one unknown alpha if
  // clamped, D otherwise), each body's right after the first node it is
  // joined to (other bodies last); grounded coordinates are constants
  // from q0. Then the initial unknowns z0 and their rates v0 (the scene's
  // rigid velocity) by least squares through the map.
  void OrderUnknowns();

  // The pending rows into the model, but for a row no unknown can change
  // (its gradient on z at q0 is below 1e-12: both sides held by ground,
  // say): satisfied by construction, it would only make the Newton
  // system singular.
  void KeepMovableRows();

  // Fails when a moving support's row was dropped by KeepMovableRows (its
  // point is also held by a fixed joint to ground): names the joint.
  absl::Status CheckMovingRows() const;

  // Fails when the scene's integrator cannot take what it holds:
  // DORMAND_PRINCE integrates unconstrained motion only (no constraint rows
  // after KeepMovableRows: joints to ground eliminate coordinates, every
  // other joint and a body's axes are rows; IntegratorTraits::
  // takes_constraint_rows), and the explicit ones take no winches (the mass
  // is factored once). Names the first joint or body.
  absl::Status CheckIntegratorFits() const;

  // The ANCF elements between consecutive nodes (not between the halves
  // of a split node) with their gravity [N] and scalar mass matrices [kg],
  // the model's energy_roundoff [J], and where each cable's elements begin
  // (for the energy per cable).
  void BuildElements();

  // The force contributors the scene uses (engine/forces/force_contributor.h),
  // each built by the Make... next to its class, in the order the model
  // sums them: applied loads (time-varying forces, torques), body damping,
  // body seabed contact, body fluid loads (whose added mass joins
  // the bodies' mass here), sliding joints (MakeSlidingJoints fails when a
  // slider's body point is more than 1e-6 m from its cable at t = 0, naming
  // the joint). A contributor that dissipates turns on the damping pass.
  absl::Status Contributors();
  // The scene's free surface (disabled without fluid.free_surface) and the
  // buoyancy the cables lose above it (CableSurfaceBuoyancy; null: none).
  FreeSurface Surface() const;
  // The scene's current by depth (empty: the uniform current).
  CurrentProfile Current() const;
  template <int D>
  std::unique_ptr<ForceContributor> SurfaceBuoyancy(
      const std::vector<MultibodyModel::ElementData<D>>& elements) const;

  // The winches' data (MultibodyModel::WinchData): their cables' element
  // ranges; the model then needs its damping pass (the convective terms).
  void Winches();

  // Gravity and the loads' constant forces as a contributor (GravityLoads,
  // forces/gravity_loads.h), first in the list: element and body gravity
  // and each load's force at its point. Torques and time-varying forces
  // are the applied-loads contributor's (Contributors).
  void ConstantForces();

  // Each probe's point as a linear form of q (position [m] = const + sum
  // coeff q_i); a probe on the point a moving support holds also gets that
  // support's rows (its force, MultibodyModel::ProbeForces); and the cable
  // nodes whose positions output.shape writes.
  void Probes();

  // The skyline envelope of the Newton matrix on z (what elements, bodies
  // and rows couple), the reduced mass matrix S^T M S [kg, kg m^2] in it,
  // and the element scatter tables (skyline slot and factor per entry).
  void EnvelopeAndMass();

  // The constraint Jacobian's pattern on z, and per monomial of a row its
  // Hessian entry on z and factor.
  void ConstraintPattern();

  // The model: scratch space, its time set to 0 (moving supports and
  // varying loads at their start), the initial velocity projected onto
  // the joints (and the supports' initial velocity). The builder is spent.
  MultibodyModel Finish();

  // Results of the steps.
  const Mesh& mesh() const { return mesh_; }
  const Eigen::VectorXd& q0() const { return q0_; }
  const Elimination& elimination() const { return elimination_; }
  const std::vector<PendingRow>& pending_rows() const { return pending_; }
  // The model so far.
  const MultibodyModel& model() const { return model_; }
  // After OrderUnknowns: the unknown that full coordinate i is a multiple
  // of, or -1 (a constant).
  int UnknownOf(int i) const { return model_.j_[i]; }

 private:
  using Row = JointRows::Row;

  // Relative tolerance for matching arc lengths to nodes.
  static constexpr double kSnap = 1e-9;

  // Full index of a node's position, of a body's centre of mass.
  int NodeCoord(int node) const { return model_.node_stride_ * node; }
  int BodyCoord(int body) const;
  // Points and directions as linear forms of q.
  LinearVector NodePosition(int node) const;
  LinearVector NodeSlope(int node) const;
  // Body axis k (0: x, 1: y, 2: z) in the world.
  LinearVector BodyAxis(int body, int k) const;
  std::array<LinearVector, 3> BodyAxes(int body) const;
  LinearVector BodyPoint(int body, const Eigen::Vector3d& p) const;
  LinearVector PointOf(const Attachment& at) const;
  // A linear vector's value at q0.
  Eigen::Vector3d AtStart(const LinearVector& v) const;
  // The rows of a FIXED joint that keep the orientation: slopes of two
  // cables welded end to end, a cable tangent along a body's x axis, or
  // two bodies' axes. Fails for two cables not parallel at t = 0.
  absl::Status AddOrientationRows(int joint, Attachment a, Attachment b);
  // The direction rows of a FIXED joint to ground that turns (JointSpec::
  // rotation), holding side `a`'s slope or axes.
  // `turning` false: the rows n0 . x = 0 of a FIXED support that does not
  // turn, kept as rows for its reaction (output.reactions).
  void AddTurningRows(int joint, Attachment a, bool turning = true);
  // The full coordinates of the direction vectors of a joint's side a (its
  // side that is not ground): a cable node's slope or a body's axes.
  std::pair<int, int> SideVectors(const JointSpec& joint) const;
  template <int D>
  void BuildElementsOf(std::vector<MultibodyModel::ElementData<D>>* elements);
  // The element scatter tables (per element, the (4D)^2 skyline slots
  // and factors s_a s_b) and the elements' share of the mass matrix.
  // Finish's share for the winches: mass_base_, the mass values without
  // the winch elements; and their contributor (WinchCables), last in the
  // contributors' list.
  template <int D>
  void WinchBases(const std::vector<MultibodyModel::ElementData<D>>& elements);
  template <int D>
  void WinchContributor(const std::vector<MultibodyModel::ElementData<D>>& elements);
  template <int D>
  void SetupElementSlots(const std::vector<MultibodyModel::ElementData<D>>& elements);

  const Scene& scene_;
  std::function<bool()> should_stop_;
  bool stopped_ = false;
  MultibodyModel model_;
  Mesh mesh_;
  Eigen::VectorXd q0_;
  std::vector<Eigen::Matrix3d> frame0_;  // per body, its axes at t = 0
  Elimination elimination_;
  std::vector<PendingRow> pending_;
  // BuildElementsOf's per-element damping and fluid-load data, and the
  // damping term (the winches clear their cables' share).
  std::vector<CableDamping::Element> damping_elements_;
  std::vector<CableFluidLoad::Element> fluid_elements_;
  std::vector<CableAddedMass::Element> added_mass_elements_;
  CableDamping* cable_damping_ = nullptr;
  // Per element: its cable, for GravityLoads (ConstantForces).
  std::vector<int> element_cable_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_MODEL_MODEL_BUILDER_H_
