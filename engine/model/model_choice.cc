#include "engine/model/model_choice.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace cablesim {
namespace {

std::string Z(const std::string& path, const Eigen::Vector3d& v) {
  return v.z() != 0 ? absl::StrCat(path, ".z") : "";
}

std::string NotAboutZ(const std::string& path, const Eigen::Vector3d& v) {
  if (v.x() != 0) return absl::StrCat(path, ".x");
  if (v.y() != 0) return absl::StrCat(path, ".y");
  return "";
}

}  // namespace

std::string OutOfPlaneField(const Scene& scene) {
  if (auto f = Z("gravity", scene.gravity_m_s2); !f.empty()) return f;
  for (size_t i = 0; i < scene.cables.size(); ++i) {
    const auto& points = scene.cables[i].points;
    for (size_t k = 0; k < points.size(); ++k) {
      // The engine keeps the cable as a polyline; name the cable and point.
      if (points[k].z() != 0) return absl::StrCat("cables[", i, "] (point ", k, " has z != 0)");
    }
  }
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    const std::string path = absl::StrCat("bodies[", i, "]");
    if (auto f = Z(path + ".position", scene.bodies[i].position_m); !f.empty()) return f;
    if (auto f = Z(path + ".axis", scene.bodies[i].axis); !f.empty()) return f;
    for (const BodyFluidPart& part : scene.bodies[i].hydro_parts) {
      const std::string part_path =
          part.scene_index < 0 ? path + ".hydrodynamics"
                               : absl::StrCat(path, ".hydrodynamics_parts[", part.scene_index, "]");
      if (auto f = Z(part_path + ".axis", part.axis_body); !f.empty()) return f;
      if (auto f = Z(part_path + ".center", part.center_m); !f.empty()) return f;
    }
  }
  auto attachment = [](const std::string& path, const Attachment& at) -> std::string {
    if (at.body < 0) return "";
    return Z(path + ".point", at.point_body_m);
  };
  for (size_t i = 0; i < scene.joints.size(); ++i) {
    const std::string path = absl::StrCat("joints[", i, "]");
    if (auto f = attachment(path + ".a", scene.joints[i].a); !f.empty()) return f;
    if (auto f = attachment(path + ".b", scene.joints[i].b); !f.empty()) return f;
    if (!scene.joints[i].motion[2].IsZero()) return path + ".motion.z";
    if (scene.joints[i].HasRotation() &&
        scene.joints[i].rotation_axis.head<2>().lpNorm<Eigen::Infinity>() != 0) {
      return path + ".rotation_axis";
    }
  }
  for (size_t i = 0; i < scene.loads.size(); ++i) {
    const std::string path = absl::StrCat("loads[", i, "]");
    if (auto f = attachment(path + ".at", scene.loads[i].at); !f.empty()) return f;
    if (auto f = Z(path + ".force", scene.loads[i].force_n); !f.empty()) return f;
    if (auto f = NotAboutZ(path + ".torque", scene.loads[i].torque_nm); !f.empty()) return f;
    if (!scene.loads[i].varying_force_n[2].IsZero()) return path + ".varying_force.z";
    if (!scene.loads[i].varying_torque_nm[0].IsZero()) return path + ".varying_torque.x";
    if (!scene.loads[i].varying_torque_nm[1].IsZero()) return path + ".varying_torque.y";
  }
  for (size_t i = 0; i < scene.probes.size(); ++i) {
    if (auto f = attachment(absl::StrCat("probes[", i, "]"), scene.probes[i].at); !f.empty())
      return f;
  }
  const InitialVelocitySpec& iv = scene.initial_velocity;
  if (auto f = Z("initial_velocity.linear", iv.linear_m_s); !f.empty()) return f;
  if (auto f = NotAboutZ("initial_velocity.angular", iv.angular_rad_s); !f.empty()) return f;
  if (auto f = Z("fluid.current", scene.fluid.current_m_s); !f.empty()) return f;
  for (size_t i = 0; i < scene.fluid.current_profile_velocities_m_s.size(); ++i) {
    if (auto f = Z(absl::StrCat("fluid.current_profile[", i, "].velocity"),
                   scene.fluid.current_profile_velocities_m_s[i]);
        !f.empty())
      return f;
  }
  const WavesSpec& waves = scene.fluid.waves;
  for (size_t i = 0; i < waves.regular.size(); ++i) {
    if (auto f = Z(absl::StrCat("fluid.waves.regular[", i, "].direction"), waves.regular[i].direction);
        !f.empty())
      return f;
  }
  for (size_t i = 0; i < waves.jonswap.size(); ++i) {
    if (auto f = Z(absl::StrCat("fluid.waves.jonswap[", i, "].direction"), waves.jonswap[i].direction);
        !f.empty())
      return f;
  }
  for (size_t i = 0; i < waves.components.size(); ++i) {
    if (auto f = Z(absl::StrCat("fluid.waves.components[", i, "].direction"),
                   waves.components[i].direction);
        !f.empty())
      return f;
  }
  for (const ElevationSeriesSpec& e : waves.elevation_series)
    if (auto f = Z("fluid.waves.elevation_series.direction", e.direction); !f.empty()) return f;
  for (size_t i = 0; i < scene.fluid.current_grid_velocities_m_s.size(); ++i) {
    if (auto f = Z(absl::StrCat("fluid.current_grid.velocities[", i, "]"),
                   scene.fluid.current_grid_velocities_m_s[i]);
        !f.empty())
      return f;
  }
  if (scene.seabed.enabled)
    if (auto f = Z("seabed.normal", scene.seabed.normal); !f.empty()) return f;
  for (size_t i = 0; i < scene.sheaves.size(); ++i) {
    // A wheel's position off the plane does not matter to the planar
    // model (its axis is z there); only a tilted axis needs the spatial one.
    if (auto f = NotAboutZ(absl::StrCat("sheaves[", i, "].axis"), scene.sheaves[i].axis);
        !f.empty())
      return f;
  }
  return "";
}

absl::StatusOr<int> ChooseDimension(const Scene& scene) {
  if (scene.model == ModelChoice::kSpatial) return 3;
  const std::string field = OutOfPlaneField(scene);
  if (field.empty()) return 2;
  if (scene.model == ModelChoice::kPlanar) {
    return absl::InvalidArgumentError(absl::StrCat(
        "model: PLANAR, but ", field,
        " leaves the x-y plane (use SPATIAL or AUTO, or keep every point, direction and force "
        "at z = 0 and every rotation about z)"));
  }
  return 3;
}

}  // namespace cablesim
