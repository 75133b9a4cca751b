// ModelBuilder's steps for the forces (model_builder.h): the winches'
// checks, the cable elements and their element terms, the force
// contributors the scene uses (one line each, in the order of the sums),
// the winches' data and contributor, gravity and the constant loads.

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <utility>

#include "absl/strings/str_format.h"
#include "engine/model/model_builder.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;

// The diameter the fluid sees [m]: the hydrodynamic one, or the solid
// section's.
double HydroDiameter(const CableSpec& cable) {
  return cable.hydro_diameter_m > 0 ? cable.hydro_diameter_m : std::sqrt(4 * cable.area_m2 / kPi);
}

}  // namespace

absl::Status ModelBuilder::CheckWinches() const {
  const int num_cables = static_cast<int>(scene_.cables.size());
  for (int c = 0; c < num_cables; ++c) {
    const CableSpec& cable = scene_.cables[c];
    if (!cable.winch.enabled) continue;
    const double len = cable.length_m, tol = kSnap * len;
    if (scene_.solver.analysis == Analysis::kDynamic && scene_.solver.duration_s > 0) {
      // L(t) = len + int_0^t speed on a grid no coarser than the step (at
      // most 100,000 points), the first crossing of 0 refined by bisection.
      const double duration = scene_.solver.duration_s;
      const int n = static_cast<int>(std::min(
          1e5, std::max(100.0, std::ceil(duration / std::max(scene_.solver.step_s, 1e-12)))));
      auto length = [&](double t) { return len + cable.winch.speed.Integral(t); };
      double t_prev = 0;
      for (int i = 1; i <= n; ++i) {
        const double t = duration * i / n;
        if (length(t) > 0) {
          t_prev = t;
          continue;
        }
        double lo = t_prev, hi = t;
        for (int k = 0; k < 60 && hi - lo > 1e-12 * (1 + hi); ++k) {
          const double mid = 0.5 * (lo + hi);
          (length(mid) > 0 ? lo : hi) = mid;
        }
        return absl::InvalidArgumentError(absl::StrFormat(
            "cables[%d].winch.speed: reels in the whole cable: its free length (length + "
            "int speed dt) reaches 0 at t = %.6g s, within solver.duration (%.6g s)",
            c, hi, duration));
      }
    }
    bool held = false;
    for (size_t j = 0; j < scene_.joints.size(); ++j) {
      const JointSpec& joint = scene_.joints[j];
      for (const Attachment* at : {&joint.a, &joint.b}) {
        if (at->cable != c) continue;
        if (joint.type == JointType::kSlide) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "joints[%d]: a sliding joint cannot run on a winch cable (cables[%d].winch)", j, c));
        }
        const Attachment& other = at == &joint.a ? joint.b : joint.a;
        if (std::abs(at->s_m - len) <= tol && other.IsGround()) held = true;
        if (at->s_m > tol && at->s_m < len - tol) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "joints[%d]: a winch cable (cables[%d].winch) takes joints only at its ends (s = 0 "
              "or its length): its mesh moves through the material",
              j, c));
        }
      }
    }
    if (!held) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "cables[%d].winch: the winch holds the cable's last point (s = length): join it to "
          "the ground with a PIN or FIXED joint (with a motion for a moving winch)",
          c));
    }
    for (size_t i = 0; i < scene_.loads.size(); ++i) {
      const Attachment& at = scene_.loads[i].at;
      if (at.cable == c && at.s_m > tol && at.s_m < len - tol) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "loads[%d].at: a winch cable (cables[%d].winch) takes loads only at its ends", i, c));
      }
    }
    for (size_t i = 0; i < scene_.probes.size(); ++i) {
      const Attachment& at = scene_.probes[i].at;
      if (at.cable == c && at.s_m > tol && at.s_m < len - tol) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "probes[%d].at: a winch cable (cables[%d].winch) takes probes only at its ends", i,
            c));
      }
    }
    if (cable.bending_damping_s != 0 || cable.rayleigh_beta_s != 0) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "cables[%d].damping: a winch cable takes axial_time and rayleigh_alpha only (bending "
          "damping on an axially moving mesh is not built)",
          c));
    }
    // In a fluid and on a seabed the position-only loads follow the mesh
    // (buoyancy through GravityLoads' weight per length and, with a free
    // surface, CableSurfaceBuoyancy; the bed's contact as an element term
    // on the model's elements): each takes the elements' length L(t) / N.
    // The loads that depend on the velocity or the acceleration act on the
    // material, whose velocity on a winch cable is S edot + ldot W e, not
    // the mesh's edot their terms take: drag is WinchCables' (in a current,
    // not in waves); the rest is refused in DYNAMIC runs (STATIC holds L
    // fixed, so the material and the mesh move together).
    if (scene_.solver.analysis != Analysis::kDynamic) continue;
    if (scene_.fluid.density_kg_m3 > 0) {
      if ((cable.normal_drag != 0 || cable.tangential_drag != 0) && scene_.fluid.waves.any()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "cables[%d].hydrodynamics.%s: drag on a winch cable in waves is not modelled "
            "(WinchCables takes the drag on the material velocity S edot + ldot W e in a "
            "current, not the waves' flow): set normal_drag and tangential_drag to 0, or "
            "leave out fluid.waves",
            c, cable.normal_drag != 0 ? "normal_drag" : "tangential_drag"));
      }
      if (cable.added_mass != 0 || (cable.has_axial_added_mass && cable.axial_added_mass != 0)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "cables[%d].hydrodynamics.%s: added mass on a winch cable is not modelled "
            "(the fluid's inertia rides with the material through the moving mesh, which the "
            "winch's convective inertia does not carry): set added_mass (and axial_added_mass) "
            "to 0",
            c, cable.added_mass != 0 ? "added_mass" : "axial_added_mass"));
      }
    }
    if (scene_.seabed.enabled &&
        (scene_.seabed.damping_n_s_m2 != 0 || scene_.seabed.friction_axial != 0 ||
         scene_.seabed.friction_transverse != 0)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "seabed.%s: the seabed's damping and friction on a winch cable (cables[%d].winch) "
          "are not modelled in DYNAMIC runs (they need the material velocity S edot + ldot W "
          "e, not the axially moving mesh's): set seabed.damping, seabed.friction_axial and "
          "seabed.friction_transverse to 0",
          scene_.seabed.damping_n_s_m2 != 0 ? "damping"
          : scene_.seabed.friction_axial != 0 ? "friction_axial"
                                              : "friction_transverse",
          c));
    }
  }
  return absl::OkStatus();
}

