// Scene validation and conversion: invalid scenes are rejected with the
// offending field's path; valid ones convert with the documented defaults.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <numbers>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>
#include <unistd.h>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/scene/scene.h"
#include "engine/scene/integrator_traits.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kPi = std::numbers::pi;

absl::StatusOr<Scene> ConvertJson(const std::string& json) {
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  return SceneFromProto(*proto);
}

// Parses, converts and builds the model, as `cablesim validate` does: some
// rules (PLANAR on a scene that leaves the plane, a spatial body's inertia)
// need the model the scene gets.
absl::StatusOr<Scene> ValidateJson(const std::string& json) {
  absl::StatusOr<Scene> scene = ConvertJson(json);
  if (!scene.ok()) return scene.status();
  if (absl::StatusOr<ModelInfo> info = DescribeModel(*scene); !info.ok()) return info.status();
  return scene;
}

// A valid cable "c" of length 1.
constexpr char kCable[] =
    R"({"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01})";
// A valid solver section.
constexpr char kSolver[] = R"("solver": {"duration": 1, "step": 0.01})";

std::string Scene1(const std::string& extra) {
  return absl::StrCat("{\"cables\": [", kCable, "], ", extra, kSolver, "}");
}

// The cable "c" of length 1 with `fields` among its own, and `solver`.
std::string OneCable(const std::string& fields,
                     const std::string& solver = R"("solver": {"duration": 1})") {
  return absl::StrCat(R"({"cables": [{"name": "c", "length": 1, )", fields,
                      R"(, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}], )", solver,
                      "}");
}

struct InvalidCase {
  const char* name;
  std::string json;
  // The error message must start with this (the field path and ": ").
  const char* prefix;
  // And contain this.
  const char* detail;
};

