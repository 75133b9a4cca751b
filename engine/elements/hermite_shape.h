#ifndef CABLESIM_ENGINE_ELEMENTS_HERMITE_SHAPE_H_
#define CABLESIM_ENGINE_ELEMENTS_HERMITE_SHAPE_H_

// The cubic Hermite shape functions of the ANCF cable element (docs/model.md
// section 1, paper eq. 3) at xi = x / l in [0, 1] for an element of length
// l [m]: r(x) = sum_k s_k(x) e_k with e = [r_O, r_O,x, r_A, r_A,x]. The
// slope functions s_1, s_3 carry a factor l [m]; derivatives are in x.

namespace cablesim {

inline void HermiteShape(double xi, double l, double s[4]) {
  const double xi2 = xi * xi, xi3 = xi2 * xi;
  s[0] = 1 - 3 * xi2 + 2 * xi3;
  s[1] = l * (xi - 2 * xi2 + xi3);
  s[2] = 3 * xi2 - 2 * xi3;
  s[3] = l * (xi3 - xi2);
}

// ds_k/dx [1/m or -].
inline void HermiteShapeD1(double xi, double l, double s[4]) {
  s[0] = (-6 * xi + 6 * xi * xi) / l;
  s[1] = 1 - 4 * xi + 3 * xi * xi;
  s[2] = (6 * xi - 6 * xi * xi) / l;
  s[3] = 3 * xi * xi - 2 * xi;
}

// d^2 s_k/dx^2 [1/m^2 or 1/m].
inline void HermiteShapeD2(double xi, double l, double s[4]) {
  s[0] = (-6 + 12 * xi) / (l * l);
  s[1] = (-4 + 6 * xi) / l;
  s[2] = (6 - 12 * xi) / (l * l);
  s[3] = (6 * xi - 2) / l;
}

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_ELEMENTS_HERMITE_SHAPE_H_