template <int D>
void ModelBuilder::BuildElementsOf(std::vector<MultibodyModel::ElementData<D>>* elements) {
  const double extent = q0_.lpNorm<Eigen::Infinity>();  // scene size [m]
  const std::vector<int>& first_node = mesh_.first_node;
  model_.cable_element_begin_.assign(1, 0);
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    if (Stopped()) return;
    const CableSpec& cable = scene_.cables[c];
    model_.cable_names_.push_back(cable.name);
    const double ea = cable.youngs_modulus_pa * cable.area_m2;
    const double ei = cable.youngs_modulus_pa * cable.second_moment_m4;
    const double mpl = cable.density_kg_m3 * cable.area_m2;
    // In a fluid: buoyancy (the displaced fluid's weight off gravity),
    // isotropic added mass, and the drag factors of AddDrag.
    const double rho_f = scene_.fluid.density_kg_m3;
    const double dh = HydroDiameter(cable);
    const double displaced = rho_f > 0 ? rho_f * kPi * dh * dh / 4 : 0.0;  // [kg/m]
    const double drag_n = 0.5 * rho_f * cable.normal_drag * dh;
    const double drag_t = 0.5 * rho_f * cable.tangential_drag * kPi * dh;
    // A tension-strain table, shared by the cable's elements.
    std::shared_ptr<const TensionTable> table;
    if (cable.axial_law == AxialLaw::kTable) {
      table = std::make_shared<const TensionTable>(cable.tension_table_strains,
                                                   cable.tension_table_tensions);
    }
    const size_t first_element = fluid_elements_.size();
    for (int k = first_node[c]; k + 1 < first_node[c + 1]; ++k) {
      if (mesh_.twin_of[k + 1] == k) continue;  // the two halves of a split node
      const int local = k - first_node[c];
      const double l = mesh_.node_s[c][local + 1] - mesh_.node_s[c][local];
      MultibodyModel::ElementData<D> e;
      static_assert(CableSpec::kMaxGaussPoints <= GaussRule::kMaxPoints);
      e.element =
          AncfCableElement<D>(l, ea, ei, cable.bending, cable.gauss_points, cable.axial_law, table);
      if (cable.axial_law == AxialLaw::kViscoelastic) {
        // The law's state per Gauss point (ViscoelasticHistory).
        if (!model_.visco_) model_.visco_ = std::make_unique<ViscoelasticHistory>();
        ViscoelasticHistory::Law law;
        law.ea_static_n = ea;
        law.ea_dynamic_n = cable.visco_dynamic_ea_n;
        law.ea_base_n = cable.visco_dynamic_ea_base_n;
        law.ea_slope = cable.visco_dynamic_ea_slope;
        law.damping_static_ns = cable.visco_static_damping_ns;
        law.damping_dynamic_ns = cable.visco_dynamic_damping_ns;
        e.element.set_viscoelastic(model_.visco_.get(),
                                   model_.visco_->AddElement(law, e.element.gauss_points()));
        model_.visco_elements_.push_back(static_cast<int>(elements->size()));
      }
      // Energy the element can hold from coordinates known to 16 eps
      // (1 + |q0|_inf): a strain of that over l, a curvature of it over l^2.
      const double strain = 16 * std::numeric_limits<double>::epsilon() * (1 + extent) / l;
      const double stiffest = table ? std::max(ea, table->max_stiffness()) : ea;
      model_.energy_roundoff_ += (stiffest + ei / (l * l)) * l * strain * strain;
      e.first_coord = NodeCoord(k);
      e.mass_per_length = mpl + cable.added_mass * displaced;
      // Gravity acts on the mass less the displaced fluid's (buoyancy).
      e.weight_per_length = mpl - displaced;
      element_cable_.push_back(c);
      CableFluidLoad::Element fluid;
      // A winch cable's drag acts on the material velocity (WinchCables).
      fluid.drag_n = cable.winch.enabled ? 0.0 : drag_n;
      fluid.drag_t = cable.winch.enabled ? 0.0 : drag_t;
      // With waves, the flow's inertia: Froude-Krylov plus added mass
      // (WaveLoad).
      // Along the line C_a,ax when the scene gives it (CableAddedMass adds
      // the difference to the mass matrix's isotropic C_a).
      const double axial_added_mass =
          cable.has_axial_added_mass ? cable.axial_added_mass : cable.added_mass;
      if (model_.wave_load_) {
        fluid.fluid_inertia = (1 + cable.added_mass) * displaced;
        fluid.fluid_inertia_axial = (1 + axial_added_mass) * displaced;
      }
      fluid_elements_.push_back(fluid);
      added_mass_elements_.push_back({displaced, cable.added_mass, axial_added_mass});
      CableDamping::Element damping;
      damping.axial_s = cable.axial_damping_s + cable.rayleigh_beta_s;
      damping.bending_s = cable.bending_damping_s + cable.rayleigh_beta_s;
      damping.alpha_1_s = cable.rayleigh_alpha_1_s;
      damping.mass_per_length = e.mass_per_length;
      damping_elements_.push_back(damping);
      const auto me = e.element.MassMatrix(e.mass_per_length);
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) e.mbar(a, b) = me(D * a, D * b);
      elements->push_back(e);
    }
    // Tip loads (Hydrodynamics.start_tip, end_tip) on the first element's
    // first node and the last element's last node.
    if (rho_f > 0 && fluid_elements_.size() > first_element) {
      for (int end = 0; end < 2; ++end) {
        const size_t k = end == 0 ? first_element : fluid_elements_.size() - 1;
        fluid_elements_[k].tip_drag[end] = 0.5 * rho_f * cable.tip_drag_area_m2[end];
        if (model_.wave_load_) fluid_elements_[k].tip_inertia[end] = cable.tip_added_mass_kg[end];
        added_mass_elements_[k].tip_mass[end] = cable.tip_added_mass_kg[end];
      }
    }
    model_.cable_element_begin_.push_back(static_cast<int>(elements->size()));
  }
}