std::vector<InvalidCase> InvalidCases() {
  return {
      {"NegativeLength",
       R"({"cables": [{"name": "c", "length": -1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].length: ", "must be > 0"},
      {"NanLength",
       R"({"cables": [{"name": "c", "length": "NaN", "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].length: ", "must be finite"},
      {"InfiniteGravity",
       R"({"gravity": {"y": "-Infinity"}, "cables": [)" + std::string(kCable) + "], " + kSolver +
           "}",
       "gravity.y: ", "must be finite"},
      {"MissingLength",
       R"({"cables": [{"name": "c", "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
           "solver": {"duration": 1}})",
       "cables[0].length: ", "required"},
      {"NegativeElements",
       R"({"cables": [{"name": "c", "length": 1, "elements": -3, "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].elements: ", "must be in [1, 100000]"},
      {"ZeroElements",
       R"({"cables": [{"name": "c", "length": 1, "elements": 0, "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].elements: ", "must be in [1, 100000]"},
      {"GaussPointsTwo", OneCable(R"("gauss_points": 2)"), "cables[0].gauss_points: ",
       "must be in [3, 8]"},
      {"GaussPointsFour", OneCable(R"("gauss_points": 4)"), "cables[0].gauss_points: ",
       "4 is refused: with 4 points a slack line"},
      {"GaussPointsNine", OneCable(R"("gauss_points": 9)"), "cables[0].gauss_points: ",
       "must be in [3, 8]"},
      {"GaussPointsWithWinch",
       OneCable(R"("gauss_points": 3, "winch": {"speed": {"constant": 0.1}})", kSolver),
       "cables[0].gauss_points: ", "a cable with a winch keeps the default 5"},
      {"ZeroStep",
       absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {"duration": 1, "step": 0}})"),
       "solver.step: ", "must be > 0"},
      {"ZeroLoadStepsStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "load_steps": 0}})"),
       "solver.load_steps: ", "must be in [1, 100000]"},
      {"TooManyElements",
       R"({"cables": [{"name": "c", "length": 1, "elements": 100001, "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].elements: ", "must be in [1, 100000]"},
      {"MissingDensity",
       R"({"cables": [{"name": "c", "length": 1, "youngs_modulus": 1e7, "diameter": 0.01}],
           "solver": {"duration": 1}})",
       "cables[0].density: ", "must be > 0"},
      {"NegativeYoungsModulus",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": -1e7,
                       "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].youngs_modulus: ", "must be > 0"},
      {"MissingArea",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "second_moment": 1e-9}], "solver": {"duration": 1}})",
       "cables[0].area: ", "required (give area or diameter)"},
      {"MissingSecondMomentExactBending",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "area": 1e-4, "bending": "EXACT"}], "solver": {"duration": 1}})",
       "cables[0].second_moment: ", "required unless bending is NONE"},
      {"ZeroDiameter",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0}], "solver": {"duration": 1}})",
       "cables[0].diameter: ", "must be > 0"},
      {"UnknownBendingValue",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01, "bending": 7}], "solver": {"duration": 1}})",
       "cables[0].bending: ", "unknown value 7"},
      {"EmptyCableName",
       R"({"cables": [{"length": 1, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
           "solver": {"duration": 1}})",
       "cables[0].name: ", "required"},
      {"DuplicateCableName",
       absl::StrCat(R"({"cables": [)", kCable, ", ", kCable, "], ", kSolver, "}"),
       "cables[1].name: ", "duplicate name \"c\" (also cables[0])"},
      {"ZeroDirection",
       R"({"cables": [{"name": "c", "length": 1, "direction": {"x": 0}, "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].direction: ", "must be non-zero"},
      {"PolylineWithOnePoint",
       R"({"cables": [{"name": "c", "points": [{"x": 1}], "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].points: ", "at least 2 points"},
      {"PolylineRepeatedPoint",
       R"({"cables": [{"name": "c", "points": [{"x": 0}, {"x": 1}, {"x": 1}], "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].points[2]: ", "same as points[1]"},
      {"PolylineAndStart",
       R"({"cables": [{"name": "c", "start": {"x": 1}, "points": [{"x": 0}, {"x": 1}],
                       "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
           "solver": {"duration": 1}})",
       "cables[0].start: ", "either"},
      {"NoCableOrBody", R"({"solver": {"duration": 1}})", "cables: ", "at least one"},
      {"DuplicateBodyName", Scene1(R"("bodies": [{"name": "b", "mass": 1, "inertia": {"z": 1}},
                            {"name": "b", "mass": 1, "inertia": {"z": 1}}], )"),
       "bodies[1].name: ", "duplicate name"},
      {"BodyCylinderAndMass",
       Scene1(R"("bodies": [{"name": "b", "cylinder": {"diameter": 0.04, "height": 0.1},
                             "density": 1000, "mass": 2}], )"),
       "bodies[0].mass: ", "not both"},
      {"BodyZeroCylinderDiameter",
       Scene1(R"("bodies": [{"name": "b", "cylinder": {"height": 0.1}, "density": 1000}], )"),
       "bodies[0].cylinder.diameter: ", "must be > 0"},
      {"BodyCylinderWithoutDensity",
       Scene1(R"("bodies": [{"name": "b", "cylinder": {"diameter": 0.04, "height": 0.1}}], )"),
       "bodies[0].density: ", "required with cylinder"},
      {"BodyMassWithoutInertia", Scene1(R"("bodies": [{"name": "b", "mass": 2}], )"),
       "bodies[0].inertia.z: ", "must be > 0"},
      {"BodyNegativeInertiaX",
       Scene1(R"("bodies": [{"name": "b", "mass": 2, "inertia": {"x": -1, "z": 1}}], )"),
       "bodies[0].inertia.x: ", "must be >= 0"},
      {"BodyWithoutMass", Scene1(R"("bodies": [{"name": "b"}], )"), "bodies[0].mass: ", "required"},
      {"BodyZeroAxis",
       Scene1(R"("bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}, "axis": {"x": 0}}], )"),
       "bodies[0].axis: ", "must be non-zero"},
      {"UnknownCableInJoint", Scene1(R"("joints": [{"type": "PIN", "a": {"cable": "bem"}}], )"),
       "joints[0].a.cable: ", "no cable named \"bem\""},
      {"UnknownBodyInJoint",
       Scene1(R"("joints": [{"type": "PIN", "a": {"cable": "c"}, "b": {"body": "x"}}], )"),
       "joints[0].b.body: ", "no body named \"x\""},
      {"JointSOutOfRange",
       Scene1(R"("joints": [{"type": "PIN", "a": {"cable": "c", "s": 1.5}}], )"),
       "joints[0].a.s: ", "must be in [0, 1]"},
      {"JointNegativeS", Scene1(R"("joints": [{"type": "PIN", "a": {"cable": "c", "s": -0.1}}], )"),
       "joints[0].a.s: ", "must be in [0, 1]"},
      {"JointTypeMissing", Scene1(R"("joints": [{"a": {"cable": "c"}}], )"),
       "joints[0].type: ", "must be PIN, FIXED or SLIDE"},
      {"JointSideAGround", Scene1(R"("joints": [{"type": "PIN", "b": {"cable": "c"}}], )"),
       "joints[0].a: ", "must name a cable or a body"},
      {"JointSideCableAndBody", Scene1(R"("bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}}],
                 "joints": [{"type": "PIN", "a": {"cable": "c", "body": "b"}}], )"),
       "joints[0].a: ", "names both a cable and a body"},
      {"JointSamePlace", Scene1(R"("joints": [{"type": "FIXED", "a": {"cable": "c", "s": 0.5},
                             "b": {"cable": "c", "s": 0.5}}], )"),
       "joints[0].b: ", "same place as side a"},
      {"JointBodyToItself", Scene1(R"("bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}}],
                 "joints": [{"type": "PIN", "a": {"body": "b"},
                             "b": {"body": "b", "point": {"x": 1}}}], )"),
       "joints[0].b: ", "to itself"},
      {"PlanarJointBodyPointZ",
       Scene1(R"("model": "PLANAR", "bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}}],
                 "joints": [{"type": "PIN", "a": {"cable": "c", "s": 1},
                             "b": {"body": "b", "point": {"z": 0.1}}}], )"),
       "model: ", "PLANAR, but joints[0].b.point.z leaves the x-y plane"},
      {"TorqueOnCableLoad",
       Scene1(R"("loads": [{"at": {"cable": "c", "s": 1}, "torque": {"z": 1}}], )"),
       "loads[0].torque: ", "allowed on bodies only"},
      {"LoadOnGround", Scene1(R"("loads": [{"force": {"y": 1}}], )"),
       "loads[0].at: ", "must name a cable or a body"},
      {"PlanarLoadForceZ",
       Scene1(R"("model": "PLANAR", "loads": [{"at": {"cable": "c", "s": 1}, "force": {"z": 1}}], )"),
       "model: ", "loads[0].force.z leaves the x-y plane"},
      {"PlanarBodyTorqueX",
       Scene1(R"("model": "PLANAR", "bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}}],
                 "loads": [{"at": {"body": "b"}, "torque": {"x": 1}}], )"),
       "model: ", "loads[0].torque.x leaves the x-y plane"},
      {"PlanarGravityZ",
       R"({"model": "PLANAR", "gravity": {"z": -9.81}, "cables": [)" + std::string(kCable) +
           "], " + kSolver + "}",
       "model: ", "gravity.z leaves the x-y plane"},
      {"PlanarCableDirectionZ",
       R"({"model": "PLANAR", "cables": [{"name": "c", "length": 1, "direction": {"x": 1, "z": 1},
           "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "model: ", "cables[0] (point 1 has z != 0) leaves the x-y plane"},
      {"PlanarInitialAngularVelocityY",
       Scene1(R"("model": "PLANAR", "initial_velocity": {"angular": {"y": 4}}, )"),
       "model: ", "initial_velocity.angular.y leaves the x-y plane"},
      {"PlanarInitialLinearVelocityZ",
       Scene1(R"("model": "PLANAR", "initial_velocity": {"linear": {"z": 4}}, )"),
       "model: ", "initial_velocity.linear.z leaves the x-y plane"},
      {"SpatialBodyInertiaNotTriangle",
       Scene1(R"("model": "SPATIAL", "bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1}}], )"),
       "bodies[0].inertia: ", "less than the sum of the other two"},
      {"SpatialBodyInertiaFromPlanarHabit",
       Scene1(R"("gravity": {"z": -9.81}, "bodies": [{"name": "b", "mass": 2,
                 "inertia": {"x": 1, "y": 1, "z": 3}}], )"),
       "bodies[0].inertia: ", "(1, 1, 3) kg m^2"},
      {"BadProbeName", Scene1(R"("probes": [{"name": "tip 1", "cable": "c", "s": 1}], )"),
       "probes[0].name: ", "may contain only"},
      {"EmptyProbeName", Scene1(R"("probes": [{"cable": "c", "s": 1}], )"),
       "probes[0].name: ", "required"},
      {"DuplicateProbeName", Scene1(R"("probes": [{"name": "tip", "cable": "c", "s": 1},
                            {"name": "tip", "cable": "c", "s": 0.5}], )"),
       "probes[1].name: ", "duplicate name \"tip\" (also probes[0])"},
      {"ProbeOnNothing", Scene1(R"("probes": [{"name": "p"}], )"),
       "probes[0]: ", "must name a cable or a body"},
      {"ProbeSOutOfRange", Scene1(R"("probes": [{"name": "p", "cable": "c", "s": 2}], )"),
       "probes[0].s: ", "must be in [0, 1]"},
      {"NegativeStep",
       absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {"duration": 1, "step": -0.01}})"),
       "solver.step: ", "must be > 0"},
      {"StepLongerThanDuration",
       absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {"duration": 1, "step": 2}})"),
       "solver.step: ", "must be <= solver.duration"},
      {"ZeroDurationDynamic",
       absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {"analysis": "DYNAMIC"}})"),
       "solver.duration: ", "must be > 0"},
      {"TooManyFrames",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1e8, "step": 1, "output_interval": 1}})"),
       "solver.output_interval: ", "too many frames"},
      {"NegativeLoadStepsStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "load_steps": -1}})"),
       "solver.load_steps: ", "must be in [1, 100000]"},
      {"NewtonToleranceTooLarge",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "newton_tolerance": 0.1}})"),
       "solver.newton_tolerance: ", "must be in (0, 0.01]"},
      {"ZeroLinearTolerance",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "linear_tolerance": 0}})"),
       "solver.linear_tolerance: ", "must be in (0, 0.01]"},
      {"TooManyNewtonIterations",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "max_newton_iterations": 1001}})"),
       "solver.max_newton_iterations: ", "must be in [1, 1000]"},
      {"TooManyStepHalvings",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "max_step_halvings": 41}})"),
       "solver.max_step_halvings: ", "must be in [0, 40]"},
      {"NegativeMaxLinearIterations",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "max_linear_iterations": -5}})"),
       "solver.max_linear_iterations: ", "must be in [1, 100000]"},
      {"RhoInfinityAboveOne",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "integrator": "GENERALIZED_ALPHA",
                                     "rho_infinity": 1.5}})"),
       "solver.rho_infinity: ", "must be in [0, 1] for GENERALIZED_ALPHA"},
      {"RhoInfinityNegativeDefaultIntegrator",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "rho_infinity": -0.1}})"),
       "solver.rho_infinity: ", "must be in [0.5, 1] for HHT"},
      {"RhoInfinityBelowHhtRange",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "integrator": "HHT", "rho_infinity": 0.3}})"),
       "solver.rho_infinity: ", "must be in [0.5, 1] for HHT"},
      {"RhoInfinityWithBackwardEuler",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "integrator": "IMPLICIT_EULER",
                                     "rho_infinity": 0.5}})"),
       "solver.rho_infinity: ", "GENERALIZED_ALPHA and HHT only"},
      {"ReuseWithBackwardEuler",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "integrator": "IMPLICIT_EULER",
                                     "reuse_factorization": true}})"),
       "solver.reuse_factorization: ", "GENERALIZED_ALPHA, HHT and ENERGY_MOMENTUM only"},
      // solver.tolerance holds every DYNAMIC run's error estimate (adaptive
      // or not: docs/honest-runs.md), and no STATIC or MODAL one.
      {"ToleranceOnStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "tolerance": 1e-4}})"),
       "solver.tolerance: ", "applies to DYNAMIC analysis only (solver.analysis is STATIC)"},
      {"RelativeToleranceOnModal",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "MODAL", "relative_tolerance": 1e-3}})"),
       "solver.relative_tolerance: ", "applies to DYNAMIC analysis only (solver.analysis is MODAL)"},
      // Settings that would do nothing in the run (convert/solver_applicability.h).
      {"PreconditionerOnStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "preconditioner": "JACOBI"}})"),
       "solver.preconditioner: ", "the static solve always uses BLOCK"},
      {"AcceptInexactSolvesOnModal",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "MODAL", "accept_inexact_solves": true}})"),
       "solver.accept_inexact_solves: ", "the static solve never accepts an inexact solve"},
      {"LoadStepsOnDynamicAsGiven",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "load_steps": 5}})"),
       "solver.load_steps: ", "applies to STATIC and MODAL analysis and to solver.initial_state STATIC"},
      {"ZeroTolerance",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "adaptive": true, "tolerance": 0}})"),
       "solver.tolerance: ", "must be > 0"},
      {"NanTolerance",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "adaptive": true, "tolerance": "NaN"}})"),
       "solver.tolerance: ", "must be finite"},
      {"RelativeToleranceOne",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "adaptive": true,
                                     "relative_tolerance": 1}})"),
       "solver.relative_tolerance: ", "must be < 1"},
      {"NegativeRelativeTolerance",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "adaptive": true,
                                     "relative_tolerance": -1e-3}})"),
       "solver.relative_tolerance: ", "must be >= 0"},
      {"AdaptiveStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "adaptive": true}})"),
       "solver.adaptive: ", "DYNAMIC analysis only"},
      {"ErrorEstimateStatic",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "error_estimate": true}})"),
       "solver.error_estimate: ", "DYNAMIC analysis only"},
      {"UnknownIntegrator",
       absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {"duration": 1, "integrator": 9}})"),
       "solver.integrator: ",
       "IMPLICIT_EULER, GENERALIZED_ALPHA, HHT, ENERGY_MOMENTUM, DORMAND_PRINCE, "
       "CENTRAL_DIFFERENCE or AUTO_STEPPER"},
      {"UnknownLinearSolver",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "linear_solver": 9}})"),
       "solver.linear_solver: ", "MINRES, GMRES, DIRECT or AUTO"},
      // Physical plausibility: finite but absurd values are refused before
      // the engine starts, naming the field and the range.
      {"HugeDensity",
       R"({"cables": [{"name": "c", "length": 1, "density": 1e308, "youngs_modulus": 1e7,
                       "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].density: ", "must be in [1e-6, 1e6] kg/m^3 (got 1e308)"},
      {"StartFarAway",
       R"({"cables": [{"name": "c", "length": 1, "start": {"y": 1e20}, "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].start.y: ", "must be in [-1e6, 1e6] m (got 1e20)"},
      {"DenormalStep",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1, "step": 1e-310, "output_interval": 1}})"),
       "solver.step: ", "must be in [1e-9, 1e4] s"},
      {"TooManySteps",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"duration": 1e6, "step": 1e-6, "output_interval": 1}})"),
       "solver.step: ", "steps (at most 1e10)"},
      {"HugeDirection",
       R"({"cables": [{"name": "c", "length": 1, "direction": {"x": 1e308, "y": 1e308},
                       "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01}],
           "solver": {"duration": 1}})",
       "cables[0].direction: ", "norm overflows"},
      {"HugeBodyAxis",
       Scene1(R"("bodies": [{"name": "b", "mass": 2, "inertia": {"z": 1},
                             "axis": {"x": -1e308, "y": 1e308}}], )"),
       "bodies[0].axis: ", "norm overflows"},
      {"PolylinePointsHuge",
       R"({"cables": [{"name": "c", "points": [{"x": -1e308}, {"x": 1e308}], "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].points[0].x: ", "must be in [-1e6, 1e6] m (got -1e308)"},
      {"PolylineFoldsBack",
       R"({"cables": [{"name": "c", "points": [{"x": 0}, {"x": 1}, {"x": 0.5}], "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].points[1]: ", "folds back at this corner (turns by 180.0 degrees"},
      {"PolylineLongerThanRange",
       R"({"cables": [{"name": "c", "points": [{"x": -1e6}, {"x": 1e6}], "density": 1000,
                       "youngs_modulus": 1e7, "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].points: ", "polyline length must be in [1e-6, 1e5] m (got 2e6)"},
      {"TinyModulus",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e-3,
                       "diameter": 0.01}], "solver": {"duration": 1}})",
       "cables[0].youngs_modulus: ", "must be in [1, 1e13] Pa"},
      {"HugeDiameter",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 1e200}], "solver": {"duration": 1}})",
       "cables[0].diameter: ", "must be in [1e-6, 1000] m"},
      {"HugeSecondMoment",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "area": 1e-4, "second_moment": 1e300}], "solver": {"duration": 1}})",
       "cables[0].second_moment: ", "must be in [1e-30, 1e12] m^4"},
      {"HugeBodyMass",
       Scene1(R"("bodies": [{"name": "b", "mass": 1e30, "inertia": {"z": 1}}], )"),
       "bodies[0].mass: ", "must be in [1e-9, 1e9] kg"},
      {"HugeForce",
       Scene1(R"("loads": [{"at": {"cable": "c", "s": 1}, "force": {"y": -1e300}}], )"),
       "loads[0].force.y: ", "must be in [-1e12, 1e12] N"},
      {"HugeInitialVelocity",
       Scene1(R"("initial_velocity": {"linear": {"x": 3e8}}, )"),
       "initial_velocity.linear.x: ", "must be in [-1e5, 1e5] m/s"},
      {"HugeGravity",
       R"({"gravity": {"y": -1e100}, "cables": [)" + std::string(kCable) + "], " + kSolver + "}",
       "gravity.y: ", "must be in [-1e6, 1e6] m/s^2"},
      {"HugeDuration",
       absl::StrCat(R"({"cables": [)", kCable,
                    R"(], "solver": {"analysis": "STATIC", "duration": 1e300}})"),
       "solver.duration: ", "must be in [0, 1e9] s"},
      {"SeabedWithoutStiffness",
       Scene1(R"("gravity": {"y": -9.81}, "seabed": {"depth": 1}, )"),
       "seabed.stiffness: ", "must be > 0"},
      {"SeabedNegativeDamping",
       Scene1(R"("gravity": {"y": -9.81}, "seabed": {"stiffness": 1e5, "damping": -1}, )"),
       "seabed.damping: ", "must be >= 0"},
      {"SeabedNegativeFriction",
       Scene1(R"("gravity": {"y": -9.81},
                 "seabed": {"stiffness": 1e5, "friction_transverse": -0.5}, )"),
       "seabed.friction_transverse: ", "must be >= 0"},
      {"SeabedNegativeFrictionSpeed",
       Scene1(R"("gravity": {"y": -9.81}, "seabed": {"stiffness": 1e5, "friction_speed": -1}, )"),
       "seabed.friction_speed: ", "must be > 0"},
      // The review's hostile values (issue 30): each passed validation and
      // failed the run at t = 0 with "residual -nan" naming no field.
      {"HarmonicFrequencyHuge",
       Scene1(R"("loads": [{"at": {"cable": "c", "s": 1}, "varying_force": {"y": {"constant": 0,
                 "harmonic": {"amplitude": 1, "frequency": 1e300}}}}], )"),
       "loads[0].varying_force.y.harmonic.frequency: ", "must be in [0, "},
      {"RampSlopeHuge",
       Scene1(R"("loads": [{"at": {"cable": "c", "s": 1}, "varying_force": {"x": {"constant": 0,
                 "ramp": {"slope": 1e300}}}}], )"),
       "loads[0].varying_force.x.ramp.slope: ", "must be in ["},
      {"WinchSpeedHuge",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01, "winch": {"speed": {"constant": 1e308}}}],
           "solver": {"duration": 1, "step": 0.01}})",
       "cables[0].winch.speed.constant: ", "must be in [-1e5, 1e5] m/s"},
      {"NormalDragHuge",
       R"({"fluid": {"density": 1025}, "gravity": {"y": -9.81},
           "cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01, "hydrodynamics": {"normal_drag": 1e308}}],
           "solver": {"duration": 1, "step": 0.01}})",
       "cables[0].hydrodynamics.normal_drag: ", "must be in [0, 1000]"},
      {"CableDampingTimeHuge",
       R"({"cables": [{"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7,
                       "diameter": 0.01, "damping": {"axial_time": 1e300}}],
           "solver": {"duration": 1, "step": 0.01}})",
       "cables[0].damping.axial_time: ", "must be in [0, 1e4] s"},
      {"SeabedStiffnessHuge",
       Scene1(R"("gravity": {"y": -9.81}, "seabed": {"stiffness": 1e300}, )"),
       "seabed.stiffness: ", "must be in ["},
      {"SeabedFrictionHuge",
       Scene1(R"("gravity": {"y": -9.81}, "seabed": {"stiffness": 1e5, "friction_axial": 1e300}, )"),
       "seabed.friction_axial: ", "must be in [0, 1000]"},
      {"WavePeriodTiny",
       Scene1(R"("gravity": {"y": -9.81}, "fluid": {"density": 1025, "water_depth": 50,
                 "waves": {"regular": [{"height": 1, "period": 1e-6}]}}, )"),
       "fluid.waves.regular[0].period: ", "must be in [0.01, 1e4] s"},
      {"TableValueHuge",
       Scene1(R"("loads": [{"at": {"cable": "c", "s": 1}, "varying_force": {"z": {"constant": 0,
                 "table": {"times": [0, 1], "values": [0, 1e300]}}}}], )"),
       "loads[0].varying_force.z.table.values[1]: ", "must be in ["},
      {"SeabedWithoutNormalOrGravity",
       Scene1(R"("seabed": {"stiffness": 1e5}, )"),
       "seabed.normal: ", "must be given when gravity is zero"},
      {"SeabedZeroNormal",
       Scene1(R"("seabed": {"stiffness": 1e5, "normal": {"x": 0}}, )"),
       "seabed.normal: ", "must be non-zero"},
  };
}

