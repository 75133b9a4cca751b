#ifndef CABLESIM_CONVERT_SCENE_SECTIONS_H_
#define CABLESIM_CONVERT_SCENE_SECTIONS_H_

// The conversion of a cablesim.v1.Scene (SceneFromProto), one file a
// section of the scene. SceneFromProto calls the sections in a fixed order,
// which is part of the contract: the first invalid field is the one
// reported, and a later section reads what an earlier one converted (a
// joint names a cable by the index the cables section gave it).
//   cables.cc       cables (geometry, section, hydrodynamics, winch, damping)
//   bodies.cc       bodies (mass, contact, fluid loads, placement on a cable)
//   joints.cc       attachments and joints (slide, motion, rotation, coupling)
//   loads.cc        point loads and probes
//   environment.cc  fluid, waves, seabed and bathymetry
//   sheaves.cc      sheaves
//   solver.cc       solver settings
//   time_functions.cc  TimeFunction and TimeVec3 values, for any section

#include <numbers>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "cablesim/v1/scene.pb.h"
#include "convert/plausible_ranges.h"
#include "convert/scene/field_checks.h"
#include "engine/scene/scene.h"

namespace cablesim::scene_convert {

inline constexpr double kPi = std::numbers::pi;
// Relative tolerance of the arc-length range check, so that `s` may be given
// as the cable's length even when that length is a sum of segments.
inline constexpr double kArcLengthTolerance = 1e-9;

// The scene being built, and what a section leaves for the later ones.
struct ConversionState {
  explicit ConversionState(const v1::Scene& p) : proto(p) {}

  const v1::Scene& proto;
  Scene scene;
  NameIndex cable_index;
  NameIndex body_index;
  // The PIN joints at the faces of bodies threaded on a cable (Body.on).
  std::vector<JointSpec> threaded_joints;
  NameIndex probe_index;
};

// Each converts its section of `state->proto` into `state->scene`,
// stopping at the first invalid field.
absl::Status ConvertCables(ConversionState* state);   // cables.cc
absl::Status ConvertBodies(ConversionState* state);   // bodies.cc
absl::Status ConvertJoints(ConversionState* state);   // joints.cc
absl::Status ConvertLoads(ConversionState* state);    // loads.cc
absl::Status ConvertProbes(ConversionState* state);   // loads.cc
absl::Status ConvertFluid(ConversionState* state);    // environment.cc
absl::Status ConvertSeabed(ConversionState* state);   // environment.cc
absl::Status ConvertSheaves(ConversionState* state);  // sheaves.cc
absl::Status ConvertSolver(ConversionState* state);   // solver.cc

// A cable point, a body point or (when `allow_ground`) the ground, naming
// cables and bodies already converted (joints.cc).
absl::StatusOr<Attachment> ConvertAttachment(const ConversionState& state, absl::string_view path,
                                             const v1::Attachment& a, bool allow_ground);

// `range`: the range of the field the function drives (its values; its
// ramps' slopes per second). `depth`: how deep in a sum (time_functions.cc).
absl::StatusOr<TimeFunction> ConvertTimeFunction(const std::string& path, const v1::TimeFunction& p,
                                                 const PlausibleRange& range, int depth = 0);
absl::StatusOr<TimeVector> ConvertTimeVector(const std::string& path, const v1::TimeVec3& p,
                                             const PlausibleRange& range);

}  // namespace cablesim::scene_convert

#endif  // CABLESIM_CONVERT_SCENE_SECTIONS_H_
