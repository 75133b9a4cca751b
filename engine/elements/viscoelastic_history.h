#ifndef CABLESIM_ENGINE_ELEMENTS_VISCOELASTIC_HISTORY_H_
#define CABLESIM_ENGINE_ELEMENTS_VISCOELASTIC_HISTORY_H_

// The viscoelastic axial law (AxialLaw::kViscoelastic; MoorDyn's
// viscoelastic line types, after Hall et al., "Viscoelastic mooring line
// model for MoorDyn", IOWTC2023-110827) and its state at every Gauss point
// of the cables that use it.
//
// In the engineering strain e, a line section is two Kelvin-Voigt elements
// in series: a spring EA_1 beside a dashpot BA (the slow part, strain e_1)
// and a spring EA_2 beside a dashpot BA_D (the fast part, strain e - e_1).
// Both carry the tension [N]:
//
//   T = EA_1 e_1 + BA de_1/dt = EA_2 (e - e_1) + BA_D (de/dt - de_1/dt),
//
// so  (BA + BA_D) de_1/dt = EA_2 e - (EA_1 + EA_2) e_1 + BA_D de/dt.   (1)
//
// Held long enough the dashpots rest: T = EA e with the static stiffness
// EA = EA_1 EA_2 / (EA_1 + EA_2); fast, BA locks and the stiffness is the
// dynamic EA_2 (> EA). EA_2 is a constant, or the mean-load law
// EA_2 = a + beta T_m of the rope standards (T_m = EA_1 e_1, the slow part's
// tension, taken at the step's start), solved for EA_2 with
// EA_1 = EA_2 EA / (EA_2 - EA):
//
//   EA_2 = (s + sqrt(s^2 - 4 a EA)) / 2,   s = a + EA + beta EA e_1
//
// (a when e_1 < 0), as MoorDyn does.
//
// Over a step from t_n (state e^n, e_1^n) to t = t_n + tau, e(t') is taken
// linear in time, and (1) is integrated exactly for it: with
// B = BA + BA_D, lambda = (EA_1 + EA_2) / B, r = (e - e^n) / tau,
// phi = (1 - exp(-lambda tau)) / lambda, psi = (tau - phi) / lambda,
//
//   e_1 = e_1^n exp(-lambda tau) + (EA_2 e^n phi + (BA_D phi + EA_2 psi) r) / B,
//   T   = EA_1 e_1 + BA/B (EA_2 e - (EA_1 + EA_2) e_1 + BA_D r),
//
// both affine in the step's end strain e: e_1 = c0 + c1 e and T = k e + p.
// Exact for a strain linear in time, unconditionally stable, second order
// in tau, and free of the step's size otherwise (a rejected step, a
// stepper's stage at t_n + c h, a frame inside the step all evaluate the
// same formula at their tau). The element reads (k, p) per Gauss point as
// a tension and its slope, the way it reads a tension-strain table; the
// model commits the state after each accepted step.
//
// The stored energy is EA_1 e_1^2 / 2 + EA_2 (e - e_1)^2 / 2 per unit
// length; the dashpots dissipate BA (de_1/dt)^2 + BA_D (de/dt - de_1/dt)^2
// (energy.damped), with de_1/dt from (1).
//
// Before a dynamic run starts (statics, modal analysis) the law is the
// relaxed one, T = EA e; a run starts with the dashpots at rest,
// e_1 = EA_2 / (EA_1 + EA_2) e (the static split of the strain; under the
// mean-load law T_m is then EA e, so EA_2 = a + beta EA e).
//
// Units: SI; stiffnesses EA [N], dashpots BA [N s], strains [-].

#include <vector>

namespace cablesim {

class ViscoelasticHistory {
 public:
  struct Law {
    double ea_static_n = 0;
    double ea_dynamic_n = 0;  // > ea_static_n; 0: the mean-load law
    double ea_base_n = 0;     // a of the mean-load law (> ea_static_n)
    double ea_slope = 0;      // beta of the mean-load law [-]
    double damping_static_ns = 0;   // BA
    double damping_dynamic_ns = 0;  // BA_D
  };
  // What the element reads per Gauss point.
  struct Coefficients {
    double k = 0, p = 0;    // T = k e + p [N]
    double c0 = 0, c1 = 0;  // e_1 = c0 + c1 e
    double ea1 = 0, ea2 = 0;
    // The step's start strain e^n and length tau [s] (tau <= 0: at the
    // committed state): the strain rate the law sees is (e - e^n) / tau.
    double e_start = 0, tau = 0;
  };

  // Adds `gauss_points` points of one element of a cable with law `law`;
  // returns the index of its first point. Their coefficients start relaxed.
  int AddElement(const Law& law, int gauss_points);
  int points() const { return static_cast<int>(point_law_.size()); }
  const Coefficients* coefficients(int first_point) const { return &coef_[first_point]; }

  // The relaxed law T = EA e at every point (statics, modal analysis).
  void Relax();
  // A run starts at time t with the engineering strains `strains` (one per
  // point, in the order of AddElement): dashpots at rest.
  void Start(const std::vector<double>& strains, double t);
  bool started() const { return started_; }
  // Coefficients of a state at time t of the step from the committed one.
  // Within 1e-9 of the last committed step after the committed time (a
  // frame at it, a stepper restarted there) the last step's stay: they
  // give the committed state's tension with its strain rate, where a
  // step of length ~0 would divide the fast dashpot's share by ~0.
  void SetTime(double t);
  // The step to time t is accepted with `strains`: it becomes the state
  // steps start from. The coefficients stay those of the last SetTime.
  // With the mean-load law the stiffnesses then move to the new e_1, and
  // with them the springs' stored energy at the same strains: that change
  // per point [J/m] goes into (*energy_jump)[point] (0 under a constant
  // EA_2). The law has no potential that would account for it; the model
  // counts it as external work, as it counts a winch's.
  void Commit(const std::vector<double>& strains, double t, std::vector<double>* energy_jump);

  // The dissipated power per unit length [W/m] at a point at strain e,
  // with the strain rate the step's law sees, (e - e^n) / tau (0 at the
  // committed state itself, tau <= 0, as the law's tension there), and
  // de_1/dt from (1): the power of the tension the law gives, so that
  // energy.damped matches the work the supports do through it (with the
  // material rate at the step's end instead, a line pulled from rest
  // gained energy in its first steps, and one started at a speed in its
  // first).
  double DissipatedPower(int point, double e) const;
  // Stored energy per unit length [J/m] at a point.
  double StoredEnergy(int point, double e) const;

  // The dynamic stiffness EA_2 [N] of `law` when the slow part is at
  // strain e1, and EA_1 from it.
  static double DynamicStiffness(const Law& law, double e1);
  static double SlowStiffness(const Law& law, double ea2) {
    return ea2 * law.ea_static_n / (ea2 - law.ea_static_n);
  }
  // The coefficients over a step of length tau [s] (tau <= 0: at the
  // committed state, with its strain rate taken as 0).
  static Coefficients StepCoefficients(const Law& law, double ea1, double ea2, double e_n,
                                       double e1_n, double tau_s);

 private:
  std::vector<Law> laws_;
  std::vector<int> point_law_;
  std::vector<Coefficients> coef_;
  // The committed state per point: e^n, e_1^n, and EA_1, EA_2 for the step.
  std::vector<double> e_n_, e1_n_, ea1_, ea2_;
  double t_n_ = 0;
  double last_step_s_ = 0;  // the last committed step's length
  bool started_ = false;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_VISCOELASTIC_HISTORY_H_
