#include "convert/scene/sections.h"

#include <cmath>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"

namespace cablesim::scene_convert {
namespace {

// The field that gave body b its drag: `hydrodynamics`, or
// `hydrodynamics_parts` when only parts did (errors name what was written;
// the scene's bodies are the proto's, index for index).
std::string BodyDragField(const ConversionState& state, size_t b) {
  const bool whole = state.proto.bodies(static_cast<int>(b)).has_hydrodynamics();
  return absl::StrCat("bodies[", b, "].", whole ? "hydrodynamics" : "hydrodynamics_parts");
}

// JONSWAP components per sea (each costs a few exponentials per Gauss
// point per force evaluation).
constexpr int kMaxWaveComponents = 1000;
// An elevation series' resampled steps (half as many components).
constexpr double kMaxSeriesSteps = 2 * kMaxWaveComponents;
// A current grid's nodes (x * y * z * times).
constexpr int64_t kMaxGridNodes = 10000000;

// A wave's direction of travel: its part normal to gravity, normalised.
// Omitted: x (y when gravity is along x).
absl::StatusOr<Eigen::Vector3d> WaveDirection(const ConversionState& state, absl::string_view path,
                                              bool given, const v1::Vec3& v) {
  const Eigen::Vector3d up = -state.scene.gravity_m_s2.normalized();
  Eigen::Vector3d d = Eigen::Vector3d::UnitX();
  if (given) {
    CABLESIM_ASSIGN_OR_RETURN(d, Direction(path, v));
  } else if (std::abs(up.x()) > 0.99) {
    d = Eigen::Vector3d::UnitY();
  }
  const Eigen::Vector3d horizontal = d - up.dot(d) * up;
  if (!(horizontal.norm() >= 1e-6)) {
    return Invalid(path, "must have a horizontal part (it is along gravity)");
  }
  return Eigen::Vector3d(horizontal.normalized());
}

absl::Status ConvertWaves(ConversionState* state) {
  const v1::Fluid& f = state->proto.fluid();
  if (!f.has_waves()) return absl::OkStatus();
  const v1::Waves& w = f.waves();
  WavesSpec& spec = state->scene.fluid.waves;
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.waves.ramp_time", w.ramp_time()));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("fluid.waves.ramp_time", w.ramp_time(), plausible::kDuration));
  spec.ramp_s = w.ramp_time();
  if (w.regular_size() == 0 && w.jonswap_size() == 0 && w.components_size() == 0 &&
      !w.has_elevation_series())
    return absl::OkStatus();
  if (!(f.density() > 0)) return Invalid("fluid.waves", "needs a fluid (fluid.density > 0)");
  if (!(f.water_depth() > 0)) {
    return Invalid("fluid.water_depth", "must be > 0 with waves (their kinematics depend on it)");
  }
  if (!(state->scene.gravity_m_s2.norm() > 0)) {
    return Invalid("fluid.waves", "needs gravity (it sets the vertical and the waves' speed)");
  }
  for (int i = 0; i < w.regular_size(); ++i) {
    const v1::Waves::Regular& r = w.regular(i);
    const std::string path = Indexed("fluid.waves", "regular", i);
    RegularWaveSpec out;
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "height"), r.height(), plausible::kSize));
    out.height_m = r.height();
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "period"), r.period(), plausible::kWavePeriod));
    out.period_s = r.period();
    CABLESIM_ASSIGN_OR_RETURN(out.direction, WaveDirection(*state, Sub(path, "direction"),
                                                           r.has_direction(), r.direction()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "phase"), r.phase(), plausible::kPhase));
    out.phase_rad = r.phase();
    spec.regular.push_back(out);
  }
  for (int i = 0; i < w.jonswap_size(); ++i) {
    const v1::Waves::Jonswap& j = w.jonswap(i);
    const std::string path = Indexed("fluid.waves", "jonswap", i);
    JonswapSpec out;
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "significant_height"),
                                                  j.significant_height(), plausible::kSize));
    out.significant_height_m = j.significant_height();
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "peak_period"), j.peak_period(), plausible::kWavePeriod));
    out.peak_period_s = j.peak_period();
    if (j.peak_factor() != 0) {
      CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "peak_factor"), j.peak_factor()));
      if (!(j.peak_factor() >= 1 && j.peak_factor() <= 100)) {
        return Invalid(Sub(path, "peak_factor"),
                       absl::StrCat("must be >= 1 and <= 100 (got ", Num(j.peak_factor()), ")"));
      }
      out.peak_factor = j.peak_factor();
    }
    out.seed = j.seed();
    if (j.components() != 0) {
      CABLESIM_RETURN_IF_ERROR(
          CheckIntRange(Sub(path, "components"), j.components(), 1, kMaxWaveComponents));
      out.components = j.components();
    }
    CABLESIM_ASSIGN_OR_RETURN(out.direction, WaveDirection(*state, Sub(path, "direction"),
                                                           j.has_direction(), j.direction()));
    spec.jonswap.push_back(out);
  }
  if (w.components_size() > kMaxWaveComponents) {
    return Invalid("fluid.waves.components", absl::StrCat("at most ", kMaxWaveComponents,
                                                          " (got ", w.components_size(), ")"));
  }
  for (int i = 0; i < w.components_size(); ++i) {
    const v1::Waves::Component& c = w.components(i);
    const std::string path = Indexed("fluid.waves", "components", i);
    WaveComponentSpec out;
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "amplitude"), c.amplitude()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "amplitude"), c.amplitude(), plausible::kCoordinate));
    out.amplitude_m = c.amplitude();
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "angular_frequency"),
                                                  c.angular_frequency(), plausible::kWaveFrequency));
    out.omega_rad_s = c.angular_frequency();
    CABLESIM_ASSIGN_OR_RETURN(out.direction, WaveDirection(*state, Sub(path, "direction"),
                                                           c.has_direction(), c.direction()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "phase"), c.phase(), plausible::kPhase));
    out.phase_rad = c.phase();
    spec.components.push_back(out);
  }
  if (w.has_elevation_series()) {
    const v1::Waves::ElevationSeries& e = w.elevation_series();
    const std::string path = "fluid.waves.elevation_series";
    ElevationSeriesSpec out;
    if (e.times_size() < 2)
      return Invalid(Sub(path, "times"), absl::StrCat("at least 2 (got ", e.times_size(), ")"));
    if (e.elevations_size() != e.times_size()) {
      return Invalid(Sub(path, "elevations"), absl::StrCat("one per time: expected ",
                                                           e.times_size(), ", got ",
                                                           e.elevations_size()));
    }
    for (int i = 0; i < e.times_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(absl::StrCat(path, ".times[", i, "]"), e.times(i), plausible::kTime));
      if (i > 0 && !(e.times(i) > e.times(i - 1)))
        return Invalid(Sub(path, "times"), absl::StrCat("must increase (times[", i, "] = ",
                                                        Num(e.times(i)), " follows ",
                                                        Num(e.times(i - 1)), ")"));
      CABLESIM_RETURN_IF_ERROR(CheckRange(absl::StrCat(path, ".elevations[", i, "]"),
                                          e.elevations(i), plausible::kCoordinate));
      out.times_s.push_back(e.times(i));
      out.elevations_m.push_back(e.elevations(i));
    }
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "interval"), e.interval()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "interval"), e.interval(), plausible::kDuration));
    const double period = out.times_s.back() - out.times_s.front();
    const double steps =
        e.interval() > 0 ? period / e.interval() : static_cast<double>(e.times_size() - 1);
    if (steps > kMaxSeriesSteps) {
      return Invalid(Sub(path, "interval"),
                     absl::StrCat("cuts the series into ", Num(steps), " steps (at most ",
                                  kMaxSeriesSteps, ")"));
    }
    out.interval_s = e.interval();
    CABLESIM_RETURN_IF_ERROR(
        CheckNonNegative(Sub(path, "cutoff_frequency"), e.cutoff_frequency()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "cutoff_frequency"), e.cutoff_frequency(),
                                        plausible::kWaveFrequency));
    out.cutoff_rad_s = e.cutoff_frequency();
    CABLESIM_ASSIGN_OR_RETURN(out.direction, WaveDirection(*state, Sub(path, "direction"),
                                                           e.has_direction(), e.direction()));
    spec.elevation_series.push_back(std::move(out));
  }
  return absl::OkStatus();
}

