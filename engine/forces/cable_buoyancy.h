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
// position (free_surface.h says how Newton takes the switch). Its
// potential is U = rho_f A |g| int max(h - eta, 0) dx [J] (continuous; the
// force -dU/dq is piecewise constant, its Jacobian zero on either side, so
// it adds nothing to the Newton matrix). In DYNAMIC runs eta is the waves'
// elevation at the point's horizontal position and the time (the change of
// U with eta at fixed q, the waves' work on it, is not counted in the
// energy, as the waves' drag work is: energy.damped); in STATIC it is 0
// (the still level). Scaled by the load factor with gravity (statics ramp
// them together), in the loads' energy bucket.
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

 private:
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
