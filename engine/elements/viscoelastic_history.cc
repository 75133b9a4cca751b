#include "engine/elements/viscoelastic_history.h"

#include <algorithm>
#include <cmath>

namespace cablesim {

namespace {

ViscoelasticHistory::Coefficients Relaxed(const ViscoelasticHistory::Law& law) {
  const double ea2 = ViscoelasticHistory::DynamicStiffness(law, 0);
  const double ea1 = ViscoelasticHistory::SlowStiffness(law, ea2);
  ViscoelasticHistory::Coefficients c;
  c.k = law.ea_static_n;
  c.p = 0;
  c.c0 = 0;
  c.c1 = ea2 / (ea1 + ea2);
  c.ea1 = ea1;
  c.ea2 = ea2;
  return c;
}

}  // namespace

double ViscoelasticHistory::DynamicStiffness(const Law& law, double e1) {
  if (law.ea_dynamic_n > 0) return law.ea_dynamic_n;
  if (!(e1 > 0)) return law.ea_base_n;
  const double ea = law.ea_static_n, a = law.ea_base_n;
  const double s = a + ea + law.ea_slope * ea * e1;
  return 0.5 * (s + std::sqrt(s * s - 4 * a * ea));
}

ViscoelasticHistory::Coefficients ViscoelasticHistory::StepCoefficients(
    const Law& law, double ea1, double ea2, double e_n, double e1_n, double tau_s) {
  const double ba = law.damping_static_ns, bd = law.damping_dynamic_ns, b = ba + bd;
  const double lambda = (ea1 + ea2) / b;
  const double m = ea1 - ba * lambda;  // dT/de_1 at fixed e and r
  Coefficients c;
  c.ea1 = ea1;
  c.ea2 = ea2;
  c.e_start = e_n;
  c.tau = tau_s;
  if (!(tau_s > 0)) {
    c.c0 = e1_n;
    c.c1 = 0;
    c.k = ba * ea2 / b;
    c.p = e1_n * m;
    return c;
  }
  const double x = lambda * tau_s;
  const double decay = std::exp(-x);
  const double phi = -std::expm1(-x) / lambda;
  // psi = (tau - phi) / lambda = tau^2 (1/2 - x/6 + x^2/24 - x^3/120 + ...): the
  // series where the difference would cancel.
  const double psi = x < 1e-3 ? tau_s * tau_s * (0.5 - x / 6 + x * x / 24 - x * x * x / 120)
                              : (tau_s - phi) / lambda;
  c.c1 = (bd * phi + ea2 * psi) / (b * tau_s);
  c.c0 = e1_n * decay + ea2 * e_n * phi / b - c.c1 * e_n;
  c.k = c.c1 * m + (ba / b) * (ea2 + bd / tau_s);
  c.p = c.c0 * m - ba * bd * e_n / (b * tau_s);
  return c;
}

int ViscoelasticHistory::AddElement(const Law& law, int gauss_points) {
  const int first = points();
  const int index = static_cast<int>(laws_.size());
  laws_.push_back(law);
  const Coefficients relaxed = Relaxed(law);
  for (int g = 0; g < gauss_points; ++g) {
    point_law_.push_back(index);
    coef_.push_back(relaxed);
    e_n_.push_back(0);
    e1_n_.push_back(0);
    ea1_.push_back(relaxed.ea1);
    ea2_.push_back(relaxed.ea2);
  }
  return first;
}

void ViscoelasticHistory::Relax() {
  started_ = false;
  for (int i = 0; i < points(); ++i) coef_[i] = Relaxed(laws_[point_law_[i]]);
}

void ViscoelasticHistory::Start(const std::vector<double>& strains, double t) {
  t_n_ = t;
  last_step_s_ = 0;
  started_ = true;
  for (int i = 0; i < points(); ++i) {
    const Law& law = laws_[point_law_[i]];
    e_n_[i] = strains[i];
    // At rest the slow part carries the whole tension, T_m = EA e: the
    // mean-load law's EA_2 in closed form (DynamicStiffness of the split
    // below returns it; an iteration from the unloaded split did not
    // reach it: 7 % low at 5 % strain with beta = 20).
    ea2_[i] = law.ea_dynamic_n > 0 ? law.ea_dynamic_n
                                   : law.ea_base_n + law.ea_slope * law.ea_static_n *
                                                         std::max(strains[i], 0.0);
    ea1_[i] = SlowStiffness(law, ea2_[i]);
    e1_n_[i] = ea2_[i] / (ea1_[i] + ea2_[i]) * strains[i];
    coef_[i] = StepCoefficients(law, ea1_[i], ea2_[i], e_n_[i], e1_n_[i], 0);
  }
}

void ViscoelasticHistory::SetTime(double t) {
  if (!started_) return;
  const double tau = t - t_n_;
  if (last_step_s_ > 0 && tau <= 1e-9 * last_step_s_) return;
  for (int i = 0; i < points(); ++i)
    coef_[i] = StepCoefficients(laws_[point_law_[i]], ea1_[i], ea2_[i], e_n_[i], e1_n_[i], tau);
}

void ViscoelasticHistory::Commit(const std::vector<double>& strains, double t,
                                 std::vector<double>* energy_jump) {
  energy_jump->assign(points(), 0.0);
  if (!started_) return;
  const double tau = t - t_n_;
  for (int i = 0; i < points(); ++i) {
    const Law& law = laws_[point_law_[i]];
    const Coefficients c = StepCoefficients(law, ea1_[i], ea2_[i], e_n_[i], e1_n_[i], tau);
    const double e1 = c.c0 + c.c1 * strains[i], e2 = strains[i] - e1;
    e1_n_[i] = e1;
    e_n_[i] = strains[i];
    const double ea1 = ea1_[i], ea2 = ea2_[i];
    ea2_[i] = DynamicStiffness(law, e1);
    ea1_[i] = SlowStiffness(law, ea2_[i]);
    (*energy_jump)[i] = 0.5 * ((ea1_[i] - ea1) * e1 * e1 + (ea2_[i] - ea2) * e2 * e2);
  }
  last_step_s_ = tau;
  t_n_ = t;
}

double ViscoelasticHistory::DissipatedPower(int point, double e) const {
  const Law& law = laws_[point_law_[point]];
  const Coefficients& c = coef_[point];
  const double rate = c.tau > 0 ? (e - c.e_start) / c.tau : 0.0;
  const double e1 = c.c0 + c.c1 * e;
  const double r1 = (c.ea2 * e - (c.ea1 + c.ea2) * e1 + law.damping_dynamic_ns * rate) /
                    (law.damping_static_ns + law.damping_dynamic_ns);
  const double r2 = rate - r1;
  return law.damping_static_ns * r1 * r1 + law.damping_dynamic_ns * r2 * r2;
}

double ViscoelasticHistory::StoredEnergy(int point, double e) const {
  const Coefficients& c = coef_[point];
  const double e1 = c.c0 + c.c1 * e, e2 = e - e1;
  return 0.5 * (c.ea1 * e1 * e1 + c.ea2 * e2 * e2);
}

}  // namespace cablesim
