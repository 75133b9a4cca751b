#ifndef CABLESIM_ENGINE_OUTPUT_RESULTS_H_
#define CABLESIM_ENGINE_OUTPUT_RESULTS_H_

// What a run reports: the model it built (ModelInfo), its frames (Frame:
// probe samples, energy, reactions, shape) delivered to a FrameSink, and its
// summary (RunSummary: cost and trust). Plain data, below the model, the
// analyses and the run loop, which all fill it.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/status.h"

namespace cablesim {

// What the engine built for a scene.
struct ModelInfo {
  std::string model;       // "planar" (later also "spatial")
  int coordinates = 0;     // all nodal and body coordinates
  int dofs = 0;            // unknowns after removing ground-fixed ones
  int multipliers = 0;     // Lagrange multipliers (constraint equations)
  int elements = 0;        // cable elements, inserted nodes included
  int nodes = 0;           // cable nodes (a node split where a cable kinks counts once)
  std::vector<std::string> probe_names;
  // The probes placed on a moving support (a joint to ground with a
  // motion), in scene order: their samples carry force_n, written as
  // NAME.fx NAME.fy NAME.fz after the other columns.
  std::vector<std::string> force_probe_names;
  // Cable and body names in scene order (the parts of EnergyParts).
  std::vector<std::string> cable_names;
  std::vector<std::string> body_names;
  // Per cable, its nodes (a split node once), and every node's arc length
  // in the undeformed cable [m], cable by cable: the nodes of Frame::nodes.
  std::vector<int> cable_nodes;
  std::vector<double> node_s;
  // Whether frames carry Frame::nodes (the scene's output.shape).
  bool shape = false;
  // Whether the scene has a seabed: frames then carry energy.contact.
  bool contact = false;
  // Joint names (JointSpec::name, may be empty) in scene order.
  std::vector<std::string> joint_names;
  // With output.reactions, per joint: the numbers of its reaction in a row
  // (Frame::reactions): 3 (force), 6 (FIXED: force and moment) or 0
  // (SLIDE). Empty without.
  std::vector<int> joint_reaction_values;
  // With output.tension: the probes on a cable (scene order), each with a
  // column NAME.tension; and whether the nodes carry their tension
  // (output.shape too).
  std::vector<std::string> tension_probe_names;
  bool node_tension = false;
  // With output.orientation: every frame carries each body's orientation
  // (Frame::body_orientation).
  bool body_orientation = false;
  // With output.bending_moment: the probes on a cable (scene order), each
  // with a column NAME.bending_moment.
  std::vector<std::string> bending_moment_probe_names;
  // The joints that may let go (JointSpec::release_time_s, breaking_load_n),
  // by scene index in scene order, each with a column joints[i].released
  // after the bending moments. Empty in a scene without a release.
  std::vector<int> release_joints;
};

// The force [N] a joint exerts on its side a (a joint to ground: on what it
// holds) and, for FIXED, the moment [N m] about the joint's point.
struct JointReaction {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  // The numbers it has in a row (ModelInfo::joint_reaction_values).
  int values = 3;
};

struct ProbeSample {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration_m_s2 = Eigen::Vector3d::Zero();
};

// Energy [J]. `potential` is that of gravity and of the constant applied
// loads (both conservative) minus the work done so far by torques,
// time-varying loads and moving supports (summed step by step), so `total`
// is conserved by the exact solution without damping; with damping,
// total + damped is.
struct EnergySample {
  double kinetic = 0;
  double potential = 0;
  double axial = 0;
  double bending = 0;
  double total = 0;  // kinetic + potential + axial + bending + contact
  // Work done against damping since t = 0 (>= 0, not part of `total`): the
  // dissipated power qdot^T C qdot (MultibodyModel::DampingPower) integrated
  // by the trapezoidal rule over the accepted steps, and from a step's start
  // to a frame inside it. 0 without damping.
  double damped = 0;
  // Elastic energy stored in the seabed (engine/forces/seabed.h), part of
  // `total`; 0 without one. (Last, so that aggregate initialisers of the
  // fields above keep their meaning.)
  double contact = 0;
};

// The energy of one cable or one body [J]. `gravity` is the potential of
// gravity, -m g . r_c for a body and -int rho A g . r ds for a cable (zero
// at the world origin, as EnergySample::potential). A body has no strain:
// its axial and bending are 0.
struct PartEnergy {
  double kinetic = 0;
  double gravity = 0;
  double axial = 0;
  double bending = 0;
};

// EnergySample split by part. Summed over the parts, kinetic, axial and
// bending are the totals' and gravity plus `loads` is the total potential:
//   potential = sum gravity + loads,
// `loads` being the potential of the applied point forces (-F . r) minus
// the work torques have done so far, plus the sliding joints' penalty
// energy (SlidingJoint).
struct EnergyParts {
  std::vector<PartEnergy> cables;  // in scene order
  std::vector<PartEnergy> bodies;  // in scene order
  double loads = 0;
};

struct Frame {
  // Time [s] for DYNAMIC; the load factor in (0, 1] for STATIC.
  double t = 0;
  std::vector<ProbeSample> probes;  // in scene order
  EnergySample energy;
  // The same energy per cable and per body (sized as ModelInfo's
  // cable_names and body_names in every frame; zeros in a MODAL shape).
  EnergyParts energy_parts;
  // Angular momentum about the world origin [kg m^2/s] (z only for a
  // planar model); conserved about any axis along which the applied loads
  // and joints to ground exert no moment. Zero unless the sink asks for it
  // (FrameSink::wants_angular_momentum).
  Eigen::Vector3d angular_momentum = Eigen::Vector3d::Zero();
  // Per probe of ModelInfo::force_probe_names: the force [N] its moving
  // support exerts on the cable or body it holds (the cable pulls the
  // support with the opposite force). Empty in most scenes.
  std::vector<Eigen::Vector3d> support_forces;
  // Largest absolute constraint residual (m for positions, dimensionless
  // for tangent cross products).
  double constraint_violation = 0;
  // With output.shape (ModelInfo::shape): every cable node's position [m],
  // cable by cable, in the order of ModelInfo::node_s; empty otherwise.
  // In a MODAL shape frame, the nodes' displacement in the mode (scaled as
  // the probes').
  std::vector<Eigen::Vector3d> nodes;
  // Whether the row carries energy.contact (ModelInfo::contact).
  bool has_contact = false;
  // With output.reactions, per joint in scene order; empty otherwise.
  std::vector<JointReaction> reactions;
  // With output.tension, per probe of ModelInfo::tension_probe_names the
  // cable's axial force there [N] (compression negative), and with shape
  // too, per node of `nodes`.
  std::vector<double> probe_tensions;
  std::vector<double> node_tensions;
  // With output.orientation, per body (scene order) 10 values: the unit
  // quaternion qw, qx, qy, qz (body axes to world, qw >= 0), roll, pitch,
  // yaw [rad] (R = Rz(yaw) Ry(pitch) Rx(roll)) and the angular velocity
  // wx, wy, wz [rad/s] in world axes.
  std::vector<double> body_orientation;
  // With output.bending_moment, per probe of
  // ModelInfo::bending_moment_probe_names the cable's bending moment there
  // [N m] (planar: about z; spatial: its size).
  std::vector<double> probe_bending_moments;
  // Per joint of ModelInfo::release_joints: 0 while it holds, 1 from the
  // state at which it let go on (JointRelease). Empty without a release.
  std::vector<double> joint_released;
};

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  virtual absl::Status OnStart(const ModelInfo& info) { return absl::OkStatus(); }
  // A non-OK status stops the run (the summary says "cancelled").
  virtual absl::Status OnFrame(const Frame& frame) = 0;
  // Whether it reads Frame::angular_momentum, which no output column
  // carries: the run computes it only for a sink that says so (0.4 % of
  // the OC4 mooring benchmark's CPU otherwise). A sink that passes frames
  // on to another forwards the question.
  virtual bool wants_angular_momentum() const { return false; }
};