class InvalidSceneTest : public ::testing::TestWithParam<InvalidCase> {};

TEST_P(InvalidSceneTest, NamesTheField) {
  const InvalidCase& c = GetParam();
  const absl::StatusOr<Scene> scene = ValidateJson(c.json);
  ASSERT_FALSE(scene.ok()) << c.json;
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  const std::string message(scene.status().message());
  EXPECT_THAT(message, StartsWith(c.prefix));
  EXPECT_THAT(message, HasSubstr(c.detail));
}

INSTANTIATE_TEST_SUITE_P(All, InvalidSceneTest, ::testing::ValuesIn(InvalidCases()),
                         [](const ::testing::TestParamInfo<InvalidCase>& info) {
                           return std::string(info.param.name);
                         });

// Every invalid scene above is also a seed of the scene fuzz target's corpus
// (tests/fuzz/corpus/scene/invalid-NAME.json), so the fuzzer starts from
// each rule. CABLESIM_UPDATE_FUZZ_CORPUS=1 (re)writes the files.
TEST(FuzzCorpusTest, HoldsEveryInvalidScene) {
  const std::string dir = std::string(CABLESIM_SOURCE_DIR) + "/tests/fuzz/corpus/scene/";
  const bool update = std::getenv("CABLESIM_UPDATE_FUZZ_CORPUS") != nullptr;
  for (const InvalidCase& c : InvalidCases()) {
    const std::string path = absl::StrCat(dir, "invalid-", c.name, ".json");
    if (update) std::ofstream(path, std::ios::binary) << c.json;
    std::ifstream in(path, std::ios::binary);
    const std::string stored((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(stored, c.json) << path << " is missing or stale";
  }
}

// The ranges are wide enough for unusual but real models: a 10 km Kevlar
// mooring line on a polyline that turns by 90 degrees, a heavy buoy.
TEST(ScenePlausibilityTest, AcceptsAKevlarMooringTenKilometresLong) {
  const absl::StatusOr<Scene> scene = ValidateJson(R"({
    "gravity": {"y": -9.81},
    "cables": [{"name": "tether", "elements": 200,
                "points": [{"x": 0}, {"x": 5000}, {"x": 5000, "y": -5000}],
                "density": 1440, "youngs_modulus": 1.3e11, "diameter": 0.05}],
    "bodies": [{"name": "buoy", "mass": 5e4, "inertia": {"x": 1e5, "y": 1e5, "z": 1e5},
                "position": {"x": 5000, "y": -5000}}],
    "joints": [{"type": "PIN", "a": {"cable": "tether", "s": 0}},
               {"type": "PIN", "a": {"cable": "tether", "s": 10000}, "b": {"body": "buoy"}}],
    "solver": {"duration": 3600, "step": 0.5}})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_DOUBLE_EQ(scene->cables[0].length_m, 10000);
}

TEST(SceneParseTest, UnknownJsonFieldIsNamed) {
  const absl::StatusOr<v1::Scene> scene =
      ParseSceneJson(R"({"cables": [{"name": "c", "lenght": 1}]})");
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("lenght"));
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("cables[0]"));
}

