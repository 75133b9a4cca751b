#include "engine/scene/polyline.h"

#include <algorithm>
#include <cmath>

namespace cablesim {
namespace {

using Eigen::Vector3d;

// Within this fraction of the polyline's length of a vertex, a point is at
// the vertex (the builder's node snap).
constexpr double kVertexSnap = 1e-9;

}  // namespace

void PolylineAt(const std::vector<Vector3d>& pts, double frac, Vector3d* point,
                Vector3d* tangent, int side) {
  std::vector<double> cum(pts.size(), 0.0);
  for (size_t i = 1; i < pts.size(); ++i) cum[i] = cum[i - 1] + (pts[i] - pts[i - 1]).norm();
  const double total = cum.back();
  const double s = std::clamp(frac, 0.0, 1.0) * total;
  size_t seg = 1;
  while (seg + 1 < pts.size() && cum[seg] < s) ++seg;
  const Vector3d a = pts[seg - 1], b = pts[seg];
  const double len = cum[seg] - cum[seg - 1];
  const double t = len > 0 ? (s - cum[seg - 1]) / len : 0;
  *point = a + t * (b - a);
  Vector3d dir = (b - a).normalized();
  const double tol = kVertexSnap * total;
  if (std::abs(s - cum[seg]) <= tol && seg + 1 < pts.size()) {
    const Vector3d out = (pts[seg + 1] - b).normalized();
    dir = side < 0 ? dir : side > 0 ? out : (dir + out).normalized();
  } else if (std::abs(s - cum[seg - 1]) <= tol && seg >= 2) {
    const Vector3d in = (a - pts[seg - 2]).normalized();
    dir = side > 0 ? dir : side < 0 ? in : (dir + in).normalized();
  }
  *tangent = dir;
}

double PolylineLength(const std::vector<Vector3d>& pts) {
  double total = 0;
  for (size_t i = 1; i < pts.size(); ++i) total += (pts[i] - pts[i - 1]).norm();
  return total;
}

}  // namespace cablesim