void ModelBuilder::BuildElements() {
  // Waves need a fluid, gravity (the vertical and the dispersion) and a
  // depth; SceneFromProto refuses waves without them, naming the field.
  const FluidSpec& fluid = scene_.fluid;
  const double g = scene_.gravity_m_s2.norm();
  if (fluid.waves.any() && fluid.density_kg_m3 > 0 && g > 0 && fluid.water_depth_m > 0) {
    WaveField field(-scene_.gravity_m_s2 / g, fluid.still_water_level_m, fluid.water_depth_m, g,
                    fluid.waves.ramp_s);
    for (const RegularWaveSpec& r : fluid.waves.regular)
      field.AddRegular(r.height_m, r.period_s, r.direction, r.phase_rad);
    for (const JonswapSpec& j : fluid.waves.jonswap)
      field.AddJonswap(j.significant_height_m, j.peak_period_s, j.peak_factor, j.direction,
                       j.components, j.seed);
    for (const WaveComponentSpec& c : fluid.waves.components)
      field.AddComponent(c.amplitude_m, c.omega_rad_s, c.direction, c.phase_rad);
    for (const ElevationSeriesSpec& e : fluid.waves.elevation_series)
      field.AddElevationSeries(e.times_s, e.elevations_m, e.interval_s, e.cutoff_rad_s,
                               e.direction);
    model_.wave_load_ = std::make_shared<const WaveLoad>(std::move(field), fluid.current_m_s,
                                                         fluid.free_surface, Current());
    model_.waves_ = &model_.wave_load_->field();
    model_.damping_point_cost_ = 1 + static_cast<int64_t>(model_.waves_->components().size());
  }
  if (model_.dim_ == 2) {
    BuildElementsOf<2>(&model_.elements2_);
  } else {
    BuildElementsOf<3>(&model_.elements3_);
  }
  // The element terms, in the order they are summed: damping, the fluid's
  // load, the seabed, the sheaves.
  if (auto damping = MakeCableDamping(std::move(damping_elements_))) {
    cable_damping_ = damping.get();
    model_.cable_damping_ = damping.get();
    model_.element_terms_.push_back(std::move(damping));
  }
  const FreeSurface surface = Surface();
  if (auto load = MakeCableFluidLoad(std::move(fluid_elements_), model_.wave_load_,
                                     scene_.fluid.current_m_s, surface, Current()))
    model_.element_terms_.push_back(std::move(load));
  // The added mass beyond the mass matrix's, for the dynamics (the surface
  // is the waves' where there are waves).
  if (scene_.solver.analysis == Analysis::kDynamic)
    model_.cable_added_mass_ =
        MakeCableAddedMass(std::move(added_mass_elements_), surface, model_.waves_);
  if (auto bed = MakeCableSeabed(scene_, model_.cable_element_begin_)) {
    model_.cable_seabed_ = bed.get();
    model_.element_terms_.push_back(std::move(bed));
  }
  std::vector<int> body_coord;
  for (const MultibodyModel::BodyData& b : model_.bodies_) body_coord.push_back(b.coord);
  if (auto wheels = MakeSheaves(scene_, model_.cable_element_begin_, body_coord)) {
    model_.sheaves_ = wheels.get();
    model_.element_terms_.push_back(std::move(wheels));
  }
  for (const auto& t : model_.element_terms_) {
    if (t->has_potential()) {
      model_.potential_terms_.push_back(t.get());
      if (t->bucket() == EnergyBucket::kContact) model_.has_element_contact_ = true;
    }
    if (t->dissipates()) {
      model_.dissipative_terms_.push_back(t.get());
      model_.has_damping_ = true;
    }
  }
}