TEST(SceneParseTest, UnknownEnumNameIsNamed) {
  const absl::StatusOr<v1::Scene> scene = ParseSceneJson(R"({"joints": [{"type": "HINGE"}]})");
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("joints[0].type"));
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("HINGE"));
}

TEST(SceneParseTest, MalformedJsonIsOneLine) {
  const absl::StatusOr<v1::Scene> scene = ParseSceneJson("{\"cables\": [");
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(scene.status().message()), ::testing::Not(HasSubstr("\n")));
}

TEST(SceneParseTest, TextFormat) {
  const absl::StatusOr<v1::Scene> scene = ParseSceneTextFormat(R"pb(
    name: "t"
    cables { name: "c" length: 2 density: 1000 youngs_modulus: 1e7 diameter: 0.01 }
    solver { duration: 1 }
  )pb");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->cables(0).length(), 2);
  const absl::StatusOr<v1::Scene> bad = ParseSceneTextFormat("cables { lenght: 1 }");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(bad.status().message()), HasSubstr("lenght"));
}

TEST(SceneFileTest, FormatFromExtension) {
  EXPECT_TRUE(IsTextFormatScenePath("a/b.txtpb"));
  EXPECT_TRUE(IsTextFormatScenePath("b.textproto"));
  EXPECT_TRUE(IsTextFormatScenePath("b.pbtxt"));
  EXPECT_FALSE(IsTextFormatScenePath("b.json"));
  EXPECT_FALSE(IsTextFormatScenePath("scene"));
}

