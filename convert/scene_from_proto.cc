#include "convert/scene_from_proto.h"

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "convert/plausibility_warnings.h"
#include "convert/plausible_ranges.h"
#include "convert/scene/field_checks.h"
#include "convert/scene/sections.h"

// The scene's sections are converted in convert/scene/ (sections.h lists
// them); this file holds the scene-wide settings, the order the sections
// run in, and the enum conversions.

namespace cablesim {
namespace {

using scene_convert::ConversionState;
using scene_convert::Indexed;
using scene_convert::Invalid;
using scene_convert::Sub;
using scene_convert::UnknownEnumValue;

// name, model, gravity and output.
absl::Status ConvertSceneSettings(ConversionState* state) {
  const v1::Scene& proto = state->proto;
  Scene& scene = state->scene;
  CABLESIM_RETURN_IF_ERROR(scene_convert::CheckNameLength("name", proto.name()));
  scene.name = proto.name();
  switch (proto.model()) {
    case v1::Scene::MODEL_UNSPECIFIED:
    case v1::Scene::AUTO:
      scene.model = ModelChoice::kAuto;
      break;
    case v1::Scene::PLANAR:
      scene.model = ModelChoice::kPlanar;
      break;
    case v1::Scene::SPATIAL:
      scene.model = ModelChoice::kSpatial;
      break;
    default:
      return Invalid("model", absl::StrCat("unknown value ", static_cast<int>(proto.model()),
                                           " (expected AUTO, PLANAR or SPATIAL)"));
  }
  CABLESIM_ASSIGN_OR_RETURN(
      scene.gravity_m_s2,
      scene_convert::VectorInRange("gravity", proto.gravity(), plausible::kGravity));
  scene.output.shape = proto.output().shape();
  scene.output.statistics = proto.output().statistics();
  scene.output.reactions = proto.output().reactions();
  scene.output.tension = proto.output().tension();
  scene.output.bending_moment = proto.output().bending_moment();
  scene.output.orientation = proto.output().orientation();
  const v1::Rainflow& r = proto.output().rainflow();
  scene.output.rainflow.columns.assign(r.columns().begin(), r.columns().end());
  scene.output.rainflow.sn_slope = r.sn_slope();
  scene.output.rainflow.equivalent_cycles = r.equivalent_cycles();
  return absl::OkStatus();
}

absl::Status ConvertInitialVelocity(ConversionState* state) {
  const v1::InitialVelocity& v = state->proto.initial_velocity();
  InitialVelocitySpec& spec = state->scene.initial_velocity;
  CABLESIM_ASSIGN_OR_RETURN(
      spec.linear_m_s,
      scene_convert::VectorInRange("initial_velocity.linear", v.linear(), plausible::kVelocity));
  CABLESIM_ASSIGN_OR_RETURN(spec.angular_rad_s,
                            scene_convert::VectorInRange("initial_velocity.angular", v.angular(),
                                                         plausible::kAngularVelocity));
  CABLESIM_ASSIGN_OR_RETURN(
      spec.origin_m,
      scene_convert::VectorInRange("initial_velocity.origin", v.origin(), plausible::kCoordinate));
  return absl::OkStatus();
}

// A coupled body is held by its host: no joint of the scene holds it to
// the ground, and a sliding joint on it (a force the host would not be
// told of) is refused.
absl::Status CheckCoupledBodies(const Scene& scene) {
  for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i) {
    if (!scene.bodies[i].coupled) continue;
    for (int j = 0; j < static_cast<int>(scene.joints.size()); ++j) {
      const JointSpec& joint = scene.joints[j];
      if (joint.a.body != i && joint.b.body != i) continue;
      const std::string path = Sub(Indexed("", "bodies", i), "coupled");
      if (joint.a.IsGround() || joint.b.IsGround()) {
        return Invalid(path, absl::StrCat("the host holds the body: joints[", j,
                                          "] must not join it to the ground"));
      }
      if (joint.type == JointType::kSlide) {
        return Invalid(path, absl::StrCat("joints[", j,
                                          "]: a SLIDE joint on a coupled body is not supported"));
      }
    }
  }
  return absl::OkStatus();
}

// Validates a scene and builds the engine's scene from it, stopping at the
// first invalid field. The order of the sections is the order in which
// fields are checked (and a later section reads the earlier ones).
absl::StatusOr<Scene> ConvertScene(const v1::Scene& proto) {
  ConversionState state(proto);
  CABLESIM_RETURN_IF_ERROR(ConvertSceneSettings(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertCables(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertBodies(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertJoints(&state));
  CABLESIM_RETURN_IF_ERROR(CheckCoupledBodies(state.scene));
  AddCoupledBodyDrivers(&state.scene);
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertLoads(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertProbes(&state));
  CABLESIM_RETURN_IF_ERROR(ConvertInitialVelocity(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertFluid(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertSeabed(&state));
  const Scene& scene = state.scene;
  for (int i = 0; i < static_cast<int>(scene.cables.size()); ++i) {
    if (scene.seabed.enabled) break;
    if (scene.cables[i].seabed_stiffness_n_m2 >= 0)
      return Invalid(Sub(Indexed("", "cables", i), "seabed_stiffness"), "needs a seabed");
    if (scene.cables[i].seabed_damping_n_s_m2 >= 0)
      return Invalid(Sub(Indexed("", "cables", i), "seabed_damping"), "needs a seabed");
  }
  for (int i = 0; i < static_cast<int>(scene.bodies.size()); ++i)
    if (!scene.bodies[i].contact_points_m.empty() && !scene.seabed.enabled)
      return Invalid(Sub(Indexed("", "bodies", i), "seabed_contact"), "needs a seabed");
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertSheaves(&state));
  CABLESIM_RETURN_IF_ERROR(scene_convert::ConvertSolver(&state));
  return std::move(state.scene);
}

}  // namespace

absl::StatusOr<Scene> SceneFromProto(const v1::Scene& proto) {
  absl::StatusOr<Scene> scene = ConvertScene(proto);
  if (scene.ok()) scene->warnings = PlausibilityWarnings(proto, *scene);
  return scene;
}

absl::StatusOr<BendingModel> BendingFromProto(v1::Bending bending, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (bending) {
    case v1::BENDING_UNSPECIFIED:
    case v1::EXACT:
      return BendingModel::kExact;
    case v1::LINEAR:
      return BendingModel::kLinear;
    case v1::Solver::NONE:
      return BendingModel::kNone;
    default:
      return UnknownEnumValue(path, bending, "EXACT, LINEAR or NONE");
  }
}

absl::StatusOr<JointType> JointTypeFromProto(v1::JointType type, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (type) {
    case v1::PIN:
      return JointType::kPin;
    case v1::FIXED:
      return JointType::kFixed;
    case v1::SLIDE:
      return JointType::kSlide;
    default:
      return Invalid(path, "must be PIN, FIXED or SLIDE");
  }
}

absl::StatusOr<Analysis> AnalysisFromProto(v1::Analysis analysis, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (analysis) {
    case v1::ANALYSIS_UNSPECIFIED:
    case v1::DYNAMIC:
      return Analysis::kDynamic;
    case v1::STATIC:
      return Analysis::kStatic;
    case v1::MODAL:
      return Analysis::kModal;
    default:
      return UnknownEnumValue(path, analysis, "DYNAMIC, STATIC or MODAL");
  }
}

absl::StatusOr<Integrator> IntegratorFromProto(v1::Integrator integrator,
                                               std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (integrator) {
    case v1::IMPLICIT_EULER:
      return Integrator::kImplicitEuler;
    case v1::GENERALIZED_ALPHA:
      return Integrator::kGeneralizedAlpha;
    case v1::INTEGRATOR_UNSPECIFIED:
    case v1::HHT:
      return Integrator::kHht;
    case v1::AUTO_STEPPER:  // HHT until the run chooses (SolverSettings::auto_integrator)
      return Integrator::kHht;
    case v1::ENERGY_MOMENTUM:
      return Integrator::kEnergyMomentum;
    case v1::DORMAND_PRINCE:
      return Integrator::kDormandPrince;
    case v1::CENTRAL_DIFFERENCE:
      return Integrator::kCentralDifference;
    default:
      return UnknownEnumValue(path, integrator,
                              "IMPLICIT_EULER, GENERALIZED_ALPHA, HHT, ENERGY_MOMENTUM, "
                              "DORMAND_PRINCE, CENTRAL_DIFFERENCE or AUTO_STEPPER");
  }
}

absl::StatusOr<LinearSolverKind> LinearSolverFromProto(v1::LinearSolver solver,
                                                       std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (solver) {
    case v1::MINRES:
      return LinearSolverKind::kMinres;
    case v1::GMRES:
      return LinearSolverKind::kGmres;
    case v1::DIRECT:
      return LinearSolverKind::kDirect;
    case v1::LINEAR_SOLVER_UNSPECIFIED:
    case v1::AUTO:
      return LinearSolverKind::kAuto;
    default:
      return UnknownEnumValue(path, solver, "MINRES, GMRES, DIRECT or AUTO");
  }
}

}  // namespace cablesim