CurrentProfile ModelBuilder::Current() const {
  const FluidSpec& fluid = scene_.fluid;
  const double g = scene_.gravity_m_s2.norm();
  if (!fluid.current_grid_x_m.empty())
    return CurrentProfile::Grid(fluid.current_grid_x_m, fluid.current_grid_y_m,
                                fluid.current_grid_z_m, fluid.current_grid_t_s,
                                fluid.current_grid_velocities_m_s);
  if (fluid.current_profile_depths_m.empty() || !(g > 0)) return {};
  return CurrentProfile(-scene_.gravity_m_s2 / g, fluid.still_water_level_m,
                        fluid.current_profile_depths_m, fluid.current_profile_velocities_m_s);
}

FreeSurface ModelBuilder::Surface() const {
  FreeSurface surface;
  const double g = scene_.gravity_m_s2.norm();
  if (!scene_.fluid.free_surface || !(scene_.fluid.density_kg_m3 > 0) || !(g > 0)) return surface;
  surface.enabled = true;
  surface.up = -scene_.gravity_m_s2 / g;
  surface.level_m = scene_.fluid.still_water_level_m;
  return surface;
}

template <int D>
std::unique_ptr<ForceContributor> ModelBuilder::SurfaceBuoyancy(
    const std::vector<MultibodyModel::ElementData<D>>& elements) const {
  const FreeSurface surface = Surface();
  if (!surface.enabled) return nullptr;
  std::vector<typename CableSurfaceBuoyancy<D>::Element> out;
  const double rho_f = scene_.fluid.density_kg_m3, g = scene_.gravity_m_s2.norm();
  // Winch cables' elements follow L(t) / N (CableSurfaceBuoyancy::SetTime).
  std::vector<typename CableSurfaceBuoyancy<D>::Winch> winches;
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    const CableSpec& cable = scene_.cables[c];
    if (!cable.winch.enabled) continue;
    typename CableSurfaceBuoyancy<D>::Winch w;
    w.element_begin = model_.cable_element_begin_[c];
    w.element_end = model_.cable_element_begin_[c + 1];
    w.reel.length0 = cable.length_m;
    w.reel.speed = cable.winch.speed;
    winches.push_back(std::move(w));
  }
  for (size_t k = 0; k < elements.size(); ++k) {
    const CableSpec& cable = scene_.cables[element_cable_[k]];
    const double dh = HydroDiameter(cable);
    out.push_back(
        {elements[k].first_coord, elements[k].element, rho_f * kPi * dh * dh / 4 * g, dh / 2});
  }
  // The waves' elevation in DYNAMIC runs only (STATIC sees the still level).
  return MakeCableSurfaceBuoyancy<D>(std::move(out), surface,
                                     scene_.solver.analysis == Analysis::kDynamic,
                                     std::move(winches));
}