TEST(SceneFileTest, MissingFile) {
  const absl::StatusOr<v1::Scene> scene = ReadSceneFile("/nonexistent/scene.json");
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(scene.status().message()), StartsWith("/nonexistent/scene.json: "));
}

TEST(SceneFileTest, ParseErrorNamesFileAndField) {
  const std::string path = ::testing::TempDir() + "/scene_validation_test_bad_" + std::to_string(::getpid()) + ".json";
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs(R"({"cables": [{"name": "c", "colour": "red"}]})", f);
    std::fclose(f);
  }
  const absl::StatusOr<v1::Scene> scene = ReadSceneFile(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(scene.status().message()), StartsWith(path + ": "));
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("colour"));
  std::remove(path.c_str());
}

std::string SceneFile(const char* name) {
  return absl::StrCat(CABLESIM_SOURCE_DIR, "/scenes/", name);
}

TEST(SampleSceneTest, FallingPendulum) {
  const absl::StatusOr<v1::Scene> proto = ReadSceneFile(SceneFile("falling-pendulum.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  const absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->name, "falling-pendulum");
  EXPECT_EQ(scene->gravity_m_s2, Eigen::Vector3d(0, -9.81, 0));
  ASSERT_EQ(scene->cables.size(), 1);
  const CableSpec& cable = scene->cables[0];
  EXPECT_EQ(cable.name, "beam");
  ASSERT_EQ(cable.points.size(), 2);
  EXPECT_EQ(cable.points[0], Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(cable.points[1], Eigen::Vector3d(1.2, 0, 0));
  EXPECT_EQ(cable.length_m, 1.2);
  EXPECT_EQ(cable.elements, 12);
  EXPECT_EQ(cable.density_kg_m3, 5540);
  EXPECT_EQ(cable.youngs_modulus_pa, 0.7e6);
  EXPECT_EQ(cable.area_m2, 0.0018);
  EXPECT_EQ(cable.second_moment_m4, 1.215e-8);
  EXPECT_EQ(cable.bending, BendingModel::kExact);
  EXPECT_TRUE(scene->bodies.empty());
  ASSERT_EQ(scene->joints.size(), 1);
  EXPECT_EQ(scene->joints[0].type, JointType::kPin);
  EXPECT_EQ(scene->joints[0].a.cable, 0);
  EXPECT_EQ(scene->joints[0].a.s_m, 0);
  EXPECT_TRUE(scene->joints[0].b.IsGround());
  ASSERT_EQ(scene->probes.size(), 1);
  EXPECT_EQ(scene->probes[0].name, "tip");
  EXPECT_EQ(scene->probes[0].at.cable, 0);
  EXPECT_EQ(scene->probes[0].at.s_m, 1.2);
  const SolverSettings& solver = scene->solver;
  EXPECT_EQ(solver.analysis, Analysis::kDynamic);
  EXPECT_EQ(solver.duration_s, 1.0);
  EXPECT_EQ(solver.step_s, 1e-4);
  EXPECT_EQ(solver.output_interval_s, 0.001);
  EXPECT_EQ(solver.integrator, Integrator::kImplicitEuler);
  EXPECT_EQ(solver.linear_solver, LinearSolverKind::kMinres);
  // Defaults.
  EXPECT_EQ(solver.load_steps, 10);
  EXPECT_EQ(solver.newton_tolerance, 1e-8);
  EXPECT_EQ(solver.max_newton_iterations, 25);
  EXPECT_EQ(solver.max_step_halvings, 12);
  EXPECT_EQ(solver.linear_tolerance, 1e-10);
  EXPECT_EQ(solver.max_linear_iterations, 200);
}

TEST(SampleSceneTest, CableWithEndCylinder) {
  const absl::StatusOr<v1::Scene> proto = ReadSceneFile(SceneFile("cable-with-end-cylinder.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  const absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const CableSpec& cable = scene->cables[0];
  EXPECT_EQ(cable.points[0], Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(cable.points[1], Eigen::Vector3d(0.5, 0, 0));
  EXPECT_EQ(cable.elements, 20);
  // MODEL.md Table 1: A = 7.85e-5 m^2, I = 4.91e-10 m^4.
  EXPECT_DOUBLE_EQ(cable.area_m2, kPi * 0.01 * 0.01 / 4);
  EXPECT_NEAR(cable.area_m2, 7.85e-5, 1e-7);
  EXPECT_DOUBLE_EQ(cable.second_moment_m4, kPi * std::pow(0.01, 4) / 64);
  EXPECT_NEAR(cable.second_moment_m4, 4.91e-10, 1e-12);
  EXPECT_EQ(cable.bending, BendingModel::kExact);

  ASSERT_EQ(scene->bodies.size(), 1);
  const BodySpec& body = scene->bodies[0];
  const double m = 1000 * kPi * 0.04 * 0.04 / 4 * 0.1;
  EXPECT_DOUBLE_EQ(body.mass_kg, m);
  EXPECT_DOUBLE_EQ(body.inertia_kg_m2.x(), m * 0.04 * 0.04 / 8);
  EXPECT_DOUBLE_EQ(body.inertia_kg_m2.y(), m * (3 * 0.02 * 0.02 + 0.1 * 0.1) / 12);
  EXPECT_DOUBLE_EQ(body.inertia_kg_m2.z(), m * (3 * 0.02 * 0.02 + 0.1 * 0.1) / 12);
  EXPECT_EQ(body.position_m, Eigen::Vector3d(0.55, 0, 0));
  EXPECT_EQ(body.axis, Eigen::Vector3d(1, 0, 0));

  ASSERT_EQ(scene->joints.size(), 2);
  EXPECT_EQ(scene->joints[0].type, JointType::kPin);
  EXPECT_TRUE(scene->joints[0].b.IsGround());
  const JointSpec& weld = scene->joints[1];
  EXPECT_EQ(weld.type, JointType::kFixed);
  EXPECT_EQ(weld.a.cable, 0);
  EXPECT_EQ(weld.a.s_m, 0.5);
  EXPECT_EQ(weld.b.body, 0);
  EXPECT_EQ(weld.b.cable, -1);
  EXPECT_EQ(weld.b.point_body_m, Eigen::Vector3d(-0.05, 0, 0));
  ASSERT_EQ(scene->probes.size(), 1);
  EXPECT_EQ(scene->probes[0].at.body, 0);
  EXPECT_EQ(scene->probes[0].at.point_body_m, Eigen::Vector3d::Zero());

  EXPECT_EQ(scene->solver.analysis, Analysis::kDynamic);  // from UNSPECIFIED
  EXPECT_EQ(scene->solver.duration_s, 20);
  EXPECT_EQ(scene->solver.step_s, 0.005);
  EXPECT_EQ(scene->solver.output_interval_s, 0.01);
  EXPECT_EQ(scene->solver.integrator, Integrator::kImplicitEuler);
  EXPECT_EQ(scene->solver.linear_solver, LinearSolverKind::kMinres);
}

TEST(SampleSceneTest, CantileverLargeDeflection) {
  const absl::StatusOr<v1::Scene> proto =
      ReadSceneFile(SceneFile("cantilever-large-deflection.json"));
  ASSERT_TRUE(proto.ok()) << proto.status();
  const absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->name, "large-deflection-cantilever");
  EXPECT_EQ(scene->gravity_m_s2, Eigen::Vector3d::Zero());
  EXPECT_EQ(scene->cables[0].points[1], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(scene->cables[0].elements, 16);
  ASSERT_EQ(scene->joints.size(), 1);
  EXPECT_EQ(scene->joints[0].type, JointType::kFixed);
  EXPECT_TRUE(scene->joints[0].b.IsGround());
  ASSERT_EQ(scene->loads.size(), 1);
  EXPECT_EQ(scene->loads[0].at.cable, 0);
  EXPECT_EQ(scene->loads[0].at.s_m, 1.0);
  EXPECT_EQ(scene->loads[0].force_n, Eigen::Vector3d(0, -196.3495, 0));
  EXPECT_EQ(scene->loads[0].torque_nm, Eigen::Vector3d::Zero());
  EXPECT_EQ(scene->probes[0].at.s_m, 1.0);
  EXPECT_EQ(scene->solver.analysis, Analysis::kStatic);
  EXPECT_EQ(scene->solver.load_steps, 20);
  EXPECT_EQ(scene->solver.step_s, 1e-3);             // default
  EXPECT_EQ(scene->solver.output_interval_s, 1e-3);  // default: the step
}

TEST(SceneConversionTest, DefaultsForAMinimalCable) {
  const absl::StatusOr<Scene> scene =
      ConvertJson(R"({"cables": [{"name": "c", "length": 2, "density": 1, "youngs_modulus": 1,
                                  "area": 1e-4, "bending": "NONE"}],
                      "solver": {"duration": 1}})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const CableSpec& cable = scene->cables[0];
  EXPECT_EQ(cable.elements, 10);
  EXPECT_EQ(cable.points[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(cable.points[1], Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(cable.bending, BendingModel::kNone);
  EXPECT_EQ(cable.second_moment_m4, 0);  // not needed without bending
  EXPECT_EQ(scene->solver.step_s, 1e-3);
  EXPECT_EQ(scene->solver.output_interval_s, 1e-3);
}

TEST(SceneConversionTest, StartAndNormalisedDirection) {
  const absl::StatusOr<Scene> scene = ConvertJson(
      R"({"cables": [{"name": "c", "length": 10, "start": {"x": 1, "y": 2},
                      "direction": {"x": 3, "y": -4}, "density": 1, "youngs_modulus": 1,
                      "diameter": 0.01, "bending": "LINEAR"}],
          "solver": {"duration": 1}})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const CableSpec& cable = scene->cables[0];
  EXPECT_EQ(cable.points[0], Eigen::Vector3d(1, 2, 0));
  EXPECT_TRUE(cable.points[1].isApprox(Eigen::Vector3d(7, -6, 0)));
  EXPECT_EQ(cable.bending, BendingModel::kLinear);
}

TEST(SceneConversionTest, PolylineLengthAndExplicitSectionWins) {
  const absl::StatusOr<Scene> scene = ConvertJson(
      R"({"cables": [{"name": "c", "points": [{"x": 0}, {"x": 3}, {"x": 3, "y": 4}],
                      "density": 1, "youngs_modulus": 1, "diameter": 0.01, "area": 2e-4,
                      "second_moment": 3e-9}],
          "probes": [{"name": "end", "cable": "c", "s": 7}],
          "solver": {"duration": 1}})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const CableSpec& cable = scene->cables[0];
  ASSERT_EQ(cable.points.size(), 3);
  EXPECT_EQ(cable.points[2], Eigen::Vector3d(3, 4, 0));
  EXPECT_EQ(cable.length_m, 7);
  EXPECT_EQ(cable.area_m2, 2e-4);
  EXPECT_EQ(cable.second_moment_m4, 3e-9);
}

