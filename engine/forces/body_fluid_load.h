#ifndef CABLESIM_ENGINE_FORCES_BODY_FLUID_LOAD_H_
#define CABLESIM_ENGINE_FORCES_BODY_FLUID_LOAD_H_

// The fluid's load on a rigid body (a buoy, a clump weight, a float):
// buoyancy of a vertical cylinder that may pierce the surface, and the
// Morison drag and inertia of the flow (Morison, O'Brien, Johnson and
// Schaaf, "The force exerted by surface waves on piles", J. Petroleum
// Technology 2(5), 1950, eq. 1; the relative-velocity form with the
// Froude-Krylov term as in DNV-RP-C205, 2010, section 6.2.2).
//
// Shape. The body displaces a vertical circular cylinder of diameter d
// [m] and height H [m] centred at its centre of mass r_c, whatever the
// body's orientation: a model for a buoy kept upright by its ballast and
// moorings. It gives forces at the centre of mass only (no hydrostatic
// roll/pitch restoring moment, no moment of the drag). With `up` the unit
// vertical (the opposite of gravity), A = pi d^2 / 4 the waterplane area,
// and z = up . r_c - level the centre's height above a water level, the
// submerged length and volume are
//
//   s(z) = clamp(H / 2 - z, 0, H),   V(z) = A s(z).
//
// Buoyancy. Split into a conservative hydrostatic part about the still
// water level (z_0 = up . r_c - still level) and, with waves, the change
// that the wave elevation eta(x, t) at the centre's horizontal position
// makes (the level then is still level + eta):
//
//   F_s = rho g A s(z_0) up                  (NetForce, scaled as gravity)
//   F_w = rho g A (s(z_0 - eta) - s(z_0)) up (DynamicForce)
//
// F_s is minus the gradient of U_s = rho g A P(z_0) with P(z) = 0 above
// the body (z >= H/2), (z - H/2)^2 / 2 while it pierces the level, and
// H^2 / 2 - H (z + H/2) below it: U_s is the body's energy in the loads'
// part. Its tangent -dF_s/dr_c = rho g A up up^T while the body pierces
// the level (the hydrostatic heave stiffness rho g A_wp), 0 otherwise.
// F_w makes the body heave with the surface (for a wave long against the
// draft, rho g A eta is the linear Froude-Krylov heave force of the
// dynamic pressure at the keel to first order in k s); its derivative in
// r_c is left out of the Newton matrix (it is zero while the body pierces
// both levels).
//
// Morison loads. The flow u = U + u_w(r_c, t) (current plus wave
// kinematics, WaveField::At, at the centre of mass: not integrated over the
// draft, so the load is exact for a body short against the wavelength;
// above the still level the kinematics are those at z = 0). With the
// relative velocity v_r = u - rdot_c split into its horizontal part v_h and
// vertical part v_v = (v_r . up) up:
//
//   F_d = (1/2) rho C_d d s |v_h| v_h + (1/2) rho C_dv A |v_v| v_v
//   F_i = rho V (I + C_a) du/dt,   C_a = C_ah (I - up up^T) + C_av up up^T
//
// (C_d on the projected area d s across the axis, C_dv on the end area A
// while the body is wet, s > 0). F_i is the Froude-Krylov force rho V du/dt
// plus the added-mass force on the flow's acceleration; the added-mass
// force on the body's own acceleration, -rho V_ref C_a rddot_c, is in the
// mass matrix (AddedMass: the reduced mass matrix of the engine is
// constant, factored once per run, and the steppers' forces depend on q
// and qdot only, so an acceleration-dependent force has no place), with
// V_ref = V at the body's `position` in the scene (before any initial
// statics): a floating body's draft changes little, a submerged one's not
// at all.
//
// Tangent of F_d + F_i + F_w in rdot_c: C = -dF/d(rdot_c) =
// k_h (|v_h| P + v_h v_h^T / |v_h|) + 2 k_v |v_v| up up^T (P = I - up up^T,
// k_h = rho C_d d s / 2, k_v = rho C_dv A / 2), symmetric positive
// semi-definite. The derivatives in r_c (through s, eta and the flow's
// dependence on position) are left out, as for the cables' WaveLoad.
//
// Along the body's axis (Params::along_axis, a rod): the same drag and
// inertia with the part's axis a = R a_b / |R a_b| in place of `up` in the
// split, a_b (Params::axis_body) a direction in the body's frame and R =
// [e1 e2 e3] the body's axes from its natural coordinates at q (planar:
// R a_b = a_bx u + a_by e_z x u; a_b = e_x gives the body's x axis
// a = u / |u|): v_h the relative
// velocity across the axis, v_v along it, C_d on d s across, C_dv on A
// along, C_a = C_ah (I - a a^T) + C_av a a^T; the added mass on the body's
// own acceleration takes a at the body's `position` (the constant mass
// matrix: exact while the rod keeps its initial direction). The tangents
// in a (a moment's) are left out with those in r_c. Buoyancy stays the
// vertical cylinder's of the same length: exact while the rod is wholly
// under water or wholly above it (a scene built from a MoorDyn deck
// refuses a tilted rod piercing the surface where it starts).
//
// Drag areas (Params::drag_area, rotational_drag_area; MoorDyn's body
// CdA), in the body's own axes R = [e1 e2 e3] (its natural coordinates at
// q; planar: e1 = u / |u|, e2 = e_z x e1): with B = R diag(A) R^T,
//
//   F_a = (1/2) rho f B |v_r| v_r            on the centre of mass,
//   M_a = -(1/2) rho f B_w |omega| omega     about it,
//
// v_r = u - rdot_c the flow relative to the centre (u as above), omega the
// body's angular velocity (1/2) sum_k e_k x edot_k (the flow does not
// turn), A [m^2] and A_w [m^5] the areas about e1, e2, e3, f the wetted
// fraction s / H of the cylinder, or 1 for a body without one (H = 0: no
// buoyancy, no Morison terms, drag wherever the body is, as MoorDyn's).
// A body moving along e_k feels (1/2) rho A_k |v| v. The moment acts on
// the axes as Q_k = (1/2) M_a x e_k (its virtual work M_a . dtheta for
// orthonormal axes); planar, as T e_z x u on u with T = M_a . e_z. Tangent
// in qdot: on rdot_c, k sym(B (|v_r| I + v_r v_r^T / |v_r|)) (k = rho f /
// 2; B is not isotropic, so its symmetric part: exact for equal areas);
// on the axes, (1/4) S^T K S with S = [[e1]x [e2]x [e3]x] and K the same
// symmetric part for omega (planar: 2 k A_wz |omega| (e_z x u)(e_z x u)^T),
// positive semi-definite. Derivatives in q (through R and f) are left out.
//
// Parts. A body may carry several such loads (BodySpec::hydro_parts: its
// own volume and rods on it), each a BodyFluidLoad with its own cylinder,
// coefficients and axis; their forces, tangents, added masses
// (MultibodyModel sums AddedMass over them), energies and damping powers
// add.
//
// Off the centre of mass (Params::center_body = c, body frame [m]). A
// part's cylinder may be centred at r_p = r_c + R c instead of r_c. In
// natural coordinates that point is linear in the body's coordinates q_b:
// r_p = T q_b with T = [I, c_1 I, c_2 I, c_3 I] (spatial, q_b = [r_c, e1,
// e2, e3]) or T = [I, c_x I + c_y J] (planar, q_b = [r_c, u], J u = e_z x
// u). Every formula above then reads r_p and its velocity T qdot_b in place
// of r_c and rdot_c (the height z, the flow at the point, the relative
// velocity), and a force F at the point acts on the body as T^T F: the
// force on r_c and its moment (R c) x F on the axes (for orthonormal axes,
// the virtual work F . (drdot_c + sum c_k de_k)). T is constant, so the
// tangents are T^T K T and T^T C T, the hydrostatic force stays minus the
// gradient of U_s(up . T q_b), and the added mass T^T (rho V_ref C_a) T
// [kg, kg m, kg m^2] is constant too: the fluid's inertia at the part's
// centre adds rotational inertia rho V_ref C_a |c|^2 about the centre of
// mass (to the rotational inertia of the cylinder about its own centre,
// left out, as for a part at the centre of mass). Drag areas act at the
// centre of mass: SceneFromProto refuses them on a part with an offset.
//
// Energy: F_d + F_i + F_w (and F_a, M_a) is not a potential's force; its power -F . rdot_c
// joins the damping power (MultibodyModel::DampingPower), so energy.damped
// counts the drag's dissipation and the waves' work, and energy.total +
// energy.damped stays what the exact solution conserves.
//
// Units SI. Allocates nothing.

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/force_contributor.h"
#include "engine/forces/waves.h"
#include "engine/scene/scene.h"

