#ifndef CABLESIM_ENGINE_LINEAR_COORDINATE_MAP_H_
#define CABLESIM_ENGINE_LINEAR_COORDINATE_MAP_H_

// The model's map of full coordinates onto unknowns: q_i = c_i + s_i
// z_{j_i} (j_i = -1: fixed; engine/model/multibody_model.h). The scatter
// helpers add a local symmetric matrix over full coordinates, mapped onto
// z, into a skyline matrix (lower triangle on z: pairs with j_a > j_b
// once, j_a == j_b all, so a symmetric local matrix sums both transposes).
// Force contributors and constraint families receive it from the model
// (a view: the model owns j and s).

#include <Eigen/Core>

#include "engine/linear/skyline_ldlt.h"

namespace cablesim {

struct CoordinateMap {
  const int* j = nullptr;
  const double* s = nullptr;
  int dim = 2;

  // scale * m over the coordinates coord[0..n) (m n x n, column-major with
  // leading dimension ld).
  void Scatter(const int* coord, int n, const double* m, int ld, double scale,
               SkylineLdlt* a) const;
  // scale * m over the n consecutive coordinates from `first` (m n x n,
  // column-major with leading dimension ld).
  void ScatterRange(int first, int n, const double* m, int ld, double scale,
                    SkylineLdlt* a) const;
  // scale * m (dim x dim block of a 3 x 3) over the dim coordinates from
  // full index `first`.
  void ScatterBlock(int first, const Eigen::Matrix3d& m, double scale, SkylineLdlt* a) const;
};

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_LINEAR_COORDINATE_MAP_H_
