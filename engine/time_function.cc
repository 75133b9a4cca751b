#include "engine/time_function.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cablesim {

TimeFunction TimeFunction::Constant(double c) {
  TimeFunction f;
  f.set_constant(c);
  return f;
}

TimeFunction TimeFunction::Table(std::vector<double> times, std::vector<double> values) {
  TimeFunction f;
  f.set_table(std::move(times), std::move(values));
  return f;
}

TimeFunction TimeFunction::Sine(double amplitude, double frequency_hz, double phase_rad) {
  TimeFunction f;
  f.add_harmonic({amplitude, frequency_hz, phase_rad});
  return f;
}

TimeFunction TimeFunction::Linear(double slope, double start_s) {
  TimeFunction f;
  f.add_ramp({slope, start_s});
  return f;
}

void TimeFunction::set_table(std::vector<double> times, std::vector<double> values) {
  times_ = std::move(times);
  values_ = std::move(values);
}

void TimeFunction::add_term(TimeFunction f) {
  if (!f.IsZero()) terms_.push_back(std::move(f));
}

bool TimeFunction::IsZero() const {
  if (constant_ != 0) return false;
  for (double v : values_)
    if (v != 0) return false;
  for (const Harmonic& h : harmonics_)
    if (h.amplitude != 0) return false;
  for (const Ramp& r : ramps_)
    if (r.slope != 0) return false;
  for (const TimeFunction& f : terms_)
    if (!f.IsZero()) return false;
  return true;
}

TimeFunction::Value TimeFunction::Evaluate(double t) const {
  Value v;
  v.f = constant_;
  if (!values_.empty()) {
    const size_t n = times_.size();
    if (n == 1 || t < times_.front()) {
      v.f += values_.front();
    } else if (t >= times_.back()) {
      v.f += values_.back();
    } else {
      // The segment [t_k, t_{k+1}) holding t (right derivative at t_k).
      const size_t k = static_cast<size_t>(
          std::upper_bound(times_.begin(), times_.end(), t) - times_.begin()) - 1;
      const double slope = (values_[k + 1] - values_[k]) / (times_[k + 1] - times_[k]);
      v.f += values_[k] + slope * (t - times_[k]);
      v.df += slope;
    }
  }
  constexpr double kTwoPi = 6.283185307179586;
  for (const Harmonic& h : harmonics_) {
    const double w = kTwoPi * h.frequency_hz, arg = w * t + h.phase_rad;
    const double s = std::sin(arg), c = std::cos(arg);
    v.f += h.amplitude * s;
    v.df += h.amplitude * w * c;
    v.ddf -= h.amplitude * w * w * s;
  }
  for (const Ramp& r : ramps_) {
    if (t >= r.start_s) {
      v.f += r.slope * (t - r.start_s);
      v.df += r.slope;
    }
  }
  for (const TimeFunction& f : terms_) {
    const Value u = f.Evaluate(t);
    v.f += u.f;
    v.df += u.df;
    v.ddf += u.ddf;
  }
  return v;
}

}  // namespace cablesim
