#ifndef CABLESIM_ENGINE_FORCES_CABLE_ADDED_MASS_H_
#define CABLESIM_ENGINE_FORCES_CABLE_ADDED_MASS_H_

// The cables' added mass where it is not the constant mass matrix's: along
// and across the line separately (MoorDyn's Ca and CaAx), and none above
// the free surface (engine/forces/free_surface.h).
//
// The fluid a line accelerates through adds, per unit length, the mass
//
//   m_a = rho_f A (C_a P + C_a,ax t t^T)   [kg/m],  P = I - t t^T,
//
// t the unit tangent, A the displaced area (Morison et al. 1950; the split
// along and across a slender line as Hall and Goupee 2015, section 2,
// and MoorDyn's line model), and none where the line is out of the water.
// The model's mass matrix is constant and holds the isotropic part
// rho_f A C_a I (ModelBuilder); this term adds the rest,
//
//   D = m_a - rho_f A C_a I = rho_f A (C_a,ax - C_a) t t^T       (wet)
//                           = -rho_f A C_a I                      (dry)
//
// as the inertia force f = -int S^T D S qdd dx [N] on the element's
// coordinate accelerations qdd (AncfCableElement::AddDirectionalMass),
// with its acceleration derivative int S^T D S dx [kg] for the Newton
// matrix, where it joins the mass matrix (M + int S^T D S dx is the
// consistent mass of m I + m_a: positive definite). Newton's matrix leaves
// out the derivative of D through t in the positions (of relative size
// s |qdd| |C_a,ax - C_a| rho_f A / (mu |r'| (1 + ...)) per step, s = beta h^2:
// small for the accelerations of moorings), as the damping's C'(q) qdot is
// left out. The wet or dry switch is point-wise, as free_surface.h says.
//
// The flow's own acceleration (waves) is in WaveLoad with the same split.
// Only the alpha-family steppers (GENERALIZED_ALPHA, HHT) take this term
// (ModelBuilder::CheckIntegratorFits refuses the others): they solve for
// the accelerations, so an acceleration-dependent force joins their
// residual as the mass does. The kinetic energy reported is 1/2 qdot^T
// (M + int S^T D S dx) qdot (engine/model/model_outputs.cc). The inertia
// force's power, -qdot^T (int S^T D S dx) qdd, leaves out the rate of D
// (t turning, a point crossing the surface): the energy balance carries
// 1/2 qdot^T Ddot qdot, as a line's energy does in MoorDyn's lumped model.
//
// Tip loads (Hydrodynamics.start_tip, end_tip): an added mass m [kg]
// along the unit tangent t at a cable's first or last node (MoorDyn's rod
// of zero length), D_tip = m t t^T on the node's position coordinates
// while the node is under the surface: force -m t t^T a, and m t t^T
// joins the Newton matrix (the derivative through t left out, as above).
//
// Units SI. Allocates nothing.

#include <memory>
#include <vector>

#include "engine/elements/ancf_cable_element.h"
#include "engine/forces/free_surface.h"
#include "engine/forces/waves.h"

namespace cablesim {

class CableAddedMass {
 public:
  struct Element {
    double displaced_kg_m = 0;  // rho_f A [kg/m]
    double added_mass = 0;      // C_a, across (and in the mass matrix) [-]
    double axial_added_mass = 0;  // C_a,ax [-]
    // The tip added mass at the element's first [0] and last [1] node [kg].
    double tip_mass[2] = {0, 0};
    bool distributed(bool surface) const {
      return displaced_kg_m != 0 &&
             (axial_added_mass != added_mass || (surface && added_mass != 0));
    }
    bool any(bool surface) const {
      return distributed(surface) || tip_mass[0] != 0 || tip_mass[1] != 0;
    }
  };
  // Per element of the model, in its order; `waves` the wave field whose
  // elevation is the surface (null: the still level).
  CableAddedMass(std::vector<Element> elements, const FreeSurface& surface,
                 const WaveField* waves)
      : elements_(std::move(elements)), surface_(surface), waves_(waves) {}

  bool ActsOn(int index) const { return elements_[index].any(surface_.enabled); }

  // Element `index` at coordinates e and accelerations edd, time t [s]:
  // adds -int S^T D S edd dx to `force` and, when `m` is not null,
  // int S^T D S dx to it.
  template <int D>
  void Add(const AncfCableElement<D>& element, int index,
           const typename AncfCableElement<D>::Coords& e,
           const typename AncfCableElement<D>::Coords& edd, double t,
           typename AncfCableElement<D>::Coords* force,
           typename AncfCableElement<D>::Matrix* m) const;
  // The kinetic energy of that added mass, 1/2 edot^T (int S^T D S dx)
  // edot (tip masses included) at coordinates e and velocities edot [J]:
  // Add's quadrature, without its force.
  template <int D>
  double KineticEnergy(const AncfCableElement<D>& element, int index,
                       const typename AncfCableElement<D>::Coords& e,
                       const typename AncfCableElement<D>::Coords& edot, double t) const;

 private:
  // a_n, a_t of AncfCableElement::AddDirectionalMass at the element's
  // Gauss points (D split across and along; the dry points lose their
  // whole added mass).
  template <int D>
  void PointMasses(const AncfCableElement<D>& element, const Element& p,
                   const typename AncfCableElement<D>::Coords& e, double t, double* a_n,
                   double* a_t) const;

  std::vector<Element> elements_;
  FreeSurface surface_;
  const WaveField* waves_;
};

// Null when no element needs it.
std::unique_ptr<CableAddedMass> MakeCableAddedMass(std::vector<CableAddedMass::Element> elements,
                                                   const FreeSurface& surface,
                                                   const WaveField* waves);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_CABLE_ADDED_MASS_H_
