#include "engine/elements/tension_table.h"

#include <algorithm>
#include <utility>

namespace cablesim {

TensionTable::TensionTable(std::vector<double> strains, std::vector<double> tensions)
    : strain_(std::move(strains)), tension_(std::move(tensions)) {
  const int n = static_cast<int>(strain_.size());
  slope_.resize(std::max(n - 1, 0));
  energy_.assign(n, 0.0);
  for (int k = 0; k + 1 < n; ++k) {
    slope_[k] = (tension_[k + 1] - tension_[k]) / (strain_[k + 1] - strain_[k]);
    max_stiffness_ = std::max(max_stiffness_, slope_[k]);
    energy_[k + 1] =
        energy_[k] + 0.5 * (tension_[k] + tension_[k + 1]) * (strain_[k + 1] - strain_[k]);
  }
}

int TensionTable::Segment(double e) const {
  // The number of inner knots e_1 .. e_last at or below e (a bisection: a
  // table read from a file may have hundreds of knots).
  const int last = static_cast<int>(slope_.size()) - 1;
  return static_cast<int>(std::upper_bound(strain_.begin() + 1, strain_.begin() + 1 + last, e) -
                          (strain_.begin() + 1));
}

TensionTable::Value TensionTable::At(double e) const {
  const int k = Segment(e);
  return {tension_[k] + slope_[k] * (e - strain_[k]), slope_[k]};
}

double TensionTable::Energy(double e) const {
  const int k = Segment(e);
  const double t = tension_[k] + slope_[k] * (e - strain_[k]);
  return energy_[k] + 0.5 * (tension_[k] + t) * (e - strain_[k]);
}

double TensionTable::MeanTension(double e0, double e1) const {
  if (e1 < e0) std::swap(e0, e1);
  const int k0 = Segment(e0), k1 = Segment(e1);
  const double t0 = tension_[k0] + slope_[k0] * (e0 - strain_[k0]);
  const double t1 = tension_[k1] + slope_[k1] * (e1 - strain_[k1]);
  // T is linear between e0 and e1: its mean is the mean of the ends.
  if (k0 == k1) return 0.5 * (t0 + t1);
  // Otherwise the trapezoids between the knots in (e0, e1), weighted by
  // their widths: a mean of positive weights, exact and free of the
  // cancellation of (W(e1) - W(e0)) / (e1 - e0).
  double sum = 0, at = e0, t = t0;
  for (int k = k0 + 1; k <= k1; ++k) {
    sum += 0.5 * (t + tension_[k]) * (strain_[k] - at);
    at = strain_[k];
    t = tension_[k];
  }
  sum += 0.5 * (t + t1) * (e1 - at);
  return sum / (e1 - e0);
}

}  // namespace cablesim
