#ifndef CABLESIM_ENGINE_FORCES_CABLE_BUOYANCY_H_
#define CABLESIM_ENGINE_FORCES_CABLE_BUOYANCY_H_

// The buoyancy a cable loses above the free surface (the scene's
// fluid.free_surface; engine/forces/free_surface.h), as a ForceContributor.
//
// Gravity acts on every cable element with the weight per length less the
// displaced fluid's, (mu - rho_f A) g (GravityLoads: buoyancy rho_f A |g|
// [N/m] along up everywhere). With a free surface, a point above the
// instantaneous level (height h above the still level at or above the
// waves' elevation eta) displaces nothing, so this contributor gives the
// buoyancy back there: per unit undeformed length
//
//   q = -rho_f A |g| up   where h >= eta,   0 below        [N/m],
//
// integrated by the element's Gauss rule, each point wet or dry by its own
// position (free_surface.h says how Newton takes the switch), in DYNAMIC
// runs. Its
// potential is U = rho_f A |g| int max(h - eta, 0) dx [J] (continuous; the
// force -dU/dq is piecewise constant, its Jacobian zero on either side, so
// it adds nothing to the Newton matrix). In DYNAMIC runs eta is the waves'
// elevation at the point's horizontal position and the time (the change of
// U with eta at fixed q, the waves' work on it, is not counted in the
// energy, as the waves' drag work is: energy.damped); in STATIC it is 0
// (the still level). Scaled by the load factor with gravity (statics ramp
// them together), in the loads' energy bucket.
//
// STATIC (the still level): the section's own dry fraction instead. A
// circular section of radius R (the hydrodynamic diameter's half) whose
// centre is h above the level is dry over the fraction
//
//   g(u) = (acos(-u) + u sqrt(1 - u^2)) / pi,   u = clamp(h / R, -1, 1),
//
// of its area (the section taken level, whatever the line's inclination),
// so q = -rho_f A |g| g(u) up, U = rho_f A |g| int P(h) dx with P' = g
// (P = R G(u), G' = g, G(-1) = 0, in cable_buoyancy.cc; P = h once the
// section is out of the water). Why:
// the point-wise switch is a step in the height, with no stiffness on
// either side, and a line that floats (a float's section at the surface,
// MoorDyn's tripod.txt) has no equilibrium under it: Newton hopped between
// a point wet and dry for 500 iterations. g is continuous with a continuous
// derivative g' = 2 sqrt(1 - u^2) / (pi R), so the force has an
// equilibrium and the Newton matrix its exact tangent, rho_f A |g| g' up
// up^T over the sections that pierce the level (for a line through the
// level, rho_f |g| A / |dh/dx|, the waterplane stiffness). A level line
// floats at the draft where its wet fraction 1 - g is its density over the
// fluid's; a straight line through the level keeps the step's dry length
// exactly (int g dh over -R < h < R is R). Along an element, h(x) is the
// cubic of the position; the element is cut where h = -R and h = R (the
// roots of two cubics), each piece wholly out of the water gets two Gauss
// points (exact for the cubic), each piece piercing the level kBandPoints.
// Only a STATIC analysis uses the section's fraction: DYNAMIC keeps the
// point-wise switch, and so does the statics of solver.initial_state
// STATIC (the model its dynamics uses), so that run starts in its own
// model's equilibrium.
//
// On a winch cable (WinchReel) the elements' length is L(t) / N: SetTime
// sets it, so the Gauss points and weights follow the paid-out length, and
// AddExternalPower gives the explicit rate ldot dU/dl at fixed coordinates
// (the reel's share of the energy balance, as GravityLoads' for gravity).
//
// Units SI. Allocates nothing per call.

#include <memory>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/force_contributor.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/winch_inertia.h"

namespace cablesim {

template <int D>
class CableSurfaceBuoyancy : public ForceContributor {
 public:
  struct Element {
    int first_coord = 0;
    AncfCableElement<D> element;
    double buoyancy_n_m = 0;  // rho_f A |g| [N/m]
    double radius_m = 0;      // of the section that displaces the fluid
  };
  // A winch cable's elements [element_begin, element_end) (indices into
  // the element list) and its reel.
  struct Winch {
    int element_begin = 0, element_end = 0;
    WinchReel reel;
  };
  // `use_waves`: eta from the state's waves (DYNAMIC) rather than 0.
  CableSurfaceBuoyancy(std::vector<Element> elements, const FreeSurface& surface, bool use_waves,
                       std::vector<Winch> winches = {})
      : elements_(std::move(elements)),
        surface_(surface),
        use_waves_(use_waves),
        winches_(std::move(winches)) {
    SetTime(0);
  }

  std::string_view name() const override { return "free_surface"; }
  bool time_dependent() const override { return !winches_.empty(); }
  void SetTime(double t) override;
  void AddAppliedLoad(const ForceState& s, ForceOutput* out) const override;
  double StoredEnergy(const ForceState& s) const override;
  // The winch elements' ldot dU/dl at fixed coordinates [W].
  void AddExternalPower(const ForceState& s, double* power) const override;
  // STATIC: element k's load (the model's element order) at s, the
  // buoyancy its sections' dry fractions lose, into fe; false (fe
  // untouched) when it has none or the analysis is DYNAMIC. For the
  // outputs' section forces (MultibodyModel::ElementEndForces).
  bool StaticLoadOfElement(int k, const ForceState& s,
                           typename AncfCableElement<D>::Coords* fe) const;

 private:
  // STATIC: the quadrature points of an element's dry part at the still
  // level (see the file comment): xi = x / l, weight w l [m], the dry
  // fraction g of the section there, dg/dh [1/m] and the potential P(h)
  // [m] (U = rho_f A |g| sum weight P). Returns how many: two on each
  // piece wholly out of the water, kBandPoints on each piece where the
  // section pierces the level (up to 7 pieces between the ends and the
  // points where h = -R and h = R).
  static constexpr int kBandPoints = 8;
  static constexpr int kMaxDryPoints = 7 * kBandPoints;
  struct DryPoint {
    double xi = 0, weight = 0, fraction = 0, rate = 0, potential = 0;
  };
  int DryPoints(const Element& el, const AncfCableElement<D>& element,
                const Eigen::Matrix<double, 4 * D, 1>& e, DryPoint* points) const;
  // An element's STATIC load fe and its matrix -dfe/de into ke (may be
  // null); false when the element has no dry part.
  bool StaticElementLoad(const Element& el, const ForceState& s,
                         typename AncfCableElement<D>::Coords* fe,
                         typename AncfCableElement<D>::Matrix* ke) const;
  // One element's U / load factor [J] at its coordinates in s.
  double ElementEnergy(const ForceState& s, const Element& el,
                       const AncfCableElement<D>& element) const;

  std::vector<Element> elements_;
  FreeSurface surface_;
  bool use_waves_;
  std::vector<Winch> winches_;
};

// Null unless `surface` is enabled and some element has buoyancy.
template <int D>
std::unique_ptr<ForceContributor> MakeCableSurfaceBuoyancy(
    std::vector<typename CableSurfaceBuoyancy<D>::Element> elements, const FreeSurface& surface,
    bool use_waves, std::vector<typename CableSurfaceBuoyancy<D>::Winch> winches = {});

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CABLE_BUOYANCY_H_
