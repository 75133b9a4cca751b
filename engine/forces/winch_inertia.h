#ifndef CABLESIM_ENGINE_FORCES_WINCH_INERTIA_H_
#define CABLESIM_ENGINE_FORCES_WINCH_INERTIA_H_

// The inertia of an ANCF cable element on a winch's axially moving
// (arbitrary Lagrangian-Eulerian) mesh (docs/model.md, "Winches").
//
// A winch cable of free length L(t) [m] is cut into N equal elements of
// length l(t) = L(t) / N; its material coordinate s in [0, L] is measured
// from the payload end (s = 0, where the material stays) and the winch
// holds s = L. Element k (k = 0 at the payload) covers s in [k l, (k + 1) l]
// with xi = s / l - k, so at fixed material s the element coordinate moves,
// dxi/dt = -(xi + k) ldot / l, and the material velocity of
// r = sum_a s_a(xi; l) e_a (scene coordinates: nodal positions and slopes
// dr/ds, MODEL.md section 1) is
//
//   v = dr/dt|_s = S edot + ldot W e,   W = dS/dl - (xi + k) S',
//
// S' = dS/dx the slope shape functions (dS/dl: the l factor of the slope
// functions s_2, s_4). The kinetic energy of the element's material
// T = 1/2 int_0^l mu |v|^2 dx (mu = rho A [kg/m]) is then
//
//   T = 1/2 edot^T M edot + ldot edot^T G e + 1/2 ldot^2 e^T H e,
//   M = mu l int S^T S dxi,  G = mu l int S^T W dxi,  H = mu l int W^T W dxi,
//
// and Lagrange's equations of the material in [0, L] give
//
//   M eddot + [Mdot + ldot (G - G^T)] edot + [d(ldot G)/dt - ldot^2 H] e
//     + (elastic and applied forces at the reference length l) = 0,
//
// with Mdot = ldot dM/dl and d(ldot G)/dt = lddot G + ldot^2 dG/dl. The
// open-system equations (Irschik and Holl, Appl. Mech. Rev. 57:145-160,
// 2004, the momentum flux term of their Lagrange equations) add a term
// int over the outflow section of (dr/dq) . (flux): at s = L,
// dr/dq is non-zero only on the winch node's position, which the winch
// holds (fixed or prescribed), so the term changes the winch's reaction
// and not the motion. tests/winch_inertia_test.cc checks both: the
// velocity W reproduces a rigid reel-in exactly, and the assembled
// convective force vanishes on every coordinate but the winch node's
// position for a straight cable reeled in at constant speed.
//
// All matrices are 4 x 4 per spatial component (Kronecker product with
// I_D), in kg (M, and G ldot), kg/m (dM/dl), etc.; computed by 5-point
// Gauss quadrature, exact for their degree-6 polynomial integrands.

#include <Eigen/Core>

#include "engine/scene/time_function.h"

namespace cablesim {

// A winch's free length in time: L(t) = L(0) + int_0^t speed, with its
// rate and acceleration (what the model's elements and the winch's
// contributors evaluate at SetTime).
struct WinchReel {
  double length0 = 0;  // L(0) [m]
  TimeFunction speed;  // Ldot(t) [m/s]
  struct State {
    double length = 0, rate = 0, accel = 0;  // L [m], Ldot [m/s], Lddot [m/s^2]
  };
  State At(double t) const {
    const TimeFunction::Value v = speed.Evaluate(t);
    return State{length0 + speed.Integral(t), v.f, v.df};
  }
};

struct WinchElementInertia {
  Eigen::Matrix4d m, m_l;  // M and dM/dl
  Eigen::Matrix4d g, g_l;  // G and dG/dl
  Eigen::Matrix4d h;       // H
};

// The matrices of element k (0 at the payload end) of length l [m] for mass
// per length mu [kg/m].
WinchElementInertia ComputeWinchElementInertia(double mu, double l, int k);

// The convective force's coefficients, Q = -cv edot - ce e (per component),
// for length rate ldot [m/s] and its rate lddot [m/s^2]:
//   cv = ldot (dM/dl + G - G^T),  ce = lddot G + ldot^2 (dG/dl - H).
void WinchConvectiveCoefficients(const WinchElementInertia& in, double ldot, double lddot,
                                 Eigen::Matrix4d* cv, Eigen::Matrix4d* ce);

// The slope's share of the material velocity: d(r_s)/dt|_s =
// S' edot + ldot W' e with W' = dW/dx = -(1/l) [S'_0, 0, S'_2, 0] -
// (xi + k) S'' (the position functions' entries of S' = dS/dx, S'' =
// d^2S/dx^2), per component. A winch cable's Kelvin-Voigt damping takes
// the material strain rate u . d(r_s)/dt|_s from it (the nodes move
// through the material, so S' edot alone would see a reel-in as a
// compression). `wd` receives W' at xi for element k of length l.
void WinchSlopeRateShape(double xi, double l, int k, double wd[4]);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_FORCES_WINCH_INERTIA_H_
