#ifndef CABLESIM_ENGINE_SCENE_POLYLINE_H_
#define CABLESIM_ENGINE_SCENE_POLYLINE_H_

// The polyline a cable is laid along at t = 0 (CableSpec::points), shared
// by the model builder (node positions and slopes) and by convert/ (bodies
// placed on a cable), so that both compute the same points to the last bit.

#include <vector>

#include <Eigen/Core>

namespace cablesim {

// Arc-length position along a polyline: point [m] and unit tangent at
// `frac` (clamped to [0, 1]) of its total length. At an interior vertex
// (within 1e-9 of the length) the tangent is the average of the two
// segments' directions (side 0), or the incoming (side -1) or outgoing
// (side +1) segment's.
void PolylineAt(const std::vector<Eigen::Vector3d>& pts, double frac, Eigen::Vector3d* point,
                Eigen::Vector3d* tangent, int side = 0);

// Total length [m].
double PolylineLength(const std::vector<Eigen::Vector3d>& pts);

}  // namespace cablesim

#endif  // CABLESIM_ENGINE_SCENE_POLYLINE_H_