absl::Status ModelBuilder::Contributors() {
  MultibodyModel& m = model_;
  std::vector<int> body_coord(scene_.bodies.size());
  for (size_t b = 0; b < body_coord.size(); ++b) body_coord[b] = BodyCoord(static_cast<int>(b));
  auto add = [&m](std::unique_ptr<ForceContributor> c) {
    if (c->dissipates()) m.has_damping_ = true;
    m.contributors_.push_back(std::move(c));
  };
  // The list's order is the order of summation.
  std::vector<std::array<std::vector<AppliedLoads::Term>, 3>> points(scene_.loads.size());
  for (size_t l = 0; l < points.size(); ++l) {
    if (IsZero(scene_.loads[l].varying_force_n)) continue;
    const LinearVector point = PointOf(scene_.loads[l].at);
    for (int d = 0; d < m.dim_; ++d)
      for (const auto& [i, c] : point[d].terms) points[l][d].push_back({i, c});
  }
  if (auto loads = MakeAppliedLoads(scene_, points, body_coord, m.dim_)) {
    m.has_step_work_ = true;
    add(std::move(loads));
  }
  if (auto buoyancy = m.dim_ == 2 ? SurfaceBuoyancy<2>(m.elements2_)
                                  : SurfaceBuoyancy<3>(m.elements3_))
    add(std::move(buoyancy));
  if (auto damping = MakeBodyDamping(scene_, body_coord, m.dim_)) add(std::move(damping));
  if (auto contact = MakeBodySeabedContact(scene_, body_coord, m.dim_)) {
    m.body_contact_ = contact.get();
    add(std::move(contact));
  }
  if (auto fluid = MakeBodyFluidForces(scene_, body_coord, m.dim_, m.wave_load_ != nullptr)) {
    // The added mass joins the body's mass matrix and kinetic energy: the
    // sum over the body's parts.
    for (const BodyFluidLoad& load : fluid->loads()) {
      for (size_t b = 0; b < body_coord.size(); ++b) {
        if (body_coord[b] != load.coord()) continue;
        MultibodyModel::BodyData& data = m.bodies_[b];
        data.added_mass += load.AddedMass(q0_);
        data.has_added_mass = !data.added_mass.isZero(0);
      }
    }
    m.body_fluid_ = fluid.get();
    add(std::move(fluid));
  }
  bool slides = false;
  for (const JointSpec& joint : scene_.joints) slides = slides || joint.type == JointType::kSlide;
  if (slides) {
    std::vector<std::vector<SlidingJoint::Segment>> segments(scene_.cables.size());
    for (size_t cable = 0; cable < segments.size(); ++cable) {
      double s0 = 0;
      for (int k = m.cable_element_begin_[cable]; k < m.cable_element_begin_[cable + 1]; ++k) {
        const int first = m.dim_ == 2 ? m.elements2_[k].first_coord : m.elements3_[k].first_coord;
        const double l =
            m.dim_ == 2 ? m.elements2_[k].element.length() : m.elements3_[k].element.length();
        segments[cable].push_back({first, s0, l});
        s0 += l;
      }
    }
    absl::StatusOr<std::unique_ptr<SlidingJoints>> sliders =
        MakeSlidingJoints(scene_, segments, body_coord, m.dim_, m.body_stride_, q0_);
    if (!sliders.ok()) return sliders.status();
    m.sliders_ = sliders->get();
    add(std::move(*sliders));
  }
  return absl::OkStatus();
}

