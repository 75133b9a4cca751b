#ifndef CABLESIM_ENGINE_SCENE_SCENE_H_
#define CABLESIM_ENGINE_SCENE_SCENE_H_

// The engine's description of a scene: plain structs, free of protobuf.
// convert/ builds one from a cablesim.v1.Scene after validating it; the
// vectors here keep the indices of the scene file, so the engine can name a
// field (`joints[1]`) in its own errors.
//
// Units are SI: m, kg, s, N, Pa, rad.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/scene/time_function.h"

namespace cablesim {

// AUTO: planar when the whole scene lies in the x-y plane (model_choice.h).
enum class ModelChoice { kAuto, kPlanar, kSpatial };
enum class BendingModel { kExact, kLinear, kNone };
// The axial law (engine/elements/ancf_cable_element.h): the strain energy
// EA/2 eps^2 of the Green-Lagrange strain eps = (|r'|^2 - 1) / 2, or of the
// engineering strain e = |r'| - 1 (tension T = EA e, as mooring decks
// mean their EA), or a tension-strain table T(e) in the engineering strain
// (CableSpec::tension_table_*; engine/elements/tension_table.h), or the
// viscoelastic law of polyester and nylon ropes: two Kelvin-Voigt elements
// in series (CableSpec::visco_*; engine/elements/viscoelastic_history.h).
enum class AxialLaw { kGreenLagrange, kEngineering, kTable, kViscoelastic };
// kSlide: a body point kept on a cable, free to slide along it
// (SlidingJoint; JointSpec::slide).
enum class JointType { kPin, kFixed, kSlide };
enum class Analysis { kDynamic, kStatic, kModal };
enum class Integrator { kImplicitEuler, kGeneralizedAlpha, kHht, kEnergyMomentum, kDormandPrince,
                              kCentralDifference };
// kDirect: exact block elimination (skyline LDL^T of the Newton block and a
// dense Schur complement); kAuto: picked per scene (SaddlePointSolver).
enum class LinearSolverKind { kMinres, kGmres, kDirect, kAuto };
// What preconditions MINRES and GMRES (engine/linear/saddle_point_solver.h).
enum class PreconditionerKind { kBlock, kJacobi, kNone };
// Where a DYNAMIC run starts: the scene as laid out, or its static
// equilibrium under gravity and loads (StaticSolver).
enum class InitialState { kAsGiven, kStatic };

// The scene-file spelling of an enum value, e.g. "DYNAMIC", "MINRES" (what
// the summary reports).
std::string_view AnalysisName(Analysis analysis);
// IntegratorName and every other fact of an integrator: integrator_traits.h.
std::string_view LinearSolverName(LinearSolverKind solver);

// A winch at a cable's end (MultibodyModel, docs/model.md "Winches"): the
// cable's free (unstretched) length is L(t) = length_m + int_0^t speed, so
// a positive speed [m/s] pays cable out and a negative one reels it in.
// The winch holds the cable's last point (s = length_m), which a joint to
// ground (PIN or FIXED, fixed or moving) must hold; the cable's material
// is measured from its first point (s = 0), where the payload stays.
struct WinchSpec {
  bool enabled = false;
  TimeFunction speed;
};

struct CableSpec {
  std::string name;
  // Polyline the undeformed-length cable is laid along at t = 0 (>= 2
  // points). A straight cable has two.
  std::vector<Eigen::Vector3d> points;
  double length_m = 0;  // undeformed length
  int elements = 10;    // before extra nodes are inserted
  // Gauss points per element of the element's integrals without a closed
  // form (strain energy, Kelvin-Voigt damping, fluid loads), in
  // [kMinGaussPoints, kMaxGaussPoints]; the default is the element's
  // (AncfCableElement::kDefaultGaussPoints). Two points sample too little
  // strain for a string (bending NONE): OC4's lines found no static
  // equilibrium with them. (Scene validation also refuses 4.)
  static constexpr int kMinGaussPoints = 3, kMaxGaussPoints = 8;
  int gauss_points = 5;
  double density_kg_m3 = 0;
  double youngs_modulus_pa = 0;
  double area_m2 = 0;
  double second_moment_m4 = 0;
  BendingModel bending = BendingModel::kExact;
  AxialLaw axial_law = AxialLaw::kGreenLagrange;
  // With AxialLaw::kTable: the knots of T(e) [-, N], strains increasing
  // from 0, tensions non-decreasing from 0 (TensionTable). The tension is
  // the table's; youngs_modulus_pa * area_m2 stays the nominal EA that
  // the axial damping time multiplies and the step checks use.
  std::vector<double> tension_table_strains;
  std::vector<double> tension_table_tensions;
  // With AxialLaw::kViscoelastic (MoorDyn's viscoelastic line types; Hall
  // et al., IOWTC2023-110827): in the engineering strain e, a spring
  // EA_1 beside a dashpot BA [N s] (the slow, static part) in series with a
  // spring EA_2 beside a dashpot BA_D [N s] (the fast, dynamic part). The
  // static EA = EA_1 EA_2 / (EA_1 + EA_2) is youngs_modulus_pa * area_m2;
  // the dynamic EA_2 is visco_dynamic_ea_n, or, when that is 0, the mean-
  // load law EA_2 = visco_dynamic_ea_base_n + visco_dynamic_ea_slope *
  // T_mean (T_mean = EA_1 e_1, the static part's tension). EA_2 > EA;
  // BA + BA_D > 0.
  double visco_dynamic_ea_n = 0;
  double visco_dynamic_ea_base_n = 0;
  double visco_dynamic_ea_slope = 0;
  double visco_static_damping_ns = 0;
  double visco_dynamic_damping_ns = 0;
  // Damping (MultibodyModel::DampingForce; 0: none). Kelvin-Voigt
  // retardation times [s]: axial stress E (eps + axial_damping_s deps/dt),
  // bending moment EI (kappa + bending_damping_s dkappa/dt). Rayleigh:
  // mass-proportional alpha [1/s] (force -alpha M qdot) and
  // stiffness-proportional beta [s], applied to the material stiffness,
  // that is added to both retardation times.
  double axial_damping_s = 0;
  double bending_damping_s = 0;
  double rayleigh_alpha_1_s = 0;
  double rayleigh_beta_s = 0;
  // Hydrodynamics in the scene's fluid (MultibodyModel::DampingForce,
  // ModelBuilder::BuildElements): Morison drag coefficients normal and
  // tangential [-], added-mass coefficient [-] and outer diameter [m]
  // (0: that of a solid circle of the cable's area).
  double normal_drag = 0;
  double tangential_drag = 0;
  double added_mass = 0;
  // Along the cable (MoorDyn's CaAx) [-], when has_axial_added_mass;
  // otherwise added_mass acts in every direction
  // (engine/forces/cable_added_mass.h).
  bool has_axial_added_mass = false;
  double axial_added_mass = 0;
  double hydro_diameter_m = 0;
  // Concentrated fluid loads along the tangent at the cable's start [0]
  // and end [1] (Hydrodynamics.start_tip, end_tip): drag area C_d A [m^2]
  // and added mass [kg] (engine/forces/cable_fluid_load.h,
  // cable_added_mass.h).
  double tip_drag_area_m2[2] = {0, 0};
  double tip_added_mass_kg[2] = {0, 0};
  bool has_tip_loads() const {
    return tip_drag_area_m2[0] != 0 || tip_drag_area_m2[1] != 0 || tip_added_mass_kg[0] != 0 ||
           tip_added_mass_kg[1] != 0;
  }
  WinchSpec winch;  // disabled: the length is fixed
  // The seabed's normal stiffness [N/m^2] and damping [N s/m^2] per unit
  // length of this cable when it has its own (a mooring deck's kBot and
  // cBot act on each line's diameter); negative: the scene's SeabedSpec's.
  double seabed_stiffness_n_m2 = -1;
  double seabed_damping_n_s_m2 = -1;
};

// One hydrodynamic part of a body (BodySpec::hydro_parts): a circular
// cylinder of diameter and height [m] centred at the body's centre of mass
// (or at center_m from it, in the body's frame) displaces the fluid (buoyed as a vertical one); Morison drag
// coefficients across its split axis (on d times the submerged length) and
// along it (on the end area) [-], added-mass coefficients across and along
// [-]. The split axis is the vertical, or with along_axis the body-frame
// direction axis_body (a rod, turning with the body).
struct BodyFluidPart {
  double diameter_m = 0, height_m = 0;
  double drag = 0, heave_drag = 0;
  double added_mass = 0, heave_added_mass = 0;
  bool along_axis = false;
  Eigen::Vector3d axis_body = Eigen::Vector3d::UnitX();  // unit, body frame
  // Drag areas along the body's axes [m^2] and about them [m^5]
  // (BodyFluidLoad::AreaDrag); a part with them alone has no cylinder
  // (diameter_m = height_m = 0: no buoyancy, wet wherever it is).
  Eigen::Vector3d drag_area_m2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotational_drag_area_m5 = Eigen::Vector3d::Zero();
  // The cylinder's centre in the body's frame from the centre of mass [m]
  // (BodyFluidLoad's offset; zero: at the centre of mass).
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  // Where the scene gave it: -1 Body.hydrodynamics, k >= 0
  // Body.hydrodynamics_parts[k] (for naming the field).
  int scene_index = -1;
};

struct BodySpec {
  std::string name;
  double mass_kg = 0;
  // Principal moments of inertia about the centre of mass, body axes.
  Eigen::Vector3d inertia_kg_m2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // centre of mass
  // Local x axis in the world at t = 0, unit. The local y axis is
  // normalize(e_z x axis) (normalize(e_x x axis) when the axis is along z),
  // and z = x x y; the principal moments refer to these axes.
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  // Damping (0: none): force -linear c v on the centre of mass [N s/m],
  // torque -angular c omega [N m s/rad].
  double linear_damping_n_s_m = 0;
  double angular_damping_n_m_s = 0;
  // Points of the body that touch the seabed (Seabed::PointPotential), body
  // frame [m]; empty: the body never touches it (and costs nothing).
  // Each point has its own normal spring [N/m] and damper [N s/m], and
  // isotropic Coulomb friction `contact_friction` [-] in the bed's plane
  // (regularised as the cable's, by seabed.friction_speed).
  std::vector<Eigen::Vector3d> contact_points_m;
  double contact_stiffness_n_m = 0;
  double contact_damping_n_s_m = 0;
  double contact_friction = 0;
  // Fluid loads in the scene's fluid (engine/forces/body_fluid_load.h),
  // only when has_hydrodynamics: one or more parts (BodyFluidPart), each a
  // cylinder centred at the centre of mass or off it, whose loads add up.
  bool has_hydrodynamics = false;
  std::vector<BodyFluidPart> hydro_parts;
  // Driven by a coupling host (engine/run/coupling.h): its pose (centre of
  // mass and axes) is the host's, step by step; the scene holds it by a
  // driver joint (CoupledBodyDriver, appended to the joints). In an
  // ordinary run it stays where the scene places it.
  bool coupled = false;
};

// A place on a cable (cable >= 0), on a body (body >= 0), or the ground
// (both -1).
struct Attachment {
  int cable = -1;
  double s_m = 0;  // arc length in the undeformed cable
  int body = -1;
  Eigen::Vector3d point_body_m = Eigen::Vector3d::Zero();
  bool IsGround() const { return cable < 0 && body < 0; }
};

// Three time functions: a vector (x, y, z) that varies in time.
using TimeVector = std::array<TimeFunction, 3>;
bool IsZero(const TimeVector& v);
// Its value, first or second derivative (order 0, 1, 2) at t.
Eigen::Vector3d Evaluate(const TimeVector& v, double t, int order = 0);

// A sliding joint's parameters (SlidingJoint).
struct SlideSpec {
  double friction = 0;        // Coulomb coefficient mu [-]
  double stiffness_n_m = 0;   // penalty stiffness [N/m]; 0: EA / l_e of the cable
  double stick_velocity_m_s = 1e-3;  // friction regularization v_s [m/s]
};

struct JointSpec {
  JointType type = JointType::kPin;
  Attachment a;  // never ground
  Attachment b;
  // Joints to ground only: the ground point moves by motion(t) [m] from
  // its place at t = 0 (motion(0) = 0); a FIXED joint keeps its initial
  // direction (the support translates). Zero: a fixed support.
  TimeVector motion;
  SlideSpec slide;  // SLIDE only
  // Joints to ground only: the ground point is driven by a coupling host
  // (engine/run/coupling.h), a moving support whose motion the host sets
  // step by step; zero motion outside a coupling session.
  bool coupled = false;
  bool HasMotion() const { return coupled || !IsZero(motion); }
  // FIXED joints to ground only: the support also turns by the angle
  // rotation(t) [rad] (rotation(0) = 0) about the unit `rotation_axis`
  // (world axes), and the held slope or body axes turn with it.
  TimeFunction rotation;
  Eigen::Vector3d rotation_axis = Eigen::Vector3d::UnitZ();
  // A coupled body's driver (CoupledBodyDriver): a coupled FIXED joint to
  // ground at the body's centre whose turning rows the coupling host also
  // drives (their axis and angle are set step by step); zero rotation
  // outside a coupling session.
  bool coupled_rotation = false;
  bool HasRotation() const { return coupled_rotation || !rotation.IsZero(); }
  // Free text naming the joint in the outputs (ModelInfo::joint_names).
  std::string name;
  // Line failure (PIN and FIXED only, not at a winch's end or coupled):
  // the joint lets go at release_time_s [s] or at the end of the first
  // step whose reaction force |F| exceeds breaking_load_n [N], whichever
  // comes first (engine/run/joint_release.h). Negative: not asked.
  double release_time_s = -1;
  double breaking_load_n = -1;
  bool HasRelease() const { return release_time_s >= 0 || breaking_load_n > 0; }
  // Set by the dynamic run once the joint has let go (never by the input):
  // the model is then built without its rows (its reaction reads 0).
  bool released = false;
};

struct LoadSpec {
  Attachment at;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_nm = Eigen::Vector3d::Zero();  // bodies only
  // Added to force_n and torque_nm at time t (statics: at t = 0).
  TimeVector varying_force_n;
  TimeVector varying_torque_nm;
  bool IsVarying() const { return !IsZero(varying_force_n) || !IsZero(varying_torque_nm); }
};

struct ProbeSpec {
  std::string name;
  Attachment at;
};

// A regular linear (Airy) wave (WaveField::AddRegular): height H = 2 a
// [m], period [s], horizontal unit direction of travel, phase [rad].
struct RegularWaveSpec {
  double height_m = 0;
  double period_s = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double phase_rad = 0;
};

// An irregular JONSWAP sea (WaveField::AddJonswap).
struct JonswapSpec {
  double significant_height_m = 0;
  double peak_period_s = 0;
  double peak_factor = 3.3;  // gamma [-]
  uint64_t seed = 0;
  int components = 100;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // horizontal, unit
};

// One wave component given by the user (WaveField::AddComponent):
// amplitude [m], angular frequency [rad/s], horizontal unit direction,
// phase [rad].
struct WaveComponentSpec {
  double amplitude_m = 0;
  double omega_rad_s = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double phase_rad = 0;
};

// A sea given by its elevation at the origin (WaveField::
// AddElevationSeries): times [s] strictly increasing, elevations [m],
// resampling interval [s] (0: the mean interval), cutoff [rad/s] (0: none).
struct ElevationSeriesSpec {
  std::vector<double> times_s;
  std::vector<double> elevations_m;
  double interval_s = 0;
  double cutoff_rad_s = 0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

// Waves on the fluid's surface (engine/forces/waves.h, their load
// engine/forces/wave_load.h): the sum of every component, ramped in over
// ramp_s [s] (0: none).
struct WavesSpec {
  std::vector<RegularWaveSpec> regular;
  std::vector<JonswapSpec> jonswap;
  std::vector<WaveComponentSpec> components;
  std::vector<ElevationSeriesSpec> elevation_series;  // none or one
  double ramp_s = 0;
  bool any() const {
    return !regular.empty() || !jonswap.empty() || !components.empty() ||
           !elevation_series.empty();
  }
};

// A fluid filling the scene: density [kg/m^3] (0: none) and a uniform,
// steady current [m/s]. Cables in it are buoyed (their displaced weight is
// taken off their gravity) and feel their hydrodynamics. Waves, when there
// are any, are measured from the still water level (its height above the
// origin along the vertical, the opposite of gravity [m]) in water of
// water_depth_m [m] below it.
struct FluidSpec {
  double density_kg_m3 = 0;
  Eigen::Vector3d current_m_s = Eigen::Vector3d::Zero();
  double still_water_level_m = 0;
  double water_depth_m = 0;
  WavesSpec waves;
  // true: the cables' fluid loads act below the instantaneous water level
  // only (engine/forces/cable_buoyancy.h); false: everywhere.
  bool free_surface = false;
  // The current by depth below the still level (engine/forces/
  // current_profile.h): depths [m] strictly increasing, velocities [m/s];
  // empty: the uniform current_m_s.
  std::vector<double> current_profile_depths_m;
  std::vector<Eigen::Vector3d> current_profile_velocities_m_s;
  // The current on a grid in space and time (engine/forces/
  // current_profile.h): axes x, y, z [m] and times [s], each strictly
  // increasing; velocities [m/s] at index ((a ny + b) nz + c) nt + d;
  // empty axes: none.
  std::vector<double> current_grid_x_m, current_grid_y_m, current_grid_z_m, current_grid_t_s;
  std::vector<Eigen::Vector3d> current_grid_velocities_m_s;
};

// A bathymetry grid (engine/forces/bathymetry_grid.h): depths [m] below
// the origin along the seabed's normal at nx x ny nodes u = origin_x + i dx,
// v = origin_y + j dy on the two axes across the normal, row-major
// (depths_m[j nx + i]), bilinear between them.
struct BathymetrySpec {
  bool enabled = false;  // false: the bed is the plane of SeabedSpec
  double origin_x_m = 0, origin_y_m = 0;
  double dx_m = 1, dy_m = 1;
  int nx = 1, ny = 1;
  std::vector<double> depths_m;
};

// The seabed's dynamic friction law (SeabedSpec::friction_law).
enum class FrictionLaw { kRegularized, kMoorDyn };

// A seabed the cables lie on (MultibodyModel, engine/forces/seabed.h): the
// plane of points r with normal . r = -depth_m, the normal pointing out of
// the bed into the water. Contact is a distributed spring and damper per
// unit undeformed cable length; Coulomb friction acts in the bed's plane.
struct SeabedSpec {
  bool enabled = false;  // false: no seabed (and no seabed object)
  double depth_m = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // unit
  double stiffness_n_m2 = 0;   // [N/m per m of penetration per m of cable]
  double damping_n_s_m2 = 0;   // [N s/m per m of cable]
  double friction_axial = 0;       // Coulomb coefficient along the cable [-]
  double friction_transverse = 0;  // across the cable, in the bed's plane [-]
  // Sliding speed [m/s] below which friction is regularised (the friction
  // force grows as v / sqrt(v^2 + friction_speed^2)).
  double friction_speed_m_s = 1e-3;
  // STATIC analyses: displacement [m] from the configuration the analysis
  // starts from (where the line was laid) below which friction is
  // regularised (Seabed::AddStaticFriction).
  double friction_length_m = 1e-5;
  // The dynamic friction law (engine/forces/seabed.h): kRegularized (the
  // law above) or kMoorDyn, MoorDyn's viscous-then-Coulomb law with
  // friction_damping [N s/m per m of cable] and static_friction_scale.
  FrictionLaw friction_law = FrictionLaw::kRegularized;
  double friction_damping_n_s_m2 = 0;
  double static_friction_scale = 1;
  // When enabled, the bed is this grid instead of the plane (depth_m is
  // then 0 and the normal a coordinate axis: the grid's "up").
  BathymetrySpec bathymetry;
};

// A fixed wheel cables wrap around (engine/forces/sheave.h): a cylinder of
// radius_m about the axis through position_m, pushing cables out with a
// distributed spring and damper per unit undeformed length and rubbing on
// them with Coulomb friction (a wheel that does not turn).
struct SheaveSpec {
  std::string name;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  double radius_m = 0;
  double stiffness_n_m2 = 0;  // [N/m per m of penetration per m of cable], > 0
  double damping_n_s_m2 = 0;  // [N s/m per m of cable]
  double friction = 0;        // Coulomb coefficient [-]
  double friction_speed_m_s = 1e-3;  // regularisation, as SeabedSpec's
  std::vector<int> cables;    // indices of the cables it touches; empty: all
  bool Touches(int cable) const {
    return cables.empty() || std::find(cables.begin(), cables.end(), cable) != cables.end();
  }
  // The body carrying it (index in Scene::bodies; the wheel's centre is the
  // body's centre of mass and position_m is unused), or -1: fixed.
  int body = -1;
};

struct InitialVelocitySpec {
  Eigen::Vector3d linear_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rad_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
};

struct SolverSettings {
  Analysis analysis = Analysis::kDynamic;
  double duration_s = 0;
  double step_s = 1e-3;
  double output_interval_s = 0;  // 0: every step
  Integrator integrator = Integrator::kHht;
  LinearSolverKind linear_solver = LinearSolverKind::kAuto;
  int load_steps = 10;
  double newton_tolerance = 1e-8;
  int max_newton_iterations = 25;
  int max_step_halvings = 12;
  double linear_tolerance = 1e-10;
  int max_linear_iterations = 200;
  // MINRES and GMRES: the preconditioner, and whether a DYNAMIC Newton step
  // may use a solve whose true relative residual stayed above
  // kMaxLinearResidual (engine/steppers/newton_convergence.h) after
  // max_linear_iterations; such solves are counted in the summary.
  PreconditionerKind preconditioner = PreconditionerKind::kBlock;
  bool accept_inexact_solves = false;
  // MODAL: number of lowest modes; 0 means the default (10, or every degree
  // of freedom when there are fewer).
  int modes = 0;
  // Numerical damping of GENERALIZED_ALPHA and HHT: the spectral radius of
  // the amplification matrix at infinite frequency, in [0, 1] ([0.5, 1] for
  // HHT); 1 conserves the energy of linear problems.
  double rho_infinity = 0.5;
  // Adaptive steps: the step grows and shrinks so that the estimated local
  // error of every unknown stays below tolerance_m + relative_tolerance |z|.
  bool adaptive = false;
  double tolerance_m = 1e-4;
  // AUTO made the steps adaptive because the scene gives no solver.step
  // (convert/; tolerance_m then defaults to 1e-4 of the scene's size).
  bool auto_step = false;
  double relative_tolerance = 0;
  // DYNAMIC: the tolerance every run's error estimate is held to (the
  // summary's error_tolerance_m; engine/run/run_warnings.h): tolerance_m
  // when the scene gives solver.tolerance or steps adaptively, else 1 % of
  // the scene's size (convert/). Held with relative_tolerance as the
  // adaptive controller holds tolerance_m.
  double error_tolerance_m = 1e-4;
  // Run warnings (engine/run/run_warnings.h) fail an otherwise successful
  // run: solver.strict, `cablesim run --strict`, RunRequest.strict.
  bool strict = false;
  // solver.integrator AUTO: `integrator` is HHT until the run chooses
  // (engine/run/auto_integrator.h). auto_keep_implicit: when not empty, a
  // setting that applies to implicit steppers only was given (its field),
  // and AUTO keeps HHT.
  // Code that sets the stepper itself calls Use(), which turns AUTO off
  // (an assignment to `integrator` other than HHT does too: RunPrepared
  // chooses only while `integrator` is still HHT).
  bool auto_integrator = false;
  std::string auto_keep_implicit;
  void Use(Integrator chosen) {
    integrator = chosen;
    auto_integrator = false;
  }
  // AUTO with fixed steps, when nothing in the scene rules the explicit
  // steppers out: the run changes between CENTRAL_DIFFERENCE and HHT as
  // the scene stiffens and softens (set by ChooseIntegrator).
  bool auto_may_switch = false;
  // Adds an estimate of the run's largest probe-position error to the
  // summary, from a companion run (RunScene).
  bool error_estimate = false;
  // Newton economy: keep the factorized Newton matrix across iterations and
  // steps while Newton contracts fast enough (a fresh one otherwise).
  // GENERALIZED_ALPHA, HHT, ENERGY_MOMENTUM (convert/ defaults it off for
  // ENERGY_MOMENTUM: see README, and for the alpha family on a scene whose
  // tangents move with the state: ReuseCostsNewton).
  bool reuse_factorization = true;
  // Why convert/ turned reuse_factorization off for a scene that did not
  // set it (ReuseCostsNewton's sentence); empty otherwise. AUTO's
  // integrator_reason says it.
  std::string reuse_factorization_off;
  InitialState initial_state = InitialState::kAsGiven;  // DYNAMIC only
};

// What a run writes besides the probes and energies.
// Rainflow cycle counting of chosen frame columns (ASTM E1049-85 5.4.4) and
// their damage-equivalent load (engine/output/run_statistics.h).
struct RainflowSpec {
  // Frame column names (engine/output/frame_columns.h), e.g. "top.fz".
  std::vector<std::string> columns;
  // S-N slope m (> 0) and the reference cycle count N_eq (> 0) of
  // DEL = (sum n_i S_i^m / N_eq)^(1/m).
  double sn_slope = 0;
  double equivalent_cycles = 0;
};

struct OutputSpec {
  // Every cable node's position in every frame (Frame::nodes).
  bool shape = false;
  // Per frame column, minimum, maximum (with their times), mean and standard
  // deviation over the run's frames (RunSummary::statistics).
  bool statistics = false;
  RainflowSpec rainflow;
  // Every joint's reaction in every frame (Frame::reactions); joints to
  // ground are then rows with multipliers instead of removed coordinates.
  bool reactions = false;
  // The axial force of every cable probe (NAME.tension) and, with shape,
  // of every node in every frame (Frame::probe_tensions, node_tensions).
  bool tension = false;
  // Every body's orientation (a unit quaternion and roll, pitch, yaw) and
  // angular velocity in every frame (Frame::body_orientation).
  bool orientation = false;
  // The bending moment at every cable probe in every frame
  // (NAME.bending_moment, Frame::probe_bending_moments).
  bool bending_moment = false;
};

struct Scene {
  std::string name;
  ModelChoice model = ModelChoice::kAuto;
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d::Zero();
  std::vector<CableSpec> cables;
  std::vector<BodySpec> bodies;
  std::vector<JointSpec> joints;
  std::vector<LoadSpec> loads;
  std::vector<ProbeSpec> probes;
  InitialVelocitySpec initial_velocity;
  SolverSettings solver;
  OutputSpec output;
  FluidSpec fluid;
  SeabedSpec seabed;
  std::vector<SheaveSpec> sheaves;
  // Plausibility warnings found when the scene was read (convert/
  // plausibility_warnings.h): a run puts them first in RunSummary::warnings.
  std::vector<std::string> warnings;
};

// Appends a driver joint for every coupled body (BodySpec::coupled) that
// has none yet: FIXED between the body's centre of mass and the ground,
// coupled (its point the host's) and coupled_rotation (its axes the
// host's), named "<body> (coupled)". Scene readers call it once all the
// scene's own joints are in, so the drivers come last.
void AddCoupledBodyDrivers(Scene* scene);

// Why a kept Newton matrix (SolverSettings::reuse_factorization) costs
// this scene Newton iterations rather than saving them, in a sentence;
// empty when it does not. A kept matrix pays where the tangent changes
// slowly with the state (pendulums: one factorisation serves several
// steps) and loses where a force's tangent turns with it, since Newton
// then converges linearly on the stale matrix: seabed contact (the
// touchdown point and its damping's moving term, friction) and the
// cables' Morison drag (its tangent follows the relative flow). Measured
// in docs/steppers.md (OC4 three-line mooring: 3.1x the Newton iterations
// and 1.9x the CPU time with a kept matrix).
std::string ReuseCostsNewton(const Scene& scene);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_SCENE_H_
