#ifndef CABLESIM_ENGINE_FORCES_WINCH_CABLES_H_
#define CABLESIM_ENGINE_FORCES_WINCH_CABLES_H_

// A winch cable's forces beyond its elements' own (docs/model.md,
// "Winches"), as one ForceContributor over every winch of a scene:
//
//  - the convective inertia of the axially moving mesh (winch_inertia.h):
//    Q = -cv edot - ce e per element, cv = ldot (dM/dl + G - G^T),
//    ce = lddot G + ldot^2 (dG/dl - H), evaluated at L(t) / N (SetTime).
//    It is not dissipation (AddDissipatedPower leaves it out), but it
//    depends on the rates, so it rides with the velocity-dependent forces
//    (AddDissipative, which every stepper calls). Its rate tangent in the
//    Newton matrix is Mdot = ldot dM/dl, the symmetric part of cv; the skew
//    ldot (G - G^T) and the small position term ce are left out;
//  - damping on the material motion: Rayleigh alpha as
//    -alpha int mu S^T v dx (v = S edot + ldot W e the material velocity,
//    so a rigid reel-in is damped as any motion through still air would
//    be), and Kelvin-Voigt axial damping on the material strain rate
//    (WinchSlopeRateShape); its power alpha int mu |v|^2 + int c rate^2
//    >= 0. Bending damping is refused on winch cables (the model
//    builder's CheckWinches), and the elements' own damping cleared there;
//  - Morison drag on the material's velocity relative to the fluid (a
//    uniform current or a current profile; with a free surface on the
//    Gauss points under the still level only): at each Gauss point, v_r =
//    u(r) - v, v = S edot + ldot W e the material velocity, split along
//    the tangent t = r' / |r'| and across it, q = kn |v_n| v_n + kt |v_t|
//    v_t [N/m] (the coefficients of AncfCableElement::AddDrag), Q = int S^T
//    q dx (the virtual work of q on the material, whose virtual
//    displacement at fixed time is S de). Its power -int q . v dx goes to
//    energy.damped (the current's work with it, as the ordinary cables'
//    drag); its velocity tangent is AddDrag's (dv/d(edot) = S). The
//    elements' own drag (CableFluidLoad, on the mesh's velocity) is left
//    out for winch cables; drag in waves is refused there.
//
// What stays in the model: the winch cables' elements (their length
// L(t) / N) and their mass matrices in the model's mass matrix, which
// every stepper factors (a mass that changes with time is the model's,
// not a force); their gravity is GravityLoads' (gravity_loads.h).

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/forces/current_profile.h"
#include "engine/forces/force_contributor.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/winch_inertia.h"

namespace cablesim {

template <int D>
class WinchCables : public ForceContributor {
 public:
  static constexpr int kN = 4 * D;
  using Coords = Eigen::Matrix<double, kN, 1>;
  using Matrix = Eigen::Matrix<double, kN, kN>;
  // An element of a winch cable: its first full coordinate.
  struct Element {
    int first_coord = 0;
  };
  struct Winch {
    WinchReel reel;
    double mass_per_length = 0;  // rho A [kg/m]
    double ea = 0;               // [N]
    double axial_damping_s = 0, alpha_1_s = 0;
    // Drag: kn = rho C_dn d / 2, kt = rho C_dt pi d / 2 [kg/m^2], the
    // fluid's velocity (the profile's at the point when it has one), where
    // the water ends.
    double drag_n = 0, drag_t = 0;
    Eigen::Vector3d current = Eigen::Vector3d::Zero();
    CurrentProfile profile;
    FreeSurface surface;
    std::vector<Element> elements;  // from the payload end (k = 0)
  };

  explicit WinchCables(std::vector<Winch> winches);

  std::string_view name() const override { return "winch_cables"; }
  bool time_dependent() const override { return true; }
  void SetTime(double t) override;
  bool dissipates() const override { return true; }
  void AddDissipative(const ForceState& s, ForceOutput* out) const override;
  void AddDissipatedPower(const ForceState& s, double* power) const override;
  // What the reel feeds in through the moving mesh, per element:
  // f . edot + 1/2 edot^T Mdot edot + P_d, f = -cv edot - ce e + f_d this
  // contributor's force, Mdot = ldot dM/dl the rate of the model's mass
  // (whose kinetic energy 1/2 edot^T M(t) edot the model reports) and P_d
  // the damping's power (energy.damped's share): with the skew part of cv
  // dropping out, -1/2 edot^T Mdot edot - edot^T ce e + (f_d . edot + P_d)
  // (MultibodyModel::ExternalPower has the derivation).
  void AddExternalPower(const ForceState& s, double* power) const override;

 private:
  // Per element at the time of SetTime: the scalar mass matrix and the
  // convective coefficients (4 x 4 per component).
  struct Now {
    Eigen::Matrix4d mbar, cv, ce, mdot, g, h;
  };
  // Element k of winch w's damping on the material motion: adds the force
  // to `fe` and its edot-derivative to `ce` (either may be null); returns
  // the dissipated power [W], >= 0.
  double Damping(const Winch& w, const WinchReel::State& now, int k, const Now& at,
                 const Eigen::VectorXd& q, const Eigen::VectorXd& qdot, Coords* fe,
                 Matrix* ce) const;

  std::vector<Winch> winches_;
  std::vector<WinchReel::State> state_;  // per winch
  std::vector<Now> now_;                  // per element, winch by winch
};

// The contributor, or null without winches.
template <int D>
std::unique_ptr<ForceContributor> MakeWinchCables(std::vector<typename WinchCables<D>::Winch> winches);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_WINCH_CABLES_H_
