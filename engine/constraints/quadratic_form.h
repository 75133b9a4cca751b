#ifndef CABLESIM_ENGINE_CONSTRAINTS_QUADRATIC_FORM_H_
#define CABLESIM_ENGINE_CONSTRAINTS_QUADRATIC_FORM_H_

// Linear and quadratic forms in the full coordinates q, used to build joint
// constraints when a model is assembled (not in the hot loop).
//
// With ANCF cable nodes [r, r_x] and rigid bodies in natural coordinates
// (centre of mass and body axes, see MultibodyModel), every point and
// direction a joint refers to is a linear form of q, and every constraint is
// a linear form (positions coincide) or a product of two (a tangent
// perpendicular to a body axis, unit axes, orthogonal axes). So each
// constraint row is
//
//   phi(q) = c + sum_i l_i q_i + sum_(a <= b) w_ab q_a q_b,
//
// with a constant gradient part and a constant Hessian.

#include <array>
#include <map>
#include <utility>

#include <Eigen/Core>

namespace cablesim {

struct LinearForm {
  double c = 0;
  std::map<int, double> terms;  // coordinate index -> coefficient

  static LinearForm Constant(double value) {
    LinearForm f;
    f.c = value;
    return f;
  }
  static LinearForm Coordinate(int index, double coefficient = 1) {
    LinearForm f;
    if (coefficient != 0) f.terms[index] = coefficient;
    return f;
  }
  LinearForm& operator+=(const LinearForm& o) {
    c += o.c;
    for (const auto& [i, v] : o.terms) terms[i] += v;
    return *this;
  }
  LinearForm Scaled(double s) const {
    LinearForm f;
    f.c = c * s;
    for (const auto& [i, v] : terms)
      if (v * s != 0) f.terms[i] = v * s;
    return f;
  }
  double Evaluate(const Eigen::VectorXd& q) const {
    double acc = c;
    for (const auto& [i, v] : terms) acc += v * q(i);
    return acc;
  }
};

// A vector in space whose components are linear forms (z is zero in a
// planar model).
using LinearVector = std::array<LinearForm, 3>;

inline LinearVector Add(const LinearVector& a, const LinearVector& b, double sb = 1) {
  LinearVector r = a;
  for (int d = 0; d < 3; ++d) r[d] += b[d].Scaled(sb);
  return r;
}

// The constant vector v.
inline LinearVector Constant(const Eigen::Vector3d& v) {
  return {LinearForm::Constant(v.x()), LinearForm::Constant(v.y()), LinearForm::Constant(v.z())};
}

// sum s_k v_k.
inline LinearVector Combination(const std::vector<std::pair<double, LinearVector>>& terms) {
  LinearVector r;
  for (const auto& [s, v] : terms) r = Add(r, v, s);
  return r;
}

struct QuadraticForm {
  double c = 0;
  std::map<int, double> linear;
  std::map<std::pair<int, int>, double> quadratic;  // (a, b) with a <= b

  static QuadraticForm FromLinear(const LinearForm& f) {
    QuadraticForm q;
    q.c = f.c;
    q.linear = f.terms;
    return q;
  }
  static QuadraticForm Product(const LinearForm& f, const LinearForm& g) {
    QuadraticForm q;
    q.c = f.c * g.c;
    for (const auto& [i, v] : f.terms) q.linear[i] += v * g.c;
    for (const auto& [i, v] : g.terms) q.linear[i] += v * f.c;
    for (const auto& [i, v] : f.terms)
      for (const auto& [j, w] : g.terms) q.quadratic[{std::min(i, j), std::max(i, j)}] += v * w;
    return q;
  }
  QuadraticForm& AddScaled(const QuadraticForm& o, double s) {
    c += s * o.c;
    for (const auto& [i, v] : o.linear) linear[i] += s * v;
    for (const auto& [ij, v] : o.quadratic) quadratic[ij] += s * v;
    return *this;
  }
  double Evaluate(const Eigen::VectorXd& q) const {
    double acc = c;
    for (const auto& [i, v] : linear) acc += v * q(i);
    for (const auto& [ij, v] : quadratic) acc += v * q(ij.first) * q(ij.second);
    return acc;
  }
};

// a . b over the first `dim` components.
inline QuadraticForm Dot(const LinearVector& a, const LinearVector& b, int dim) {
  QuadraticForm q;
  for (int d = 0; d < dim; ++d) q.AddScaled(QuadraticForm::Product(a[d], b[d]), 1);
  return q;
}

// (a x b) . m for a constant vector m.
inline QuadraticForm CrossDot(const LinearVector& a, const LinearVector& b,
                              const Eigen::Vector3d& m) {
  QuadraticForm q;
  for (int d = 0; d < 3; ++d) {
    if (m(d) == 0) continue;
    const int i = (d + 1) % 3, j = (d + 2) % 3;
    q.AddScaled(QuadraticForm::Product(a[i], b[j]), m(d));
    q.AddScaled(QuadraticForm::Product(a[j], b[i]), -m(d));
  }
  return q;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_CONSTRAINTS_QUADRATIC_FORM_H_