// fluid.current_grid: axes strictly increasing, one velocity per node.
absl::Status ConvertCurrentGrid(ConversionState* state) {
  const v1::Fluid& f = state->proto.fluid();
  const v1::Fluid::CurrentGrid& g = f.current_grid();
  FluidSpec& fluid = state->scene.fluid;
  const std::string path = "fluid.current_grid";
  if (!(f.density() > 0)) return Invalid(path, "needs a fluid (fluid.density > 0)");
  if (fluid.current_m_s != Eigen::Vector3d::Zero())
    return Invalid(path, "give fluid.current or fluid.current_grid, not both");
  if (f.current_profile_size() > 0)
    return Invalid(path, "give fluid.current_profile or fluid.current_grid, not both");
  for (size_t b = 0; b < state->scene.bodies.size(); ++b) {
    if (state->scene.bodies[b].has_hydrodynamics) {
      return Invalid(path, absl::StrCat("not taken by ", BodyDragField(*state, b),
                                        " (a body's drag takes the uniform fluid.current)"));
    }
  }
  struct Axis {
    const char* name;
    const google::protobuf::RepeatedField<double>& values;
    std::vector<double>* out;
    const PlausibleRange& range;
  };
  const Axis axes[] = {{"x", g.x(), &fluid.current_grid_x_m, plausible::kCoordinate},
                       {"y", g.y(), &fluid.current_grid_y_m, plausible::kCoordinate},
                       {"z", g.z(), &fluid.current_grid_z_m, plausible::kCoordinate},
                       {"times", g.times(), &fluid.current_grid_t_s, plausible::kTime}};
  int64_t nodes = 1;
  for (const Axis& a : axes) {
    const std::string axis = Sub(path, a.name);
    if (a.values.empty()) return Invalid(axis, "at least one value");
    for (int i = 0; i < a.values.size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(absl::StrCat(axis, "[", i, "]"), a.values[i], a.range));
      if (i > 0 && !(a.values[i] > a.values[i - 1]))
        return Invalid(axis, absl::StrCat("must increase (", a.name, "[", i, "] = ",
                                          Num(a.values[i]), " follows ",
                                          Num(a.values[i - 1]), ")"));
    }
    nodes *= a.values.size();
    if (nodes > kMaxGridNodes)
      return Invalid(path, absl::StrCat("at most ", kMaxGridNodes, " nodes"));
    a.out->assign(a.values.begin(), a.values.end());
  }
  if (g.velocities_size() != nodes) {
    return Invalid(Sub(path, "velocities"),
                   absl::StrCat("expected x * y * z * times = ", nodes, " velocities, got ",
                                g.velocities_size()));
  }
  for (int i = 0; i < g.velocities_size(); ++i) {
    Eigen::Vector3d v;
    CABLESIM_ASSIGN_OR_RETURN(v, VectorInRange(absl::StrCat(path, ".velocities[", i, "]"),
                                               g.velocities(i), plausible::kVelocity));
    fluid.current_grid_velocities_m_s.push_back(v);
  }
  return absl::OkStatus();
}