TEST(SceneConversionTest, ArcLengthAtTheEndToleratesRounding) {
  // 0.1 + 0.2 is slightly above 0.3.
  const absl::StatusOr<Scene> scene = ConvertJson(absl::StrCat(
      R"({"cables": [{"name": "c", "length": 0.3, "density": 1, "youngs_modulus": 1,
                      "diameter": 0.01}],
          "probes": [{"name": "end", "cable": "c", "s": )",
      0.1 + 0.2, R"(}], "solver": {"duration": 1}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->probes[0].at.s_m, 0.3);  // clamped into [0, length]
}

TEST(SceneConversionTest, BodyWithMassAndInertia) {
  const absl::StatusOr<Scene> scene = ConvertJson(
      R"({"bodies": [{"name": "b", "mass": 2, "inertia": {"z": 0.5},
                      "position": {"x": 1, "y": -1}, "axis": {"x": 0, "y": 2}}],
          "loads": [{"at": {"body": "b", "point": {"x": 0.1}}, "force": {"x": 1},
                     "torque": {"z": 3}}],
          "probes": [{"name": "b.com", "body": "b"}],
          "initial_velocity": {"linear": {"x": 1}, "angular": {"z": 2},
                               "origin": {"x": 1, "z": 5}},
          "solver": {"analysis": "STATIC", "linear_solver": "GMRES"}})");
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_TRUE(scene->cables.empty());
  const BodySpec& body = scene->bodies[0];
  EXPECT_EQ(body.mass_kg, 2);
  EXPECT_EQ(body.inertia_kg_m2, Eigen::Vector3d(0, 0, 0.5));
  EXPECT_EQ(body.position_m, Eigen::Vector3d(1, -1, 0));
  EXPECT_EQ(body.axis, Eigen::Vector3d(0, 1, 0));  // normalised
  EXPECT_EQ(scene->loads[0].at.body, 0);
  EXPECT_EQ(scene->loads[0].at.point_body_m, Eigen::Vector3d(0.1, 0, 0));
  EXPECT_EQ(scene->loads[0].torque_nm, Eigen::Vector3d(0, 0, 3));
  EXPECT_EQ(scene->initial_velocity.angular_rad_s, Eigen::Vector3d(0, 0, 2));
  EXPECT_EQ(scene->initial_velocity.origin_m, Eigen::Vector3d(1, 0, 5));
  EXPECT_EQ(scene->solver.analysis, Analysis::kStatic);
  EXPECT_EQ(scene->solver.linear_solver, LinearSolverKind::kGmres);
}

