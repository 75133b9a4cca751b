#include "engine/scene/time_function.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

void TimeFunction::add_product(std::vector<TimeFunction> factors) {
  if (factors.empty()) return;
  for (const TimeFunction& f : factors)
    if (f.IsZero()) return;  // a zero factor: the product adds nothing
  products_.push_back(std::move(factors));
}

bool TimeFunction::HasProduct() const {
  if (!products_.empty()) return true;
  for (const TimeFunction& f : terms_)
    if (f.HasProduct()) return true;
  return false;
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
  return products_.empty();  // add_product keeps no product with a zero factor
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
  for (const std::vector<TimeFunction>& factors : products_) {
    // The product rule, one factor at a time: p <- p g, p' <- p' g + p g',
    // p'' <- p'' g + 2 p' g' + p g''.
    Value p{1, 0, 0};
    for (const TimeFunction& factor : factors) {
      const Value g = factor.Evaluate(t);
      p = {p.f * g.f, p.df * g.f + p.f * g.df, p.ddf * g.f + 2 * p.df * g.df + p.f * g.ddf};
    }
    v.f += p.f;
    v.df += p.df;
    v.ddf += p.ddf;
  }
  return v;
}

namespace {

// int_a^b of the table's function (values[0] before the first time, the
// last value after the last), a <= b.
double TableIntegral(const std::vector<double>& times, const std::vector<double>& values,
                     double a, double b) {
  const size_t n = times.size();
  auto value_at = [&](double t) {
    if (n == 1 || t <= times.front()) return values.front();
    if (t >= times.back()) return values.back();
    const size_t k = static_cast<size_t>(
        std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    return values[k] + (values[k + 1] - values[k]) * (t - times[k]) / (times[k + 1] - times[k]);
  };
  // Breakpoints inside (a, b), then the trapezoidal rule between them.
  double sum = 0, t0 = a, y0 = value_at(a);
  for (size_t k = 0; k < n; ++k) {
    if (times[k] <= a || times[k] >= b) continue;
    sum += 0.5 * (y0 + values[k]) * (times[k] - t0);
    t0 = times[k];
    y0 = values[k];
  }
  return sum + 0.5 * (y0 + value_at(b)) * (b - t0);
}

}  // namespace

double TimeFunction::Integral(double t) const {
  double sum = constant_ * t;
  if (!values_.empty()) {
    sum += t >= 0 ? TableIntegral(times_, values_, 0, t) : -TableIntegral(times_, values_, t, 0);
  }
  constexpr double kTwoPi = 6.283185307179586;
  for (const Harmonic& h : harmonics_) {
    const double w = kTwoPi * h.frequency_hz;
    if (w == 0) {
      sum += h.amplitude * std::sin(h.phase_rad) * t;
    } else {
      sum += h.amplitude / w * (std::cos(h.phase_rad) - std::cos(w * t + h.phase_rad));
    }
  }
  for (const Ramp& r : ramps_) {
    const double a = std::max(0.0, t - r.start_s), b = std::max(0.0, -r.start_s);
    sum += 0.5 * r.slope * (a * a - b * b);
  }
  for (const TimeFunction& f : terms_) sum += f.Integral(t);
  if (!products_.empty()) sum = std::numeric_limits<double>::quiet_NaN();
  return sum;
}

}  // namespace cablesim
