#ifndef CABLESIM_ENGINE_SCENE_TIME_FUNCTION_H_
#define CABLESIM_ENGINE_SCENE_TIME_FUNCTION_H_

// A scalar function of time f(t) for prescribed motions and time-varying
// loads (free of protobuf; convert/ builds it from cablesim.v1.TimeFunction).
// Its value is the sum of its parts:
//
//   constant     c
//   table        piecewise linear through (t_k, y_k), t_k increasing; y_0
//                before t_0 and y_last after the last time
//   harmonic     A sin(2 pi f t + phi)         (A, f [Hz], phi [rad])
//   ramp         m max(0, t - t_0)              (m per second, from t_0 [s])
//   sum          the sum of further TimeFunctions
//   product      the product of further TimeFunctions (a ramp in times a
//                harmonic), with (fg)' = f'g + fg' and
//                (fg)'' = f''g + 2f'g' + fg'' over its factors
//
// Evaluate() returns the value and its first and second derivatives exactly.
// A table (and a ramp at t_0) has a kink: there the derivative is that of
// the segment that starts at t (the right derivative), so it is piecewise
// constant, and the second derivative is 0 everywhere (the Dirac impulses at
// the kinks are left out). A motion whose velocity jumps therefore starts
// without the impulse's acceleration: the stepper's constraint still moves
// the point exactly, and its multiplier carries the impulse over one step.
//
// Units are those of the quantity it gives (m, N, N m) per second^0.

#include <vector>

namespace cablesim {

class TimeFunction {
 public:
  struct Value {
    double f = 0;    // f(t)
    double df = 0;   // df/dt
    double ddf = 0;  // d^2f/dt^2
  };
  struct Harmonic {
    double amplitude = 0;
    double frequency_hz = 0;
    double phase_rad = 0;
  };
  struct Ramp {
    double slope = 0;    // per second
    double start_s = 0;  // t_0
  };

  // The zero function.
  TimeFunction() = default;
  static TimeFunction Constant(double c);
  static TimeFunction Table(std::vector<double> times, std::vector<double> values);
  static TimeFunction Sine(double amplitude, double frequency_hz, double phase_rad);
  static TimeFunction Linear(double slope, double start_s);

  // Parts (each adds to the value).
  void set_constant(double c) { constant_ = c; }
  // times increasing (convert/ validates), same size as values, >= 1.
  void set_table(std::vector<double> times, std::vector<double> values);
  void add_harmonic(const Harmonic& h) { harmonics_.push_back(h); }
  void add_ramp(const Ramp& r) { ramps_.push_back(r); }
  void add_term(TimeFunction f);
  // A product of `factors` added to the value (none: nothing added).
  void add_product(std::vector<TimeFunction> factors);
  // True when a product is part of it, here or in a term: Integral is then
  // not exact (see there).
  bool HasProduct() const;

  // True when every part is absent: the function is identically 0.
  bool IsZero() const;

  Value Evaluate(double t) const;
  // The integral int_0^t f(tau) dtau, exact for every part (a table's
  // segments by the trapezoidal rule, which is exact on them; a harmonic of
  // frequency 0 is the constant A sin(phi)). A winch's free length is its
  // initial length plus the integral of its pay-out speed (scene.h).
  // A product has no closed-form integral: it contributes NaN (convert/
  // refuses products where an integral is taken, a winch's speed).
  double Integral(double t) const;
  double operator()(double t) const { return Evaluate(t).f; }

 private:
  double constant_ = 0;
  std::vector<double> times_, values_;
  std::vector<Harmonic> harmonics_;
  std::vector<Ramp> ramps_;
  std::vector<TimeFunction> terms_;
  std::vector<std::vector<TimeFunction>> products_;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_TIME_FUNCTION_H_