TEST(SceneConversionTest, JointBetweenTwoPointsOfOneCable) {
  const absl::StatusOr<Scene> scene =
      ConvertJson(Scene1(R"("joints": [{"type": "PIN", "a": {"cable": "c", "s": 0},
                                        "b": {"cable": "c", "s": 1}}], )"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->joints[0].b.cable, 0);
  EXPECT_EQ(scene->joints[0].b.s_m, 1);
}

// What every DYNAMIC run's error estimate is held to (docs/honest-runs.md),
// and the settings that apply although they might look as if they did not.
TEST(SceneConversionTest, ErrorToleranceAndSettingsThatApply) {
  // Fixed steps, no tolerance given: 1 % of the longest cable (at least 1 m).
  const char* kLong =
      R"({"name": "long", "length": 20, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01})";
  absl::StatusOr<Scene> scene =
      ConvertJson(absl::StrCat(R"({"cables": [)", kCable, ",", kLong, "], ", kSolver, "}"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_DOUBLE_EQ(scene->solver.error_tolerance_m, 0.2);
  scene = ConvertJson(Scene1(""));  // one 1 m cable: the 1 m floor
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_DOUBLE_EQ(scene->solver.error_tolerance_m, 0.01);
  EXPECT_FALSE(scene->solver.strict);
  // Given: held to it, fixed steps too.
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable,
                                   R"(], "solver": {"duration": 1, "tolerance": 1e-5,
                                      "relative_tolerance": 1e-3, "strict": true}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.error_tolerance_m, 1e-5);
  EXPECT_EQ(scene->solver.relative_tolerance, 1e-3);
  EXPECT_TRUE(scene->solver.strict);
  // Adaptive without a tolerance: the controller's own default.
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable,
                                   R"(], "solver": {"duration": 1, "adaptive": true}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.error_tolerance_m, scene->solver.tolerance_m);
  // load_steps with initial_state STATIC (the load path to equilibrium).
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {
      "duration": 1, "initial_state": "STATIC", "load_steps": 4}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.load_steps, 4);
  // DIRECT uses linear_tolerance (its refinement pass) and falls back to
  // MINRES with max_linear_iterations and the preconditioner.
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {
      "duration": 1, "linear_solver": "DIRECT", "linear_tolerance": 1e-9,
      "max_linear_iterations": 50, "preconditioner": "JACOBI"}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  // A dynamic scene switched to MODAL keeps its time-stepping settings.
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {
      "analysis": "MODAL", "duration": 1, "step": 0.01, "output_interval": 0.1,
      "integrator": "GENERALIZED_ALPHA", "rho_infinity": 0.8}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  // STATIC takes the linear settings its static solve uses.
  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {
      "analysis": "STATIC", "load_steps": 5, "linear_tolerance": 1e-9,
      "max_linear_iterations": 50, "newton_tolerance": 1e-9}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
}