void ModelBuilder::Winches() {
  MultibodyModel& m = model_;
  for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
    const CableSpec& cable = scene_.cables[c];
    if (!cable.winch.enabled) continue;
    MultibodyModel::WinchData w;
    w.cable = c;
    w.element_begin = m.cable_element_begin_[c];
    w.element_end = m.cable_element_begin_[c + 1];
    w.reel.length0 = w.length = cable.length_m;
    w.reel.speed = cable.winch.speed;
    w.mass_per_length = cable.density_kg_m3 * cable.area_m2;
    w.ea = cable.youngs_modulus_pa * cable.area_m2;
    m.winches_.push_back(std::move(w));
  }
  if (m.winches_.empty()) return;
  for (const MultibodyModel::WinchData& w : m.winches_) {
    for (int k = w.element_begin; k < w.element_end; ++k) {
      // The winch damps the material motion instead (WinchCables).
      if (cable_damping_) cable_damping_->ClearMaterialDamping(k);
    }
  }
  m.has_damping_ = true;  // the convective terms ride on DampingForce
}

template <int D>
void ModelBuilder::WinchContributor(const std::vector<MultibodyModel::ElementData<D>>& elements) {
  MultibodyModel& m = model_;
  std::vector<typename WinchCables<D>::Winch> winches;
  for (const MultibodyModel::WinchData& data : m.winches_) {
    const CableSpec& cable = scene_.cables[data.cable];
    typename WinchCables<D>::Winch w;
    w.reel = data.reel;
    w.mass_per_length = data.mass_per_length;
    w.ea = data.ea;
    w.axial_damping_s = cable.axial_damping_s;
    w.alpha_1_s = cable.rayleigh_alpha_1_s;
    const double rho_f = scene_.fluid.density_kg_m3;
    if (rho_f > 0 && scene_.solver.analysis == Analysis::kDynamic) {
      const double dh = HydroDiameter(cable);
      w.drag_n = 0.5 * rho_f * cable.normal_drag * dh;
      w.drag_t = 0.5 * rho_f * cable.tangential_drag * kPi * dh;
      w.current = scene_.fluid.current_m_s;
      w.profile = Current();
      w.surface = Surface();
    }
    for (int k = data.element_begin; k < data.element_end; ++k)
      w.elements.push_back({elements[k].first_coord});
    winches.push_back(std::move(w));
  }
  // Last in the list: the model summed the winches' terms after every
  // other contributor's.
  if (auto c = MakeWinchCables<D>(std::move(winches))) m.contributors_.push_back(std::move(c));
}

