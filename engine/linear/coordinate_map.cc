#include "engine/linear/coordinate_map.h"

namespace cablesim {

void CoordinateMap::Scatter(const int* coord, int n, const double* m, int ld, double scale,
                            SkylineLdlt* a) const {
  double* values = a->values();
  for (int i = 0; i < n; ++i) {
    const int ji = j[coord[i]];
    if (ji < 0) continue;
    for (int k = 0; k < n; ++k) {
      const int jk = j[coord[k]];
      if (jk < 0 || jk > ji) continue;
      values[a->Slot(ji, jk)] += scale * s[coord[i]] * s[coord[k]] * m[i + ld * k];
    }
  }
}

void CoordinateMap::ScatterRange(int first, int n, const double* m, int ld, double scale,
                                 SkylineLdlt* a) const {
  double* values = a->values();
  for (int i = 0; i < n; ++i) {
    const int ji = j[first + i];
    if (ji < 0) continue;
    for (int k = 0; k < n; ++k) {
      const int jk = j[first + k];
      if (jk < 0 || jk > ji) continue;
      values[a->Slot(ji, jk)] += scale * s[first + i] * s[first + k] * m[i + ld * k];
    }
  }
}

void CoordinateMap::ScatterBlock(int first, const Eigen::Matrix3d& m, double scale,
                                 SkylineLdlt* a) const {
  ScatterRange(first, dim, m.data(), 3, scale, a);
}

}  // namespace cablesim