// The grid replaces the plane: depth 0, the normal a coordinate axis.
absl::Status ConvertBathymetry(ConversionState* state, const v1::Seabed& b) {
  const v1::Bathymetry& g = b.bathymetry();
  BathymetrySpec& spec = state->scene.seabed.bathymetry;
  constexpr int kMaxNodes = 10000000;
  if (b.depth() != 0)
    return Invalid("seabed.depth", "must be 0 with a bathymetry grid (the grid gives the depths)");
  const Eigen::Vector3d& n = state->scene.seabed.normal;
  if (n.cwiseAbs().maxCoeff() != 1.0)
    return Invalid("seabed.normal",
                   "must be along a coordinate axis with a bathymetry grid (the grid's up)");
  CABLESIM_RETURN_IF_ERROR(CheckIntRange("seabed.bathymetry.nx", g.nx(), 1, kMaxNodes));
  CABLESIM_RETURN_IF_ERROR(CheckIntRange("seabed.bathymetry.ny", g.ny(), 1, kMaxNodes));
  const int64_t count = static_cast<int64_t>(g.nx()) * g.ny();
  if (count > kMaxNodes)
    return Invalid("seabed.bathymetry",
                   absl::StrCat("at most ", kMaxNodes, " nodes (got nx*ny = ", count, ")"));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("seabed.bathymetry.origin_x", g.origin_x(), plausible::kCoordinate));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("seabed.bathymetry.origin_y", g.origin_y(), plausible::kCoordinate));
  if (g.nx() > 1) {
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange("seabed.bathymetry.dx", g.dx(), plausible::kCableLength));
  }
  if (g.ny() > 1) {
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange("seabed.bathymetry.dy", g.dy(), plausible::kCableLength));
  }
  if (g.depths_size() != count)
    return Invalid("seabed.bathymetry.depths",
                   absl::StrCat("expected nx*ny = ", count, " values, got ", g.depths_size()));
  spec.depths_m.resize(count);
  for (int i = 0; i < g.depths_size(); ++i) {
    CABLESIM_RETURN_IF_ERROR(CheckRange(absl::StrCat("seabed.bathymetry.depths[", i, "]"),
                                        g.depths(i), plausible::kCoordinate));
    spec.depths_m[i] = g.depths(i);
  }
  spec.enabled = true;
  spec.origin_x_m = g.origin_x();
  spec.origin_y_m = g.origin_y();
  spec.dx_m = g.nx() > 1 ? g.dx() : 1.0;
  spec.dy_m = g.ny() > 1 ? g.dy() : 1.0;
  spec.nx = g.nx();
  spec.ny = g.ny();
  return absl::OkStatus();
}

}  // namespace

