#ifndef CABLESIM_CONVERT_PLAUSIBLE_RANGES_H_
#define CABLESIM_CONVERT_PLAUSIBLE_RANGES_H_

// The physical ranges a scene's numbers must lie in (SceneFromProto checks
// them; README "Ranges" lists them with the reasons). They are deliberately
// wide: they exist to turn a typo or a hostile value (1e308, a denormal
// step) into an error naming the field before the engine starts, not to
// second-guess an unusual but real model (a 10 km mooring line, a Kevlar
// tether, a nearly weightless rod in a statics check).

namespace cablesim {

struct PlausibleRange {
  double lo;
  double hi;
  const char* unit;
};

namespace plausible {

// Cable length and a polyline's length [m]: a micro-fibre to a 100 km tow.
inline constexpr PlausibleRange kCableLength{1e-6, 1e5, "m"};
// Every coordinate of a point in the world or on a body [m].
inline constexpr PlausibleRange kCoordinate{-1e6, 1e6, "m"};
// Cable diameter, cylinder diameter and height [m].
inline constexpr PlausibleRange kSize{1e-6, 1e3, "m"};
inline constexpr PlausibleRange kArea{1e-14, 1e6, "m^2"};
// Upper end only: 0 is allowed (bending NONE) and checked separately.
inline constexpr PlausibleRange kSecondMoment{1e-30, 1e12, "m^4"};
// Aerogel to well above osmium; the low end admits "weightless" idealisations.
inline constexpr PlausibleRange kDensity{1e-6, 1e6, "kg/m^3"};
// A soft gel to well above carbon nanotubes.
inline constexpr PlausibleRange kYoungsModulus{1, 1e13, "Pa"};
inline constexpr PlausibleRange kMass{1e-9, 1e9, "kg"};
inline constexpr PlausibleRange kInertia{0, 1e15, "kg m^2"};
// Each component of gravity (a centrifuge's 10,000 g is inside).
inline constexpr PlausibleRange kGravity{-1e6, 1e6, "m/s^2"};
inline constexpr PlausibleRange kForce{-1e12, 1e12, "N"};
inline constexpr PlausibleRange kTorque{-1e12, 1e12, "N m"};
inline constexpr PlausibleRange kVelocity{-1e5, 1e5, "m/s"};
inline constexpr PlausibleRange kAngularVelocity{-1e5, 1e5, "rad/s"};
inline constexpr PlausibleRange kStep{1e-9, 1e4, "s"};
inline constexpr PlausibleRange kDuration{0, 1e9, "s"};
// Adaptive steps' absolute tolerance.
inline constexpr PlausibleRange kErrorTolerance{1e-15, 1e3, "m"};
// duration / step: more nominal steps than this is a unit mistake.
inline constexpr double kMaxNominalSteps = 1e10;
// A polyline may turn by at most this angle at a corner [degrees]; more
// folds the cable back on itself (at 180 degrees the corner has no tangent).
inline constexpr double kMaxCornerTurnDegrees = 135;

// Longest name (of the scene, a cable, body or probe, or a name referred
// to) [bytes]; names are echoed in messages and CSV headers.
inline constexpr int kMaxNameBytes = 256;

}  // namespace plausible
}  // namespace cablesim

#endif  // CABLESIM_CONVERT_PLAUSIBLE_RANGES_H_