// The statistics of one frame column (engine/output/frame_columns.h) over
// the frames of a run, in the column's unit; times are Frame::t (the load
// factor for STATIC). The first frame holding the extreme gives its time.
struct ColumnStatistics {
  std::string column;
  int64_t count = 0;  // frames
  double min = 0, min_t = 0;
  double max = 0, max_t = 0;
  double mean = 0;    // over frames (a time mean when frames are evenly spaced)
  double stddev = 0;  // population standard deviation over frames
};

// Rainflow counting (ASTM E1049-85 5.4.4) of one column's frame series.
struct RainflowStatistics {
  std::string column;
  double cycles = 0;       // full cycles, a half cycle counting 0.5
  double half_cycles = 0;  // how many half cycles (each adds 0.5 to cycles)
  double max_range = 0;    // largest counted range
  // (sum n_i S_i^m / N_eq)^(1/m), S_i the ranges, n_i their counts.
  double damage_equivalent_load = 0;
};

// output.statistics and output.rainflow (engine/output/run_statistics.h).
struct RunStatistics {
  std::vector<ColumnStatistics> columns;  // frame column order, `t` left out
  double sn_slope = 0;                    // of the rainflow's DEL
  double equivalent_cycles = 0;
  std::vector<RainflowStatistics> rainflow;  // in output.rainflow.columns order
};

// A joint that let go during a dynamic run (JointSpec::release_time_s,
// breaking_load_n; engine/run/joint_release.h).
struct JointReleaseEvent {
  int joint = -1;       // scene index
  std::string name;     // JointSpec::name
  double time_s = 0;    // when it let go
  double force_n = 0;   // |force| it carried then [N]
  std::string cause;    // "time" or "breaking_load"
};

// A stretch of a DYNAMIC run made by one stepper (AUTO may change it
// during the run: engine/run/auto_integrator.h).
struct IntegratorSegment {
  std::string integrator;  // its name (integrator_traits.h)
  double start_s = 0;      // the time it took over [s]
  int64_t steps = 0;       // accepted steps it made
  std::string reason;      // why it ran (one sentence)
};