namespace cablesim {

class BodyFluidLoad {
 public:
  struct Params {
    double density_kg_m3 = 0;  // of the fluid
    double g_m_s2 = 0;         // |gravity|
    Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    double still_level_m = 0;  // up . r of the still water level
    double diameter_m = 0, height_m = 0;
    double drag = 0, heave_drag = 0;              // C_d, C_dv [-]
    double added_mass = 0, heave_added_mass = 0;  // C_ah, C_av [-]
    // The split across/along the body-frame direction axis_body (unit;
    // default the body's x axis) instead of the vertical.
    bool along_axis = false;
    Eigen::Vector3d axis_body = Eigen::Vector3d::UnitX();
    Eigen::Vector3d current_m_s = Eigen::Vector3d::Zero();
    // Drag areas along the body's axes [m^2] and about them [m^5].
    Eigen::Vector3d drag_area = Eigen::Vector3d::Zero();
    Eigen::Vector3d rotational_drag_area = Eigen::Vector3d::Zero();
    // The cylinder's centre in the body's frame from the centre of mass [m]
    // (planar: its x and y). Zero: at the centre of mass.
    Eigen::Vector3d center_body = Eigen::Vector3d::Zero();
  };
  // The body's natural coordinates per body: r_c and u (planar), r_c and
  // e1, e2, e3 (spatial).
  static constexpr int kMaxStride = 12;
  using Generalized = Eigen::Matrix<double, kMaxStride, 1>;
  using GeneralizedMatrix = Eigen::Matrix<double, kMaxStride, kMaxStride>;