void ModelBuilder::ConstantForces() {
  MultibodyModel& m = model_;
  const int D = m.dim_;
  for (const BodySpec& body : scene_.bodies) m.body_names_.push_back(body.name);
  m.gravity_ = scene_.gravity_m_s2;
  std::vector<int> first, body_coord;
  std::vector<double> weight, length, body_mass;
  auto element = [&](const auto& e) {
    first.push_back(e.first_coord);
    weight.push_back(e.weight_per_length);
    length.push_back(e.element.length());
  };
  for (const auto& e : m.elements2_) element(e);
  for (const auto& e : m.elements3_) element(e);
  for (const MultibodyModel::BodyData& b : m.bodies_) {
    body_coord.push_back(b.coord);
    body_mass.push_back(b.mass);
  }
  // A force F at a point r = sum_i a_i q_i + c does the work F . dr, so its
  // generalized force is sum_d F_d a_{d,i} on q_i (constant: the point is
  // linear in q).
  std::vector<std::pair<int, double>> load_terms;
  for (const LoadSpec& load : scene_.loads) {
    const LinearVector point = PointOf(load.at);
    for (int d = 0; d < D; ++d)
      for (const auto& [i, v] : point[d].terms) load_terms.push_back({i, v * load.force_n(d)});
  }
  std::vector<std::pair<std::pair<int, int>, WinchReel>> winches;
  for (const MultibodyModel::WinchData& w : m.winches_)
    winches.push_back({{w.element_begin, w.element_end}, w.reel});
  // First in the list: the applied loads are summed onto gravity.
  if (auto gravity = MakeGravityLoads(D, scene_.gravity_m_s2, weight, first, length,
                                      element_cable_, body_coord, body_mass, load_terms,
                                      !scene_.loads.empty(), winches,
                                      static_cast<int>(q0_.size())))
    m.contributors_.insert(m.contributors_.begin(), std::move(gravity));
}

template void ModelBuilder::WinchContributor<2>(
    const std::vector<MultibodyModel::ElementData<2>>& elements);
template void ModelBuilder::WinchContributor<3>(
    const std::vector<MultibodyModel::ElementData<3>>& elements);

}  // namespace cablesim
