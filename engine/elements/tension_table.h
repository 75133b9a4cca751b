#ifndef CABLESIM_ENGINE_ELEMENTS_TENSION_TABLE_H_
#define CABLESIM_ENGINE_ELEMENTS_TENSION_TABLE_H_

// A tension-strain table (AxialLaw::kTable; MoorDyn's nonlinear line
// types): the tension T(e) [N] piecewise linear in the engineering strain
// e = |r'| - 1 through the knots (e_k, T_k), with e_0 = 0 and T_0 = 0.
//
//   e in [e_k, e_k+1]:  T = T_k + k_k (e - e_k),  k_k = (T_k+1 - T_k) / (e_k+1 - e_k)
//   e > e_last:         the last segment continued (slope k_last)
//   e < 0:              the first segment continued, T = k_0 e (compression
//                       pushes as under ENGINEERING, so that a one-segment
//                       table is ENGINEERING with EA = k_0)
//
// The stiffness dT/de is the segment's slope (the right one at a knot), the
// strain energy per unit undeformed length W(e) = int_0^e T de is exact
// (a sum of trapezoids), and MeanTension gives the exact difference
// quotient (W(e1) - W(e0)) / (e1 - e0) without the cancellation of that
// formula (the energy-momentum stepper's discrete gradient).
//
// The knots are validated by convert/ (strains increasing from 0, tensions
// non-decreasing from 0, so every slope is >= 0 and T is monotone).

#include <vector>

namespace cablesim {

class TensionTable {
 public:
  struct Value {
    double tension = 0;    // T(e) [N]
    double stiffness = 0;  // dT/de [N]
  };

  TensionTable() = default;
  // strains[0] = 0 < strains[1] < ..., tensions[0] = 0, at least two knots.
  TensionTable(std::vector<double> strains, std::vector<double> tensions);

  Value At(double e) const;
  // W(e) = int_0^e T de [J/m].
  double Energy(double e) const;
  // (W(e1) - W(e0)) / (e1 - e0), T(e0) when e1 == e0 [N].
  double MeanTension(double e0, double e1) const;
  // The largest slope [N]: the stiffest the line gets.
  double max_stiffness() const { return max_stiffness_; }

 private:
  // The segment whose law holds at e (0 below the first knot, the last
  // beyond the last one).
  int Segment(double e) const;

  std::vector<double> strain_, tension_, slope_, energy_;  // energy_[k] = W(e_k)
  double max_stiffness_ = 0;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_TENSION_TABLE_H_
