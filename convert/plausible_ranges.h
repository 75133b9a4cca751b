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
// A mass that may be 0 (a cable tip's added mass).
inline constexpr PlausibleRange kMassOrZero{0, 1e9, "kg"};
inline constexpr PlausibleRange kInertia{0, 1e15, "kg m^2"};
// Each component of gravity (a centrifuge's 10,000 g is inside).
inline constexpr PlausibleRange kGravity{-1e6, 1e6, "m/s^2"};
inline constexpr PlausibleRange kForce{-1e12, 1e12, "N"};
// A tension-strain table's strain (a rubber cord stretches to 5 or 6).
inline constexpr PlausibleRange kStrain{0, 10, "(dimensionless)"};
inline constexpr PlausibleRange kTorque{-1e12, 1e12, "N m"};
inline constexpr PlausibleRange kVelocity{-1e5, 1e5, "m/s"};
inline constexpr PlausibleRange kAngularVelocity{-1e5, 1e5, "rad/s"};
inline constexpr PlausibleRange kStep{1e-9, 1e4, "s"};
inline constexpr PlausibleRange kDuration{0, 1e9, "s"};
// Adaptive steps' absolute tolerance.
inline constexpr PlausibleRange kErrorTolerance{1e-15, 1e3, "m"};
// Time functions (TimeFunction): the range of their values depends on
// what they drive (a force, a displacement, a winch's speed): constants,
// amplitudes and table values lie in that field's range, and a ramp's
// slope in that range per second. Frequencies, phases and times:
inline constexpr PlausibleRange kFrequency{0, 1e6, "Hz"};
inline constexpr PlausibleRange kPhase{-1e6, 1e6, "rad"};
inline constexpr PlausibleRange kTime{-1e9, 1e9, "s"};
// A prescribed rotation [rad] (many turns allowed).
inline constexpr PlausibleRange kAngle{-1e6, 1e6, "rad"};
// Drag and added-mass coefficients (about 1 in practice).
inline constexpr PlausibleRange kHydroCoefficient{0, 1e3, "(dimensionless)"};
// A body's drag areas [m^2] and rotational drag areas [m^5].
inline constexpr PlausibleRange kDragArea{0, 1e6, "m^2"};
inline constexpr PlausibleRange kRotationalDragArea{0, 1e12, "m^5"};
// Friction coefficients (about 0.1 to 1 in practice).
inline constexpr PlausibleRange kFrictionCoefficient{0, 1e3, "(dimensionless)"};
// Cable damping times (axial_time, bending_time, rayleigh_beta) and
// Rayleigh's mass-proportional alpha.
inline constexpr PlausibleRange kDampingTime{0, 1e4, "s"};
inline constexpr PlausibleRange kRayleighAlpha{0, 1e6, "1/s"};
// Contact springs: a point's [N/m] and a bed's or wheel's per area [N/m^2].
inline constexpr PlausibleRange kStiffness{1e-6, 1e15, "N/m (N/m^2 per area)"};
// Dampers: linear [N s/m], angular [N m s], per area [N s/m^2].
inline constexpr PlausibleRange kDampingCoefficient{0, 1e15, "N s/m (N m s, N s/m^2)"};
// Wave periods [s]: ripples to swells, wide.
inline constexpr PlausibleRange kWavePeriod{1e-2, 1e4, "s"};
// Wave angular frequencies [rad/s] (2 pi over the periods above).
inline constexpr PlausibleRange kWaveFrequency{0, 1e3, "rad/s"};
// Friction's regularising speed [m/s] and length [m].
inline constexpr PlausibleRange kFrictionSpeed{1e-12, 1e5, "m/s"};
inline constexpr PlausibleRange kFrictionLength{1e-12, 1e5, "m"};
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