absl::Status ConvertFluid(ConversionState* state) {
  const v1::Fluid& f = state->proto.fluid();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.density", f.density()));
  if (f.density() != 0)
    CABLESIM_RETURN_IF_ERROR(CheckRange("fluid.density", f.density(), plausible::kDensity));
  state->scene.fluid.density_kg_m3 = f.density();
  CABLESIM_ASSIGN_OR_RETURN(state->scene.fluid.current_m_s,
                            VectorInRange("fluid.current", f.current(), plausible::kVelocity));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("fluid.still_water_level", f.still_water_level(), plausible::kCoordinate));
  state->scene.fluid.still_water_level_m = f.still_water_level();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.water_depth", f.water_depth()));
  if (f.water_depth() != 0) {
    CABLESIM_RETURN_IF_ERROR(
        CheckRange("fluid.water_depth", f.water_depth(), plausible::kCableLength));
  }
  state->scene.fluid.water_depth_m = f.water_depth();
  if (f.free_surface()) {
    if (!(f.density() > 0))
      return Invalid("fluid.free_surface", "needs a fluid (fluid.density > 0)");
    if (!(state->scene.gravity_m_s2.norm() > 0))
      return Invalid("fluid.free_surface", "needs gravity (the vertical the level is measured on)");
    state->scene.fluid.free_surface = true;
  }
  if (f.current_profile_size() > 0) {
    if (!(f.density() > 0))
      return Invalid("fluid.current_profile", "needs a fluid (fluid.density > 0)");
    if (!(state->scene.gravity_m_s2.norm() > 0))
      return Invalid("fluid.current_profile", "needs gravity (the vertical depth is measured on)");
    if (state->scene.fluid.current_m_s != Eigen::Vector3d::Zero())
      return Invalid("fluid.current_profile", "give fluid.current or fluid.current_profile, not both");
    for (size_t b = 0; b < state->scene.bodies.size(); ++b) {
      if (state->scene.bodies[b].has_hydrodynamics) {
        return Invalid("fluid.current_profile",
                       absl::StrCat("not taken by ", BodyDragField(*state, b),
                                    " (a body's drag takes the uniform fluid.current)"));
      }
    }
    for (int i = 0; i < f.current_profile_size(); ++i) {
      const std::string path = absl::StrCat("fluid.current_profile[", i, "]");
      const double depth = f.current_profile(i).depth();
      CABLESIM_RETURN_IF_ERROR(CheckRange(path + ".depth", depth, plausible::kCoordinate));
      if (i > 0 && !(depth > f.current_profile(i - 1).depth()))
        return Invalid(path + ".depth", "depths must be strictly increasing");
      Eigen::Vector3d velocity;
      CABLESIM_ASSIGN_OR_RETURN(
          velocity,
          VectorInRange(path + ".velocity", f.current_profile(i).velocity(), plausible::kVelocity));
      state->scene.fluid.current_profile_depths_m.push_back(depth);
      state->scene.fluid.current_profile_velocities_m_s.push_back(velocity);
    }
  }
  if (f.has_current_grid()) CABLESIM_RETURN_IF_ERROR(ConvertCurrentGrid(state));
  return ConvertWaves(state);
}