  // `coord` the full index of the body's centre of mass, `dim` 2 or 3.
  BodyFluidLoad(const Params& p, int coord, int dim);

  int coord() const { return coord_; }
  int dim() const { return dim_; }
  double waterplane_area() const { return area_; }

  // The unit direction the loads split along at q: the vertical, or the
  // part's axis R a_b (along_axis).
  Eigen::Vector3d Axis(const Eigen::VectorXd& q) const;

  // The submerged length s(z) [m] at the centre's height z above a level.
  double Submerged(double z) const;
  // The body's height above the still level [m] at full configuration q.
  double Height(const Eigen::VectorXd& q) const;

  // The added-mass matrix T^T (rho V_ref C_a) T on the body's stride()
  // natural coordinates (top left; [kg] on r_c), for the body at full
  // configuration q0. Without an offset only its D x D top left block is
  // nonzero.
  GeneralizedMatrix AddedMass(const Eigen::VectorXd& q0) const;

  // F_s (times `scale`, the load factor) into `force` (full, as T^T F_s);
  // its tangent at the part's centre, scale * rho g A up up^T, into
  // `stiffness` (D x D, may be null: Spread maps it onto the body). Returns
  // |F_s|.
  double AddHydrostatic(const Eigen::VectorXd& q, double scale, Eigen::VectorXd* force,
                        Eigen::Matrix3d* stiffness) const;
  // U_s [J], times `scale`.
  double HydrostaticEnergy(const Eigen::VectorXd& q, double scale) const;

  // F_d + F_i + F_w [N] at the part's centre at time t [s] under `waves`
  // (null: none), and C [N s/m] (in that point's velocity) into `damping`
  // when not null; Spread maps both onto the body.
  Eigen::Vector3d DynamicForce(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, double t,
                               const WaveField* waves, Eigen::Matrix3d* damping) const;