struct RunSummary {
  std::string status = "ok";  // "ok", "failed" or "cancelled"
  std::string error;          // why, when not ok (with the time)
  double failure_time_s = 0;  // time of the step that failed
  std::string analysis;       // "DYNAMIC" or "STATIC"
  std::string integrator;  // the stepper that ran
  // What the scene asked for ("AUTO" or a stepper's name) and, with AUTO,
  // why `integrator` was chosen (engine/run/auto_integrator.h).
  std::string integrator_requested;
  std::string integrator_reason;
  // DYNAMIC: which stepper ran from when, for how many steps and why; one
  // segment unless AUTO changed the stepper during the run.
  std::vector<IntegratorSegment> integrator_segments;
  std::string linear_solver;
  ModelInfo info;
  int64_t frames = 0;
  int64_t steps = 0;            // accepted steps (load increments for STATIC)
  int64_t rejected_steps = 0;   // steps retried with half the step
  int64_t newton_iterations = 0;
  int64_t linear_iterations = 0;
  double min_step_s = 0;        // smallest step taken
  double wall_seconds = 0;     // the whole run, error-estimate companion included
  double end_time_s = 0;        // last converged time (or load factor)
  double energy_initial = 0;
  double energy_final = 0;
  // Energy the stepper removed: initial minus final total energy for a
  // scene without external work (gravity and constant loads included);
  // backward Euler's numerical damping.
  // With damping: initial minus (final total + energy_damped), so the
  // stepper's own dissipation stays apart from the damping's.
  double energy_dissipated = 0;
  double energy_damped = 0;  // the last frame's energy.damped [J]
  // Largest rise of total + damped above its start.
  double energy_max_increase = 0;
  double max_constraint_violation = 0;
  double max_newton_residual = 0;  // largest accepted Newton residual norm
  // The largest rounding floor of an accepted Newton residual, relative as
  // max_newton_residual (engine/steppers/newton_convergence.h): what double
  // precision cannot resolve in these coordinates.
  double max_residual_floor = 0;
  double max_linear_residual = 0;  // largest true relative residual of a solve
  // MODAL: the natural frequencies [Hz], ascending (engine/analysis/modal_solver.h).
  std::vector<double> frequencies_hz;
  // DYNAMIC: the stepper's cost and step sizes.
  std::string linear_solver_used;  // what AUTO resolved to (else linear_solver)
  int64_t factorizations = 0;      // Newton matrices assembled and factored
  int64_t direct_fallbacks = 0;    // DIRECT solves that had to run MINRES
  // Newton-step linear solves (linear_iterations / linear_solves is the
  // Krylov cost per solve), and those whose true relative residual stayed
  // above 1e-6: accepted with solver.accept_inexact_solves, else refused
  // (the step was halved).
  int64_t linear_solves = 0;
  int64_t inexact_linear_solves = 0;
  double max_step_s = 0;           // largest step taken
  bool adaptive = false;
  double rho_infinity = 0;         // GENERALIZED_ALPHA and HHT
  // solver.error_estimate: an estimate of the largest probe-position error
  // of the run [m] (over every frame and probe), and how it was obtained.
  // error_estimate_m < 0 when no estimate could be made (the method says why).
  bool has_error_estimate = false;
  double error_estimate_m = -1;
  std::string error_estimate_method;
  double error_estimate_seconds = 0;  // wall time of the companion run
  // DYNAMIC: the joints that let go, in the order they did.
  std::vector<JointReleaseEvent> releases;
  // output.statistics or output.rainflow: what the frames say.
  bool has_statistics = false;
  RunStatistics statistics;
  // DYNAMIC, every run: the largest estimated local error of an accepted
  // step [m] (the stepper's embedded estimate, Stepper::LocalErrorNorm,
  // that adaptive steps are controlled by; units of the coordinates), and
  // the tolerance it is held to (SolverSettings::error_tolerance_m).
  double local_error_estimate_m = 0;
  double error_tolerance_m = 0;
  // DYNAMIC, every run: the sum of those estimates over the accepted steps
  // [m], what the global error would be if every step's error added up
  // with no cancellation and no growth. The largest one step alone can be
  // thousands of times below the error at the end where the motion
  // amplifies earlier errors (the cable with an end cylinder, whose slack
  // phases near t = 1.6 s grow them about 150 times: docs/honest-runs.md);
  // the sum was within 1.1 to 1.6 times above the error there, and 3 to
  // 120 times above it on the pendulums and the 1,000-element rope.
  double accumulated_error_estimate_m = 0;
  // The largest LocalErrorNorm(h, error_tolerance_m, relative_tolerance)
  // of an accepted step: > 1 means a step missed the tolerance. Engine
  // only (the warning says it).
  double local_error_ratio = 0;
  // Fixed steps: the smallest step that rejections cut solver.step to
  // (infinity: none was cut; not the last steps shortened to end on the
  // duration). Engine only.
  double smallest_cut_step_s = std::numeric_limits<double>::infinity();
  // What makes the result doubtful although the run finished
  // (engine/run/run_warnings.h), one sentence each; empty: none.
  std::vector<std::string> warnings;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_OUTPUT_RESULTS_H_