absl::Status ConvertSeabed(ConversionState* state) {
  if (!state->proto.has_seabed()) return absl::OkStatus();
  const v1::Seabed& b = state->proto.seabed();
  SeabedSpec& spec = state->scene.seabed;
  spec.enabled = true;
  CABLESIM_RETURN_IF_ERROR(CheckRange("seabed.depth", b.depth(), plausible::kCoordinate));
  spec.depth_m = b.depth();
  if (b.has_normal()) {
    CABLESIM_ASSIGN_OR_RETURN(spec.normal, Direction("seabed.normal", b.normal()));
  } else if (state->scene.gravity_m_s2.norm() > 0) {
    spec.normal = -state->scene.gravity_m_s2.normalized();
  } else {
    return Invalid("seabed.normal", "must be given when gravity is zero");
  }
  CABLESIM_RETURN_IF_ERROR(
      CheckPositiveInRange("seabed.stiffness", b.stiffness(), plausible::kStiffness));
  spec.stiffness_n_m2 = b.stiffness();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("seabed.damping", b.damping()));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("seabed.damping", b.damping(), plausible::kDampingCoefficient));
  spec.damping_n_s_m2 = b.damping();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("seabed.friction_axial", b.friction_axial()));
  CABLESIM_RETURN_IF_ERROR(
      CheckRange("seabed.friction_axial", b.friction_axial(), plausible::kFrictionCoefficient));
  spec.friction_axial = b.friction_axial();
  CABLESIM_RETURN_IF_ERROR(CheckNonNegative("seabed.friction_transverse", b.friction_transverse()));
  CABLESIM_RETURN_IF_ERROR(CheckRange("seabed.friction_transverse", b.friction_transverse(),
                                      plausible::kFrictionCoefficient));
  spec.friction_transverse = b.friction_transverse();
  if (b.friction_speed() != 0) {
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.friction_speed", b.friction_speed(),
                                                  plausible::kFrictionSpeed));
    spec.friction_speed_m_s = b.friction_speed();
  }
  if (b.friction_length() != 0) {
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.friction_length", b.friction_length(),
                                                  plausible::kFrictionLength));
    spec.friction_length_m = b.friction_length();
  }
  if (b.friction_law() == v1::Seabed::MOORDYN) {
    spec.friction_law = FrictionLaw::kMoorDyn;
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.friction_damping", b.friction_damping(),
                                                  plausible::kDampingCoefficient));
    spec.friction_damping_n_s_m2 = b.friction_damping();
    if (b.static_friction_scale() != 0) {
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.static_friction_scale",
                                                    b.static_friction_scale(),
                                                    plausible::kFrictionCoefficient));
      spec.static_friction_scale = b.static_friction_scale();
    }
  } else if (b.friction_damping() != 0 || b.static_friction_scale() != 0) {
    return Invalid(b.friction_damping() != 0 ? "seabed.friction_damping"
                                             : "seabed.static_friction_scale",
                   "only with seabed.friction_law MOORDYN");
  } else if (b.friction_law() != v1::Seabed::FRICTION_LAW_UNSPECIFIED &&
             b.friction_law() != v1::Seabed::REGULARIZED) {
    return Invalid("seabed.friction_law", absl::StrCat("unknown value ", b.friction_law()));
  }
  if (b.has_bathymetry()) CABLESIM_RETURN_IF_ERROR(ConvertBathymetry(state, b));
  return absl::OkStatus();
}

}  // namespace cablesim::scene_convert
