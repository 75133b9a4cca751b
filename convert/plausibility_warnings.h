#ifndef CABLESIM_CONVERT_PLAUSIBILITY_WARNINGS_H_
#define CABLESIM_CONVERT_PLAUSIBILITY_WARNINGS_H_

// Plausibility warnings (issue 32, item 4): numbers that are legal (inside
// plausible_ranges.h, which refuses only the absurd) but that a real cable
// scene rarely has, the marks of a unit slip (`diameter: 20` meaning mm,
// `youngs_modulus: 200` meaning GPa, `step: 2` meaning ms). None blocks a
// run: SceneFromProto puts them in Scene::warnings, a run adds them to its
// summary's `warnings` (so they reach standard error, and fail a run under
// solver.strict like the run's own warnings), and `cablesim validate`
// lists them. Each names the field, its value and the units it expects.
//
// The checks, with their thresholds (docs/honest-runs.md explains them):
//  - cables[i].youngs_modulus outside kPlausibleYoungsModulus [Pa];
//  - cables[i].density outside kPlausibleDensity [kg/m^3];
//  - static strain above kMaxStaticStrain under the scene's own weight and
//    loads, estimated per cable as (its weight + the weight of the bodies
//    jointed to it + the loads on it and on them) / EA;
//  - a cable's weight above or below its payload's (bodies jointed to it)
//    by more than kWeightRatio;
//  - element length (length / elements) below the cable's diameter, or
//    above 1/10 of the cable;
//  - solver.step (fixed steps, DYNAMIC) above the shortest period of the
//    cables' axial bounce, 2 pi sqrt((payload + cable mass / 3) L / EA):
//    the dynamic tension of a lift or a snap lives at that period.

#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim {

inline constexpr double kPlausibleYoungsModulusLo = 1e5;   // [Pa] soft rubber
inline constexpr double kPlausibleYoungsModulusHi = 1e12;  // [Pa] diamond
inline constexpr double kPlausibleDensityLo = 10;          // [kg/m^3]
inline constexpr double kPlausibleDensityHi = 25000;       // [kg/m^3] above osmium
inline constexpr double kMaxStaticStrain = 0.01;
inline constexpr double kWeightRatio = 1000;

// `proto` only tells how a value was given (diameter or area); the numbers
// are `scene`'s (SceneFromProto's result).
std::vector<std::string> PlausibilityWarnings(const v1::Scene& proto, const Scene& scene);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_PLAUSIBILITY_WARNINGS_H_