TEST(SceneConversionTest, SteppersAndTheirSettings) {
  // Defaults: HHT (measured as fast as generalized-alpha at a given error
  // and more robust), rho_infinity 0.5, factorization reuse, fixed steps, no error estimate.
  absl::StatusOr<Scene> scene = ConvertJson(Scene1(""));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.integrator, Integrator::kHht);
  EXPECT_EQ(scene->solver.rho_infinity, 0.5);
  EXPECT_TRUE(scene->solver.reuse_factorization);
  EXPECT_FALSE(scene->solver.adaptive);
  EXPECT_FALSE(scene->solver.error_estimate);
  EXPECT_EQ(scene->solver.tolerance_m, 1e-4);
  EXPECT_EQ(scene->solver.relative_tolerance, 0);
  EXPECT_EQ(scene->solver.linear_solver, LinearSolverKind::kAuto);

  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable, R"(], "solver": {
      "duration": 1, "integrator": "HHT", "rho_infinity": 0.5, "linear_solver": "DIRECT",
      "adaptive": true, "tolerance": 1e-6, "relative_tolerance": 1e-3,
      "error_estimate": true, "reuse_factorization": false}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.integrator, Integrator::kHht);
  EXPECT_EQ(scene->solver.rho_infinity, 0.5);
  EXPECT_EQ(scene->solver.linear_solver, LinearSolverKind::kDirect);
  EXPECT_TRUE(scene->solver.adaptive);
  EXPECT_EQ(scene->solver.tolerance_m, 1e-6);
  EXPECT_EQ(scene->solver.relative_tolerance, 1e-3);
  EXPECT_TRUE(scene->solver.error_estimate);
  EXPECT_FALSE(scene->solver.reuse_factorization);

  scene = ConvertJson(absl::StrCat(R"({"cables": [)", kCable,
                                   R"(], "solver": {"duration": 1, "linear_solver": "AUTO",
                                      "integrator": "IMPLICIT_EULER"}})"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(scene->solver.linear_solver, LinearSolverKind::kAuto);
  EXPECT_EQ(scene->solver.integrator, Integrator::kImplicitEuler);
  EXPECT_FALSE(scene->solver.reuse_factorization);  // backward Euler does not reuse
}

// solver.reuse_factorization unset: true for the alpha family, but false on
// a scene with a seabed or with fluid drag on a cable (ReuseCostsNewton),
// with the reason AUTO's integrator_reason gives; a scene that sets it
// keeps what it set; the other steppers keep their own default.
TEST(SceneConversionTest, ReuseFactorizationDefaultFollowsTheScene) {
  const std::string bed = R"("gravity": {"y": -9.81}, "seabed": {"depth": 1, "stiffness": 1e5}, )";
  const auto with = [&](const std::string& cable, const std::string& more,
                        const std::string& solver) {
    return absl::StrCat(R"({"cables": [)", cable, "], ", more, R"("solver": {"duration": 1)",
                        solver, "}}");
  };
  struct Case {
    std::string name, json;
    bool reuse;
    std::string why;  // in reuse_factorization_off; empty: none
  };
  const std::string drag =
      R"({"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01,
          "hydrodynamics": {"normal_drag": 1.2}})";
  const std::string added_mass_only =
      R"({"name": "c", "length": 1, "density": 1000, "youngs_modulus": 1e7, "diameter": 0.01,
          "hydrodynamics": {"added_mass": 1}})";
  const std::string water = R"("fluid": {"density": 1025}, )";
  const Case cases[] = {
      {"plain", with(kCable, "", ""), true, ""},
      {"seabed", with(kCable, bed, ""), false, "seabed contact"},
      {"seabed, AUTO named", with(kCable, bed, R"(, "integrator": "AUTO_STEPPER")"), false,
       "seabed contact"},
      {"seabed, GENERALIZED_ALPHA", with(kCable, bed, R"(, "integrator": "GENERALIZED_ALPHA")"),
       false, "seabed contact"},
      {"seabed, set true", with(kCable, bed, R"(, "reuse_factorization": true)"), true, ""},
      {"seabed, ENERGY_MOMENTUM", with(kCable, bed, R"(, "integrator": "ENERGY_MOMENTUM")"), false,
       ""},
      {"seabed, IMPLICIT_EULER", with(kCable, bed, R"(, "integrator": "IMPLICIT_EULER")"), false,
       ""},
      {"cable drag", with(drag, water, ""), false, "fluid drag"},
      {"cable drag, set true", with(drag, water, R"(, "reuse_factorization": true)"), true, ""},
      {"fluid without drag", with(kCable, water, ""), true, ""},
      {"added mass only", with(added_mass_only, water, ""), true, ""},
  };
  for (const Case& c : cases) {
    absl::StatusOr<Scene> scene = ConvertJson(c.json);
    ASSERT_TRUE(scene.ok()) << c.name << ": " << scene.status();
    EXPECT_EQ(scene->solver.reuse_factorization, c.reuse) << c.name;
    if (c.why.empty()) {
      EXPECT_EQ(scene->solver.reuse_factorization_off, "") << c.name;
    } else {
      EXPECT_THAT(scene->solver.reuse_factorization_off, ::testing::HasSubstr(c.why)) << c.name;
    }
  }
}

TEST(EnumConversionTest, Names) {
  EXPECT_EQ(AnalysisName(Analysis::kStatic), "STATIC");
  EXPECT_EQ(IntegratorName(Integrator::kImplicitEuler), "IMPLICIT_EULER");
  EXPECT_EQ(LinearSolverName(LinearSolverKind::kGmres), "GMRES");
  EXPECT_EQ(IntegratorName(Integrator::kGeneralizedAlpha), "GENERALIZED_ALPHA");
  EXPECT_EQ(IntegratorName(Integrator::kHht), "HHT");
  EXPECT_EQ(LinearSolverName(LinearSolverKind::kDirect), "DIRECT");
  EXPECT_EQ(LinearSolverName(LinearSolverKind::kAuto), "AUTO");
  const absl::StatusOr<JointType> none = JointTypeFromProto(v1::JOINT_TYPE_UNSPECIFIED, "j.type");
  ASSERT_FALSE(none.ok());
  EXPECT_THAT(std::string(none.status().message()), StartsWith("j.type: "));
}

}  // namespace
}  // namespace cablesim