  // Whether the part's centre is off the centre of mass (T is not [I 0]).
  bool has_offset() const { return has_offset_; }
  // T x_b: the part's centre [m] from the full configuration x = q, or its
  // velocity [m/s] from x = qdot (zero beyond dim).
  Eigen::Vector3d MapPoint(const Eigen::VectorXd& x) const;
  // T^T f: a force at the part's centre as a generalised force on the
  // body's stride() coordinates (the rest zero).
  Generalized Spread(const Eigen::Vector3d& f) const;
  // T^T c T: a tangent at the part's centre on the body's coordinates.
  GeneralizedMatrix Spread(const Eigen::Matrix3d& c) const;
  // The body's side of a force f [N] at the part's centre, whichever T:
  // T^T f added to `full`; kSumRounding |T|^T `size` (the size of each
  // term summed into f, per direction) to `roundoff`; scale T^T k T (k the
  // D x D tangent at the centre) scattered into `matrix` through `map`.
  // Without an offset each touches only r_c's D entries, as a force on the
  // centre of mass does.
  void AddForce(const Eigen::Vector3d& f, Eigen::VectorXd* full) const;
  void AddRounding(const Eigen::Vector3d& size, Eigen::VectorXd* roundoff) const;
  void ScatterTangent(const Eigen::Matrix3d& k, const CoordinateMap& map, double scale,
                      SkylineLdlt* matrix) const;
  // F_a and M_a as generalised forces on the body's stride() natural
  // coordinates into `force`, their tangent into `damping` when not null
  // (stride x stride, top left). Zero without drag areas.
  void AreaDrag(const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, double t,
                const WaveField* waves, Generalized* force, GeneralizedMatrix* damping) const;
  bool has_area_drag() const {
    return !p_.drag_area.isZero(0) || !p_.rotational_drag_area.isZero(0);
  }
  int stride() const { return dim_ == 2 ? 4 : 12; }
  // Whether DynamicForce or AreaDrag can be nonzero (drag, or a flow that
  // accelerates).
  bool dynamic(bool has_waves) const;

 private:
  Params p_;
  int coord_ = 0, dim_ = 3;
  double area_ = 0;
  bool has_offset_ = false;
  // T (dim x stride, the rest zero).
  Eigen::Matrix<double, 3, kMaxStride> t_ = Eigen::Matrix<double, 3, kMaxStride>::Zero();
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();  // zero beyond dim
};

// Every fluid-loaded body of a scene as one ForceContributor: F_s as an
// applied load (scaled with gravity by the load factor; U_s in the loads'
// energy), F_d + F_i + F_w as the dissipative part (its power in the
// damping power).
class BodyFluidForces : public ForceContributor {
 public:
  explicit BodyFluidForces(std::vector<BodyFluidLoad> loads) : loads_(std::move(loads)) {}

  const std::vector<BodyFluidLoad>& loads() const { return loads_; }

  std::string_view name() const override { return "body_fluid"; }
  void AddAppliedLoad(const ForceState& s, ForceOutput* out) const override;
  void AddDissipative(const ForceState& s, ForceOutput* out) const override;
  double StoredEnergy(const ForceState& s) const override;
  void AddDissipatedPower(const ForceState& s, double* power) const override;
  // Whether any body's DynamicForce can be nonzero (`has_waves`: the scene
  // has waves).
  bool dynamic(bool has_waves) const;
  bool dissipates() const override { return dissipates_; }
  void set_dissipates(bool d) { dissipates_ = d; }

 private:
  std::vector<BodyFluidLoad> loads_;
  bool dissipates_ = false;
};

// The contributor for the scene's bodies with hydrodynamics (in a fluid;
// a cylinder's buoyancy and vertical need gravity, SceneFromProto checks),
// one BodyFluidLoad per part in body order, or null when none has any. `body_coord[b]`: body b's
// first full coordinate; `has_waves`: the model built a wave field.
std::unique_ptr<BodyFluidForces> MakeBodyFluidForces(const Scene& scene,
                                                     const std::vector<int>& body_coord, int dim,
                                                     bool has_waves);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_BODY_FLUID_LOAD_H_
