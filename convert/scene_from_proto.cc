#include "convert/scene_from_proto.h"
#include "convert/solver_applicability.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/string_view.h"
#include "convert/plausibility_warnings.h"
#include "convert/plausible_ranges.h"
#include "engine/scene/polyline.h"
#include "engine/scene/integrator_traits.h"

// Local helpers for early return on error.
#define CABLESIM_RETURN_IF_ERROR(expr)   \
  do {                                   \
    const absl::Status _status = (expr); \
    if (!_status.ok()) return _status;   \
  } while (false)
#define CABLESIM_CONCAT_INNER(a, b) a##b
#define CABLESIM_CONCAT(a, b) CABLESIM_CONCAT_INNER(a, b)
#define CABLESIM_ASSIGN_OR_RETURN(lhs, expr) \
  CABLESIM_ASSIGN_OR_RETURN_IMPL(CABLESIM_CONCAT(_status_or_, __LINE__), lhs, expr)
#define CABLESIM_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                                   \
  if (!tmp.ok()) return tmp.status();                  \
  lhs = std::move(*tmp)

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
// Relative tolerance of the arc-length range check, so that `s` may be given
// as the cable's length even when that length is a sum of segments.
constexpr double kArcLengthTolerance = 1e-9;
// Relative tolerance of the comparisons between solver times.
constexpr double kTimeTolerance = 1e-9;

constexpr int kDefaultElements = 10;
constexpr int kMaxElements = 100000;
constexpr double kDefaultStep = 1e-3;
constexpr double kMaxFrames = 1e7;
constexpr int kDefaultLoadSteps = 10;
constexpr int kMaxLoadSteps = 100000;
constexpr double kDefaultNewtonTolerance = 1e-8;
constexpr double kMaxTolerance = 1e-2;
constexpr int kDefaultMaxNewtonIterations = 25;
constexpr int kMaxNewtonIterations = 1000;
constexpr int kDefaultMaxStepHalvings = 12;
constexpr int kMaxStepHalvings = 40;
constexpr double kDefaultLinearTolerance = 1e-10;
constexpr int kDefaultMaxLinearIterations = 200;
constexpr int kMaxLinearIterations = 100000;
// MODAL: the engine also bounds modes by the scene's degrees of freedom.
constexpr int kMaxModes = 100000;
// JONSWAP components per sea (each costs a few exponentials per Gauss
// point per force evaluation).
constexpr int kMaxWaveComponents = 1000;

absl::Status Invalid(absl::string_view path, absl::string_view rule) {
  return absl::InvalidArgumentError(absl::StrCat(path, ": ", rule));
}

std::string Sub(absl::string_view parent, absl::string_view field) {
  return absl::StrCat(parent, ".", field);
}

std::string Indexed(absl::string_view parent, absl::string_view field, int index) {
  return absl::StrCat(parent, parent.empty() ? "" : ".", field, "[", index, "]");
}

// A number as written in messages: 10 significant digits; exponents without
// '+' or leading zeros, and round numbers of 10,000 and more as exponents
// (1e-3, 1e6, 2.5e7, 1e308), as users write them.
std::string Num(double value) {
  std::string text = absl::StrFormat("%.10g", value);
  if (text.find_first_of("e.") == std::string::npos && text.size() >= 5 &&
      absl::EndsWith(text, "0000")) {
    text = absl::StrFormat("%.9e", value);
    const size_t e = text.find('e');
    size_t mantissa_end = e;
    while (text[mantissa_end - 1] == '0') --mantissa_end;
    if (text[mantissa_end - 1] == '.') --mantissa_end;
    text = text.substr(0, mantissa_end) + text.substr(e);
  }
  const size_t e = text.find('e');
  if (e == std::string::npos) return text;
  size_t digits = e + 1;
  std::string exponent;
  if (text[digits] == '-') exponent = "-";
  if (text[digits] == '-' || text[digits] == '+') ++digits;
  while (digits + 1 < text.size() && text[digits] == '0') ++digits;
  return absl::StrCat(text.substr(0, e + 1), exponent, text.substr(digits));
}

absl::Status CheckFinite(absl::string_view path, double value) {
  if (!std::isfinite(value))
    return Invalid(path, absl::StrCat("must be finite (got ", Num(value), ")"));
  return absl::OkStatus();
}

absl::Status CheckPositive(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value > 0)) return Invalid(path, absl::StrCat("must be > 0 (got ", Num(value), ")"));
  return absl::OkStatus();
}

absl::Status CheckNonNegative(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value >= 0)) return Invalid(path, absl::StrCat("must be >= 0 (got ", Num(value), ")"));
  return absl::OkStatus();
}

// Names are echoed in messages: a long one is refused before that.
absl::Status CheckNameLength(absl::string_view path, absl::string_view name) {
  if (name.size() > static_cast<size_t>(plausible::kMaxNameBytes)) {
    return Invalid(path, absl::StrCat("at most ", plausible::kMaxNameBytes, " bytes (got ",
                                      name.size(), ")"));
  }
  return absl::OkStatus();
}

absl::Status CheckIntRange(absl::string_view path, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    return Invalid(path, absl::StrCat("must be in [", lo, ", ", hi, "] (got ", value, ")"));
  }
  return absl::OkStatus();
}

// A finite value in `range` (inclusive); the message gives the range.
absl::Status CheckRange(absl::string_view path, double value, const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value >= range.lo && value <= range.hi)) {
    return Invalid(path, absl::StrCat("must be in [", Num(range.lo), ", ", Num(range.hi), "] ",
                                      range.unit, " (got ", Num(value), ")"));
  }
  return absl::OkStatus();
}

// A value > 0 (the message most users meet first) and in `range`.
absl::Status CheckPositiveInRange(absl::string_view path, double value,
                                  const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckPositive(path, value));
  return CheckRange(path, value, range);
}

// Fixed steps without solver.tolerance: the local error estimate is held to
// this fraction of the scene's size (SceneSize). 1 % of the size in one
// step: the estimate is the largest over every unknown and step (slopes
// and stiff axial modes included), so a tighter default flagged most
// sample scenes, whose results are checked against references
// (docs/honest-runs.md has the figures).
constexpr double kDefaultRelativeErrorTolerance = 1e-2;

// A tolerance in (0, kMaxTolerance].
absl::Status CheckTolerance(absl::string_view path, double value) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(path, value));
  if (!(value > 0 && value <= kMaxTolerance)) {
    return Invalid(path,
                   absl::StrCat("must be in (0, ", Num(kMaxTolerance), "] (got ", Num(value), ")"));
  }
  return absl::OkStatus();
}

// How deep TimeFunction.sum may nest.
constexpr int kMaxTimeFunctionDepth = 8;

// `range`: the range of the field the function drives (its values; its
// ramps' slopes per second).
absl::StatusOr<TimeFunction> ConvertTimeFunction(const std::string& path,
                                                 const v1::TimeFunction& p,
                                                 const PlausibleRange& range, int depth = 0) {
  TimeFunction f;
  const PlausibleRange slope{range.lo, range.hi, "per s"};
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "constant"), p.constant(), range));
  f.set_constant(p.constant());
  if (p.has_table()) {
    const std::string table = Sub(path, "table");
    const auto& times = p.table().times();
    const auto& values = p.table().values();
    if (times.empty()) return Invalid(Sub(table, "times"), "must have at least one entry");
    if (values.size() != times.size()) {
      return Invalid(Sub(table, "values"),
                     absl::StrCat("must have as many entries as times (", times.size(), "; got ",
                                  values.size(), ")"));
    }
    for (int k = 0; k < times.size(); ++k) {
      CABLESIM_RETURN_IF_ERROR(CheckRange(Indexed(table, "times", k), times[k], plausible::kTime));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Indexed(table, "values", k), values[k], range));
      if (k > 0 && !(times[k] > times[k - 1])) {
        return Invalid(Sub(table, "times"),
                       absl::StrCat("times must increase (times[", k, "] = ", Num(times[k]),
                                    " after ", Num(times[k - 1]), ")"));
      }
    }
    f.set_table({times.begin(), times.end()}, {values.begin(), values.end()});
  }
  if (p.has_harmonic()) {
    const std::string h = Sub(path, "harmonic");
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(h, "amplitude"), p.harmonic().amplitude(), range));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(h, "frequency"), p.harmonic().frequency()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(h, "frequency"), p.harmonic().frequency(), plausible::kFrequency));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(h, "phase"), p.harmonic().phase(), plausible::kPhase));
    f.add_harmonic({p.harmonic().amplitude(), p.harmonic().frequency(), p.harmonic().phase()});
  }
  if (p.has_ramp()) {
    const std::string r = Sub(path, "ramp");
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(r, "slope"), p.ramp().slope(), slope));
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(r, "start"), p.ramp().start()));
    CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(r, "start"), p.ramp().start(), plausible::kDuration));
    f.add_ramp({p.ramp().slope(), p.ramp().start()});
  }
  for (int i = 0; i < p.sum_size(); ++i) {
    const std::string sub = Indexed(path, "sum", i);
    if (depth + 1 >= kMaxTimeFunctionDepth)
      return Invalid(sub, absl::StrCat("at most ", kMaxTimeFunctionDepth, " levels of sum"));
    CABLESIM_ASSIGN_OR_RETURN(TimeFunction term, ConvertTimeFunction(sub, p.sum(i), range, depth + 1));
    f.add_term(std::move(term));
  }
  return f;
}

absl::StatusOr<TimeVector> ConvertTimeVector(const std::string& path, const v1::TimeVec3& p,
                                             const PlausibleRange& range) {
  TimeVector v;
  CABLESIM_ASSIGN_OR_RETURN(v[0], ConvertTimeFunction(Sub(path, "x"), p.x(), range));
  CABLESIM_ASSIGN_OR_RETURN(v[1], ConvertTimeFunction(Sub(path, "y"), p.y(), range));
  CABLESIM_ASSIGN_OR_RETURN(v[2], ConvertTimeFunction(Sub(path, "z"), p.z(), range));
  return v;
}

absl::StatusOr<Eigen::Vector3d> FiniteVector(absl::string_view path, const v1::Vec3& v) {
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "x"), v.x()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "y"), v.y()));
  CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "z"), v.z()));
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

// A vector whose every component lies in `range`.
absl::StatusOr<Eigen::Vector3d> VectorInRange(absl::string_view path, const v1::Vec3& v,
                                              const PlausibleRange& range) {
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "x"), v.x(), range));
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "y"), v.y(), range));
  CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "z"), v.z(), range));
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

// Smallest norm of a direction that is normalised without losing digits.
constexpr double kMinDirectionNorm = 1e-100;

// A non-zero direction, normalised. Its size does not matter, but its norm
// must be a double: components of 1e308 are rejected as overflowing, not
// called zero.
absl::StatusOr<Eigen::Vector3d> Direction(absl::string_view path, const v1::Vec3& v) {
  CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d result, FiniteVector(path, v));
  const double norm = result.norm();
  if (!std::isfinite(norm)) {
    return Invalid(path, absl::StrCat("norm overflows (largest component ",
                                      Num(result.cwiseAbs().maxCoeff()),
                                      "); give a direction of moderate size"));
  }
  if (!(norm >= kMinDirectionNorm)) {
    return Invalid(path, absl::StrCat("must be non-zero (got norm ", Num(norm), ")"));
  }
  return Eigen::Vector3d(result / norm);
}

// The polyline's corner at points[corner], between the segment from the
// point before it and the segment to `next`, must not fold the cable back.
absl::Status CheckCorner(absl::string_view cable_path, int corner,
                         const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& next) {
  const Eigen::Vector3d in = points[corner] - points[corner - 1];
  const Eigen::Vector3d out = next - points[corner];
  const double cosine = in.dot(out) / (in.norm() * out.norm());
  const double turn_degrees = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / kPi;
  if (!(turn_degrees <= plausible::kMaxCornerTurnDegrees)) {
    return Invalid(Indexed(cable_path, "points", corner),
                   absl::StrFormat("the polyline folds back at this corner (turns by %.1f "
                                   "degrees; at most %g)",
                                   turn_degrees, plausible::kMaxCornerTurnDegrees));
  }
  return absl::OkStatus();
}

bool IsProbeNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

// Validates a scene and builds the engine's scene from it, stopping at the
// first invalid field.
// The first Newton or linear-solver setting `s` gives (the settings only an
// implicit step uses), or nullptr.
const char* NewtonSettingGiven(const v1::Solver& s) {
  for (const auto& [has, field] :
       {std::pair{s.has_newton_tolerance(), "solver.newton_tolerance"},
        std::pair{s.has_max_newton_iterations(), "solver.max_newton_iterations"},
        std::pair{s.has_linear_tolerance(), "solver.linear_tolerance"},
        std::pair{s.has_max_linear_iterations(), "solver.max_linear_iterations"},
        std::pair{s.preconditioner() != v1::Solver::PRECONDITIONER_UNSPECIFIED,
                  "solver.preconditioner"},
        std::pair{s.accept_inexact_solves(), "solver.accept_inexact_solves"}}) {
    if (has) return field;
  }
  return nullptr;
}

class SceneConverter {
 public:
  explicit SceneConverter(const v1::Scene& proto) : proto_(proto) {}

  absl::StatusOr<Scene> Convert() {
    CABLESIM_RETURN_IF_ERROR(CheckNameLength("name", proto_.name()));
    scene_.name = proto_.name();
    switch (proto_.model()) {
      case v1::Scene::MODEL_UNSPECIFIED:
      case v1::Scene::AUTO:
        scene_.model = ModelChoice::kAuto;
        break;
      case v1::Scene::PLANAR:
        scene_.model = ModelChoice::kPlanar;
        break;
      case v1::Scene::SPATIAL:
        scene_.model = ModelChoice::kSpatial;
        break;
      default:
        return Invalid("model", absl::StrCat("unknown value ", static_cast<int>(proto_.model()),
                                             " (expected AUTO, PLANAR or SPATIAL)"));
    }
    CABLESIM_ASSIGN_OR_RETURN(scene_.gravity_m_s2, VectorInRange("gravity", proto_.gravity(), plausible::kGravity));
    scene_.output.shape = proto_.output().shape();
    scene_.output.statistics = proto_.output().statistics();
    scene_.output.reactions = proto_.output().reactions();
    scene_.output.tension = proto_.output().tension();
    scene_.output.orientation = proto_.output().orientation();
    {
      const v1::Rainflow& r = proto_.output().rainflow();
      scene_.output.rainflow.columns.assign(r.columns().begin(), r.columns().end());
      scene_.output.rainflow.sn_slope = r.sn_slope();
      scene_.output.rainflow.equivalent_cycles = r.equivalent_cycles();
    }
    if (proto_.cables_size() == 0 && proto_.bodies_size() == 0) {
      return Invalid("cables", "a scene needs at least one cable or body");
    }
    scene_.cables.resize(proto_.cables_size());
    for (int i = 0; i < proto_.cables_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(ConvertCable(i, &scene_.cables[i]));
    }
    scene_.bodies.resize(proto_.bodies_size());
    for (int i = 0; i < proto_.bodies_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(ConvertBody(i, &scene_.bodies[i]));
    }
    scene_.joints.resize(proto_.joints_size());
    for (int i = 0; i < proto_.joints_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(ConvertJoint(i, &scene_.joints[i]));
    }
    // Bodies threaded on a cable: a PIN at each face, after the scene's own.
    for (const JointSpec& joint : threaded_joints_) scene_.joints.push_back(joint);
    scene_.loads.resize(proto_.loads_size());
    for (int i = 0; i < proto_.loads_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(ConvertLoad(i, &scene_.loads[i]));
    }
    scene_.probes.resize(proto_.probes_size());
    for (int i = 0; i < proto_.probes_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(ConvertProbe(i, &scene_.probes[i]));
    }
    CABLESIM_RETURN_IF_ERROR(ConvertInitialVelocity());
    CABLESIM_RETURN_IF_ERROR(ConvertFluid());
    CABLESIM_RETURN_IF_ERROR(ConvertSeabed());
    for (int i = 0; i < static_cast<int>(scene_.bodies.size()); ++i)
      if (!scene_.bodies[i].contact_points_m.empty() && !scene_.seabed.enabled)
        return Invalid(Sub(Indexed("", "bodies", i), "seabed_contact"), "needs a seabed");
    CABLESIM_RETURN_IF_ERROR(ConvertSheaves());
    CABLESIM_RETURN_IF_ERROR(ConvertSolver());
    return std::move(scene_);
  }

 private:
  // Registers `name` of item `index` in `names`; `path` is the name field.
  static absl::Status RegisterName(absl::string_view path, absl::string_view kind,
                                   const std::string& name, int index,
                                   std::map<std::string, int, std::less<>>* names) {
    if (name.empty()) return Invalid(path, "required");
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(path, name));
    const auto [it, inserted] = names->emplace(name, index);
    if (!inserted) {
      return Invalid(
          path, absl::StrCat("duplicate name \"", name, "\" (also ", kind, "[", it->second, "])"));
    }
    return absl::OkStatus();
  }

  absl::Status ConvertCable(int i, CableSpec* cable) {
    const v1::Cable& c = proto_.cables(i);
    const std::string path = Indexed("", "cables", i);
    CABLESIM_RETURN_IF_ERROR(RegisterName(Sub(path, "name"), "cables", c.name(), i, &cable_index_));
    cable->name = c.name();

    cable->elements = c.has_elements() ? c.elements() : kDefaultElements;
    CABLESIM_RETURN_IF_ERROR(
        CheckIntRange(Sub(path, "elements"), cable->elements, 1, kMaxElements));

    // Geometry: a polyline, or start + direction * length.
    if (c.points_size() > 0) {
      if (c.has_start())
        return Invalid(Sub(path, "start"), "give either start/direction or points");
      if (c.has_direction()) {
        return Invalid(Sub(path, "direction"), "give either start/direction or points");
      }
      if (c.points_size() < 2) {
        return Invalid(Sub(path, "points"),
                       absl::StrCat("needs at least 2 points (got ", c.points_size(), ")"));
      }
      double polyline_length = 0;
      for (int j = 0; j < c.points_size(); ++j) {
        const std::string point_path = Indexed(path, "points", j);
        CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d p,
                                  VectorInRange(point_path, c.points(j), plausible::kCoordinate));
        if (j > 0) {
          const Eigen::Vector3d& previous = cable->points.back();
          const double segment = (p - previous).norm();
          const double scale = std::max(p.norm(), previous.norm());
          if (!(segment > 1e-12 * scale) || segment == 0) {
            return Invalid(point_path, absl::StrCat("same as points[", j - 1,
                                                    "] (consecutive points must differ)"));
          }
          if (j > 1) CABLESIM_RETURN_IF_ERROR(CheckCorner(path, j - 1, cable->points, p));
          polyline_length += segment;
        }
        cable->points.push_back(p);
      }
      if (!(polyline_length >= plausible::kCableLength.lo &&
            polyline_length <= plausible::kCableLength.hi)) {
        return Invalid(Sub(path, "points"),
                       absl::StrCat("polyline length must be in [", Num(plausible::kCableLength.lo),
                                    ", ", Num(plausible::kCableLength.hi), "] m (got ",
                                    Num(polyline_length), ")"));
      }
      if (c.has_length()) {
        CABLESIM_RETURN_IF_ERROR(
            CheckPositiveInRange(Sub(path, "length"), c.length(), plausible::kCableLength));
        cable->length_m = c.length();
      } else {
        cable->length_m = polyline_length;
      }
    } else {
      CABLESIM_ASSIGN_OR_RETURN(const Eigen::Vector3d start,
                                VectorInRange(Sub(path, "start"), c.start(), plausible::kCoordinate));
      Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
      if (c.has_direction()) {
        CABLESIM_ASSIGN_OR_RETURN(direction,
                                  Direction(Sub(path, "direction"), c.direction()));
      }
      if (!c.has_length()) return Invalid(Sub(path, "length"), "required (or give points)");
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "length"), c.length(), plausible::kCableLength));
      cable->length_m = c.length();
      cable->points = {start, Eigen::Vector3d(start + direction * cable->length_m)};
    }

    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange(Sub(path, "density"), c.density(), plausible::kDensity));
    cable->density_kg_m3 = c.density();
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "youngs_modulus"), c.youngs_modulus(),
                                                  plausible::kYoungsModulus));
    cable->youngs_modulus_pa = c.youngs_modulus();

    if (c.has_diameter()) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "diameter"), c.diameter(), plausible::kSize));
    }
    const double d = c.diameter();
    if (c.has_area()) {
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "area"), c.area(), plausible::kArea));
      cable->area_m2 = c.area();
    } else if (c.has_diameter()) {
      cable->area_m2 = kPi * d * d / 4;
    } else {
      return Invalid(Sub(path, "area"), "required (give area or diameter)");
    }

    CABLESIM_ASSIGN_OR_RETURN(cable->bending, BendingFromProto(c.bending(), Sub(path, "bending")));
    const bool no_bending = cable->bending == BendingModel::kNone;
    if (c.has_second_moment()) {
      const std::string moment_path = Sub(path, "second_moment");
      CABLESIM_RETURN_IF_ERROR(no_bending ? CheckNonNegative(moment_path, c.second_moment())
                                          : CheckPositive(moment_path, c.second_moment()));
      if (c.second_moment() != 0) {
        CABLESIM_RETURN_IF_ERROR(
            CheckRange(moment_path, c.second_moment(), plausible::kSecondMoment));
      }
      cable->second_moment_m4 = c.second_moment();
    } else if (c.has_diameter()) {
      cable->second_moment_m4 = kPi * d * d * d * d / 64;
    } else if (no_bending) {
      cable->second_moment_m4 = 0;
    } else {
      return Invalid(Sub(path, "second_moment"),
                     "required unless bending is NONE (give second_moment or diameter)");
    }
    if (!std::isfinite(cable->area_m2) || !(cable->area_m2 > 0) ||
        !std::isfinite(cable->second_moment_m4)) {
      return Invalid(Sub(path, "diameter"), "section properties out of range");
    }
    if (c.has_hydrodynamics()) {
      const v1::Hydrodynamics& h = c.hydrodynamics();
      const std::string hydro_path = Sub(path, "hydrodynamics");
      if (!(proto_.fluid().density() > 0)) {
        return Invalid(hydro_path, "needs a fluid around the cables (fluid.density > 0)");
      }
      for (const auto& [name, value, out] :
           {std::tuple{"normal_drag", h.normal_drag(), &cable->normal_drag},
            std::tuple{"tangential_drag", h.tangential_drag(), &cable->tangential_drag},
            std::tuple{"added_mass", h.added_mass(), &cable->added_mass}}) {
        CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(hydro_path, name), value));
        CABLESIM_RETURN_IF_ERROR(
            CheckRange(Sub(hydro_path, name), value, plausible::kHydroCoefficient));
        *out = value;
      }
      if (h.has_diameter()) {
        CABLESIM_RETURN_IF_ERROR(
            CheckPositiveInRange(Sub(hydro_path, "diameter"), h.diameter(), plausible::kSize));
        cable->hydro_diameter_m = h.diameter();
      }
    }
    switch (c.axial_law()) {
      case v1::AXIAL_LAW_UNSPECIFIED:
      case v1::GREEN_LAGRANGE:
        cable->axial_law = AxialLaw::kGreenLagrange;
        break;
      case v1::ENGINEERING:
        cable->axial_law = AxialLaw::kEngineering;
        break;
      default:
        return Invalid(Sub(path, "axial_law"),
                       absl::StrCat("unknown value ", c.axial_law(),
                                    " (must be GREEN_LAGRANGE or ENGINEERING)"));
    }
    if (c.has_winch()) {
      if (cable->axial_law == AxialLaw::kEngineering) {
        return Invalid(Sub(path, "axial_law"),
                       "ENGINEERING is not available on a cable with a winch (its line tension "
                       "is the Green-Lagrange law's)");
      }
      cable->winch.enabled = true;
      CABLESIM_ASSIGN_OR_RETURN(cable->winch.speed,
                                ConvertTimeFunction(Sub(Sub(path, "winch"), "speed"),
                                                    c.winch().speed(), plausible::kVelocity));
    }
    if (c.has_damping()) {
      const v1::CableDamping& d = c.damping();
      const std::string damping_path = Sub(path, "damping");
      for (const auto& [name, value, out, range] :
           {std::tuple{"axial_time", d.axial_time(), &cable->axial_damping_s,
                       &plausible::kDampingTime},
            std::tuple{"bending_time", d.bending_time(), &cable->bending_damping_s,
                       &plausible::kDampingTime},
            std::tuple{"rayleigh_alpha", d.rayleigh_alpha(), &cable->rayleigh_alpha_1_s,
                       &plausible::kRayleighAlpha},
            std::tuple{"rayleigh_beta", d.rayleigh_beta(), &cable->rayleigh_beta_s,
                       &plausible::kDampingTime}}) {
        CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(damping_path, name), value));
        CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, name), value, *range));
        *out = value;
      }
    }
    return absl::OkStatus();
  }

  absl::Status ConvertBody(int i, BodySpec* body) {
    const v1::Body& b = proto_.bodies(i);
    const std::string path = Indexed("", "bodies", i);
    CABLESIM_RETURN_IF_ERROR(RegisterName(Sub(path, "name"), "bodies", b.name(), i, &body_index_));
    body->name = b.name();

    if (b.has_cylinder()) {
      if (b.has_mass()) {
        return Invalid(Sub(path, "mass"),
                       "give either cylinder + density or mass + inertia, not both");
      }
      if (b.has_inertia()) {
        return Invalid(Sub(path, "inertia"),
                       "follows from the cylinder; give inertia only with mass");
      }
      const std::string cylinder_path = Sub(path, "cylinder");
      const double d = b.cylinder().diameter();
      const double h = b.cylinder().height();
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(cylinder_path, "diameter"), d, plausible::kSize));
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(cylinder_path, "height"), h, plausible::kSize));
      if (!b.has_density()) return Invalid(Sub(path, "density"), "required with cylinder");
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "density"), b.density(), plausible::kDensity));
      const double m = b.density() * kPi * d * d / 4 * h;
      const double r = d / 2;
      const double transverse = m * (3 * r * r + h * h) / 12;
      body->mass_kg = m;
      body->inertia_kg_m2 = Eigen::Vector3d(m * d * d / 8, transverse, transverse);
      if (!std::isfinite(m) || !(m > 0) || !body->inertia_kg_m2.allFinite() ||
          !(body->inertia_kg_m2.minCoeff() > 0)) {
        return Invalid(cylinder_path, "mass or inertia out of range");
      }
    } else if (b.has_mass()) {
      if (b.has_density()) {
        return Invalid(Sub(path, "density"),
                       "only with cylinder (give either cylinder + density or mass + inertia)");
      }
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "mass"), b.mass(), plausible::kMass));
      body->mass_kg = b.mass();
      const std::string inertia_path = Sub(path, "inertia");
      CABLESIM_ASSIGN_OR_RETURN(body->inertia_kg_m2, FiniteVector(inertia_path, b.inertia()));
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(inertia_path, "x"), b.inertia().x()));
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(inertia_path, "y"), b.inertia().y()));
      CABLESIM_RETURN_IF_ERROR(CheckPositive(Sub(inertia_path, "z"), b.inertia().z()));
      CABLESIM_RETURN_IF_ERROR(VectorInRange(inertia_path, b.inertia(), plausible::kInertia).status());
    } else if (b.has_density()) {
      return Invalid(Sub(path, "cylinder"), "required with density");
    } else {
      return Invalid(Sub(path, "mass"), "required (give cylinder + density, or mass + inertia)");
    }

    if (b.has_seabed_contact()) CABLESIM_RETURN_IF_ERROR(ConvertBodyContact(path, b, body));
    CABLESIM_RETURN_IF_ERROR(ConvertBodyHydrodynamics(i, b, body));
    // Damping before the placement: a body placed `on` a cable returns
    // from there (its damping was silently dropped before).
    if (b.has_damping()) {
      const std::string damping_path = Sub(path, "damping");
      CABLESIM_RETURN_IF_ERROR(
          CheckNonNegative(Sub(damping_path, "linear"), b.damping().linear()));
      CABLESIM_RETURN_IF_ERROR(
          CheckNonNegative(Sub(damping_path, "angular"), b.damping().angular()));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, "linear"), b.damping().linear(),
                                          plausible::kDampingCoefficient));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(damping_path, "angular"), b.damping().angular(),
                                          plausible::kDampingCoefficient));
      body->linear_damping_n_s_m = b.damping().linear();
      body->angular_damping_n_m_s = b.damping().angular();
    }
    if (b.has_on()) return PlaceOnCable(i, b);
    CABLESIM_ASSIGN_OR_RETURN(body->position_m, VectorInRange(Sub(path, "position"), b.position(), plausible::kCoordinate));
    body->axis = Eigen::Vector3d::UnitX();
    if (b.has_axis()) {
      CABLESIM_ASSIGN_OR_RETURN(body->axis, Direction(Sub(path, "axis"), b.axis()));
    }
    return absl::OkStatus();
  }

  // Body.seabed_contact: the points, their spring, damper and friction.
  absl::Status ConvertBodyContact(const std::string& path, const v1::Body& b, BodySpec* body) {
    const v1::BodySeabedContact& c = b.seabed_contact();
    const std::string contact_path = Sub(path, "seabed_contact");
    if (c.points_size() == 0)
      return Invalid(Sub(contact_path, "points"), "at least one point is required");
    for (int k = 0; k < c.points_size(); ++k) {
      CABLESIM_ASSIGN_OR_RETURN(
          const Eigen::Vector3d point,
          VectorInRange(Indexed(contact_path, "points", k), c.points(k), plausible::kCoordinate));
      body->contact_points_m.push_back(point);
    }
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(contact_path, "stiffness"), c.stiffness(),
                                                  plausible::kStiffness));
    body->contact_stiffness_n_m = c.stiffness();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(contact_path, "damping"), c.damping()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(contact_path, "damping"), c.damping(), plausible::kDampingCoefficient));
    body->contact_damping_n_s_m = c.damping();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(contact_path, "friction"), c.friction()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange(Sub(contact_path, "friction"), c.friction(), plausible::kFrictionCoefficient));
    body->contact_friction = c.friction();
    return absl::OkStatus();
  }

  // Body.hydrodynamics (BodyFluidLoad): the cylinder's size from the
  // body's cylinder unless given; coefficients >= 0.
  absl::Status ConvertBodyHydrodynamics(int i, const v1::Body& b, BodySpec* body) {
    if (!b.has_hydrodynamics()) return absl::OkStatus();
    const v1::BodyHydrodynamics& h = b.hydrodynamics();
    const std::string path = Sub(Indexed("", "bodies", i), "hydrodynamics");
    if (!(proto_.fluid().density() > 0))
      return Invalid(path, "needs a fluid around the body (fluid.density > 0)");
    if (!(scene_.gravity_m_s2.norm() > 0))
      return Invalid(path, "needs gravity (it sets the vertical and the buoyancy)");
    for (const auto& [name, given, value, from_cylinder, out] :
         {std::tuple{"diameter", h.has_diameter(), h.diameter(), b.cylinder().diameter(),
                     &body->hydro_diameter_m},
          std::tuple{"height", h.has_height(), h.height(), b.cylinder().height(),
                     &body->hydro_height_m}}) {
      if (!given && !b.has_cylinder())
        return Invalid(Sub(path, name), "required for a body given by mass (no cylinder)");
      const double v = given ? value : from_cylinder;
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, name), v, plausible::kSize));
      *out = v;
    }
    for (const auto& [name, value, out] :
         {std::tuple{"drag_coefficient", h.drag_coefficient(), &body->hydro_drag},
          std::tuple{"heave_drag_coefficient", h.heave_drag_coefficient(),
                     &body->hydro_heave_drag},
          std::tuple{"added_mass", h.added_mass(), &body->hydro_added_mass},
          std::tuple{"heave_added_mass", h.heave_added_mass(), &body->hydro_heave_added_mass}}) {
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, name), value));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, name), value, plausible::kHydroCoefficient));
      *out = value;
    }
    body->has_hydrodynamics = true;
    return absl::OkStatus();
  }

  // Body.on: the position and axis from the cable's polyline (the points
  // the model builder lays the cable's nodes at), and for a threaded body
  // the two PIN joints at its faces.
  absl::Status PlaceOnCable(int i, const v1::Body& b) {
    BodySpec* body = &scene_.bodies[i];
    const std::string path = Indexed("", "bodies", i);
    const std::string on = Sub(path, "on");
    if (b.has_position()) return Invalid(Sub(path, "position"), "not with on (the cable places the body)");
    if (b.has_axis()) return Invalid(Sub(path, "axis"), "not with on (the cable's tangent is the axis)");
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(on, "cable"), b.on().cable()));
    const auto it = cable_index_.find(b.on().cable());
    if (it == cable_index_.end()) {
      return Invalid(Sub(on, "cable"), absl::StrCat("no cable named \"", b.on().cable(), "\""));
    }
    const CableSpec& cable = scene_.cables[it->second];
    const double length = cable.length_m, s = b.on().s();
    const std::string s_path = Sub(on, "s");
    CABLESIM_RETURN_IF_ERROR(CheckFinite(s_path, s));
    const double half = b.on().threaded() ? b.cylinder().height() / 2 : 0;
    if (b.on().threaded() && !b.has_cylinder()) {
      return Invalid(Sub(on, "threaded"),
                     "needs cylinder (its faces are where the cable enters and leaves)");
    }
    const double tolerance = kArcLengthTolerance * length;
    if (s - half < -tolerance || s + half > length + tolerance) {
      return Invalid(s_path, absl::StrCat("must be in [", Num(half), ", ", Num(length - half),
                                          "] (got ", Num(s), ")"));
    }
    Eigen::Vector3d point, tangent;
    if (!b.on().threaded()) {
      PolylineAt(cable.points, std::clamp(s, 0.0, length) / length, &point, &tangent);
      body->position_m = point;
      body->axis = tangent;
      return absl::OkStatus();
    }
    const double s1 = std::max(s - half, 0.0), s2 = std::min(s + half, length);
    Eigen::Vector3d p1, p2;
    PolylineAt(cable.points, s1 / length, &p1, &tangent);
    PolylineAt(cable.points, s2 / length, &p2, &tangent);
    const double chord = (p2 - p1).norm();
    if (!(chord > 0)) return Invalid(s_path, "the cable's faces coincide");
    body->position_m = (p1 + p2) / 2;
    body->axis = (p2 - p1) / chord;
    for (const auto& [arc, x] : {std::pair{s1, -chord / 2}, std::pair{s2, chord / 2}}) {
      JointSpec joint;
      joint.type = JointType::kPin;
      joint.a.cable = it->second;
      joint.a.s_m = arc;
      joint.b.body = i;
      joint.b.point_body_m = Eigen::Vector3d(x, 0, 0);
      threaded_joints_.push_back(joint);
    }
    return absl::OkStatus();
  }

  // A cable point, a body point or (when `allow_ground`) the ground.
  absl::StatusOr<Attachment> ConvertAttachment(absl::string_view path, const v1::Attachment& a,
                                               bool allow_ground) const {
    Attachment result;
    const bool on_cable = !a.cable().empty();
    const bool on_body = !a.body().empty();
    if (on_cable && on_body) return Invalid(path, "names both a cable and a body");
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "cable"), a.cable()));
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "body"), a.body()));
    if (on_cable) {
      const auto it = cable_index_.find(a.cable());
      if (it == cable_index_.end()) {
        return Invalid(Sub(path, "cable"), absl::StrCat("no cable named \"", a.cable(), "\""));
      }
      if (a.has_point()) return Invalid(Sub(path, "point"), "only with body");
      result.cable = it->second;
      const double length = scene_.cables[it->second].length_m;
      const std::string s_path = Sub(path, "s");
      CABLESIM_RETURN_IF_ERROR(CheckFinite(s_path, a.s()));
      const double tolerance = kArcLengthTolerance * length;
      if (a.s() < -tolerance || a.s() > length + tolerance) {
        return Invalid(s_path,
                       absl::StrCat("must be in [0, ", Num(length), "] (got ", Num(a.s()), ")"));
      }
      result.s_m = std::clamp(a.s(), 0.0, length);
      return result;
    }
    if (on_body) {
      const auto it = body_index_.find(a.body());
      if (it == body_index_.end()) {
        return Invalid(Sub(path, "body"), absl::StrCat("no body named \"", a.body(), "\""));
      }
      if (a.s() != 0) return Invalid(Sub(path, "s"), "only with cable");
      result.body = it->second;
      CABLESIM_ASSIGN_OR_RETURN(result.point_body_m, VectorInRange(Sub(path, "point"), a.point(), plausible::kCoordinate));
      return result;
    }
    if (!allow_ground) return Invalid(path, "must name a cable or a body");
    if (a.s() != 0) return Invalid(Sub(path, "s"), "only with cable");
    if (a.has_point()) return Invalid(Sub(path, "point"), "only with body");
    return result;  // ground
  }

  absl::Status ConvertJoint(int i, JointSpec* joint) const {
    const v1::Joint& j = proto_.joints(i);
    const std::string path = Indexed("", "joints", i);
    CABLESIM_ASSIGN_OR_RETURN(joint->type, JointTypeFromProto(j.type(), Sub(path, "type")));
    CABLESIM_ASSIGN_OR_RETURN(joint->a, ConvertAttachment(Sub(path, "a"), j.a(), false));
    CABLESIM_ASSIGN_OR_RETURN(joint->b, ConvertAttachment(Sub(path, "b"), j.b(), true));
    const Attachment& a = joint->a;
    const Attachment& b = joint->b;
    if (a.cable >= 0 && a.cable == b.cable) {
      const double length = scene_.cables[a.cable].length_m;
      if (std::abs(a.s_m - b.s_m) <= kArcLengthTolerance * length) {
        return Invalid(Sub(path, "b"),
                       absl::StrCat("same place as side a (cable \"", scene_.cables[a.cable].name,
                                    "\" at s = ", Num(a.s_m), ")"));
      }
    }
    if (a.body >= 0 && a.body == b.body) {
      return Invalid(Sub(path, "b"),
                     absl::StrCat("joins body \"", scene_.bodies[a.body].name, "\" to itself"));
    }
    CABLESIM_RETURN_IF_ERROR(ConvertSlide(path, j, joint));
    joint->name = j.name();
    if (j.has_motion()) {
      const std::string motion = Sub(path, "motion");
      CABLESIM_ASSIGN_OR_RETURN(joint->motion, ConvertTimeVector(motion, j.motion(), plausible::kCoordinate));
      if (joint->HasMotion() && !b.IsGround()) {
        return Invalid(motion, "only a joint to ground moves (side b must be the ground)");
      }
      for (int d = 0; d < 3; ++d) {
        const double start = joint->motion[d](0);
        if (std::abs(start) > 1e-12) {
          return Invalid(Sub(motion, std::string(1, "xyz"[d])),
                         absl::StrCat("must be 0 at t = 0 (the scene places the joint at its "
                                      "start; got ",
                                      Num(start), " m)"));
        }
      }
    }
    if (j.has_rotation()) {
      const std::string rotation = Sub(path, "rotation");
      CABLESIM_ASSIGN_OR_RETURN(joint->rotation, ConvertTimeFunction(rotation, j.rotation(), plausible::kAngle));
      if (joint->HasRotation() && (!b.IsGround() || joint->type != JointType::kFixed)) {
        return Invalid(rotation,
                       "only a FIXED joint to ground turns (a PIN holds no direction; side b "
                       "must be the ground)");
      }
      if (const double start = joint->rotation(0); std::abs(start) > 1e-12) {
        return Invalid(rotation, absl::StrCat("must be 0 at t = 0 (the scene places the joint at "
                                              "its start; got ",
                                              Num(start), " rad)"));
      }
    }
    if (j.coupled()) {
      const std::string coupled = Sub(path, "coupled");
      if (!b.IsGround()) return Invalid(coupled, "only a joint to ground is coupled (side b must be the ground)");
      if (joint->type == JointType::kSlide) return Invalid(coupled, "not with type SLIDE");
      if (!IsZero(joint->motion)) return Invalid(coupled, "not with motion (the host moves the point)");
      if (joint->HasRotation()) return Invalid(coupled, "not with rotation (the host moves the point)");
      joint->coupled = true;
    }
    if (j.has_rotation_axis()) {
      const std::string axis = Sub(path, "rotation_axis");
      if (!j.has_rotation()) return Invalid(axis, "only with rotation");
      CABLESIM_ASSIGN_OR_RETURN(joint->rotation_axis, Direction(axis, j.rotation_axis()));
    }
    return ConvertRelease(path, j, joint);
  }

  // Joint.release (line failure): a PIN or FIXED joint whose force is its
  // rows' multipliers, not a moving, turning or coupled support (their
  // force columns and work belong to the support), nor a winch's end.
  absl::Status ConvertRelease(const std::string& path, const v1::Joint& j,
                              JointSpec* joint) const {
    if (!j.has_release()) return absl::OkStatus();
    const std::string release = Sub(path, "release");
    const v1::Release& r = j.release();
    if (!r.has_time() && !r.has_breaking_load())
      return Invalid(release, "needs time or breaking_load");
    if (joint->type == JointType::kSlide)
      return Invalid(release, "not with type SLIDE (only a PIN or FIXED joint lets go)");
    if (joint->HasMotion() || joint->HasRotation())
      return Invalid(release, "not on a moving or turning support");
    for (const Attachment* at : {&joint->a, &joint->b}) {
      if (at->cable < 0 || !scene_.cables[at->cable].winch.enabled) continue;
      const double length = scene_.cables[at->cable].length_m;
      if (std::abs(at->s_m - length) <= kArcLengthTolerance * length)
        return Invalid(release, "not at a winch's end (the winch holds the line)");
    }
    if (r.has_time()) {
      if (!(r.time() >= 0) || !std::isfinite(r.time()))
        return Invalid(Sub(release, "time"), absl::StrCat("must be >= 0 and finite (got ", Num(r.time()), ")"));
      joint->release_time_s = r.time();
    }
    if (r.has_breaking_load()) {
      if (!(r.breaking_load() > 0) || !std::isfinite(r.breaking_load()))
        return Invalid(Sub(release, "breaking_load"),
                       absl::StrCat("must be > 0 and finite (got ", Num(r.breaking_load()), ")"));
      joint->breaking_load_n = r.breaking_load();
    }
    return absl::OkStatus();
  }

  // A SLIDE joint: a body on one side, a cable on the other, no motion;
  // `slide` only with SLIDE.
  absl::Status ConvertSlide(const std::string& path, const v1::Joint& j, JointSpec* joint) const {
    const std::string slide = Sub(path, "slide");
    if (joint->type != JointType::kSlide) {
      if (j.has_slide()) return Invalid(slide, "only with type SLIDE");
      return absl::OkStatus();
    }
    const Attachment& a = joint->a;
    const Attachment& b = joint->b;
    if (!((a.body >= 0 && b.cable >= 0) || (a.cable >= 0 && b.body >= 0))) {
      return Invalid(Sub(path, "b"), "SLIDE joins a body on one side to a cable on the other");
    }
    if (j.has_motion()) return Invalid(Sub(path, "motion"), "not with type SLIDE");
    const v1::Slide& p = j.slide();
    if (!(p.friction() >= 0) || !std::isfinite(p.friction()))
      return Invalid(Sub(slide, "friction"), "must be >= 0");
    if (!(p.stiffness() >= 0) || !std::isfinite(p.stiffness()))
      return Invalid(Sub(slide, "stiffness"), "must be >= 0");
    if (!(p.stick_velocity() >= 0) || !std::isfinite(p.stick_velocity()))
      return Invalid(Sub(slide, "stick_velocity"), "must be > 0");
    joint->slide.friction = p.friction();
    joint->slide.stiffness_n_m = p.stiffness();
    if (p.stick_velocity() > 0) joint->slide.stick_velocity_m_s = p.stick_velocity();
    return absl::OkStatus();
  }

  absl::Status ConvertLoad(int i, LoadSpec* load) const {
    const v1::Load& l = proto_.loads(i);
    const std::string path = Indexed("", "loads", i);
    CABLESIM_ASSIGN_OR_RETURN(load->at, ConvertAttachment(Sub(path, "at"), l.at(), false));
    CABLESIM_ASSIGN_OR_RETURN(load->force_n, VectorInRange(Sub(path, "force"), l.force(), plausible::kForce));
    const std::string torque_path = Sub(path, "torque");
    CABLESIM_ASSIGN_OR_RETURN(load->torque_nm, VectorInRange(torque_path, l.torque(), plausible::kTorque));
    if (load->at.cable >= 0) {
      if (!load->torque_nm.isZero(0)) return Invalid(torque_path, "allowed on bodies only");
    }
    if (l.has_varying_force()) {
      CABLESIM_ASSIGN_OR_RETURN(load->varying_force_n,
                                ConvertTimeVector(Sub(path, "varying_force"), l.varying_force(), plausible::kForce));
    }
    if (l.has_varying_torque()) {
      const std::string varying_torque = Sub(path, "varying_torque");
      CABLESIM_ASSIGN_OR_RETURN(load->varying_torque_nm,
                                ConvertTimeVector(varying_torque, l.varying_torque(), plausible::kTorque));
      if (load->at.cable >= 0 && !IsZero(load->varying_torque_nm))
        return Invalid(varying_torque, "allowed on bodies only");
    }
    return absl::OkStatus();
  }

  absl::Status ConvertProbe(int i, ProbeSpec* probe) {
    const v1::Probe& p = proto_.probes(i);
    const std::string path = Indexed("", "probes", i);
    const std::string name_path = Sub(path, "name");
    CABLESIM_RETURN_IF_ERROR(CheckNameLength(name_path, p.name()));
    if (!p.name().empty() && !std::all_of(p.name().begin(), p.name().end(), IsProbeNameChar)) {
      return Invalid(name_path, absl::StrCat("\"", p.name(),
                                             "\" may contain only letters, digits, '_', '-' "
                                             "and '.'"));
    }
    CABLESIM_RETURN_IF_ERROR(RegisterName(name_path, "probes", p.name(), i, &probe_index_));
    probe->name = p.name();
    v1::Attachment at;
    at.set_cable(p.cable());
    at.set_s(p.s());
    at.set_body(p.body());
    if (p.has_point()) *at.mutable_point() = p.point();
    CABLESIM_ASSIGN_OR_RETURN(probe->at, ConvertAttachment(path, at, false));
    return absl::OkStatus();
  }

  absl::Status ConvertFluid() {
    const v1::Fluid& f = proto_.fluid();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.density", f.density()));
    if (f.density() != 0)
      CABLESIM_RETURN_IF_ERROR(CheckRange("fluid.density", f.density(), plausible::kDensity));
    scene_.fluid.density_kg_m3 = f.density();
    CABLESIM_ASSIGN_OR_RETURN(scene_.fluid.current_m_s,
                              VectorInRange("fluid.current", f.current(), plausible::kVelocity));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange("fluid.still_water_level", f.still_water_level(), plausible::kCoordinate));
    scene_.fluid.still_water_level_m = f.still_water_level();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.water_depth", f.water_depth()));
    if (f.water_depth() != 0) {
      CABLESIM_RETURN_IF_ERROR(
          CheckRange("fluid.water_depth", f.water_depth(), plausible::kCableLength));
    }
    scene_.fluid.water_depth_m = f.water_depth();
    return ConvertWaves();
  }

  // A wave's direction of travel: its part normal to gravity, normalised.
  // Omitted: x (y when gravity is along x).
  absl::StatusOr<Eigen::Vector3d> WaveDirection(absl::string_view path, bool given,
                                                const v1::Vec3& v) {
    const Eigen::Vector3d up = -scene_.gravity_m_s2.normalized();
    Eigen::Vector3d d = Eigen::Vector3d::UnitX();
    if (given) {
      CABLESIM_ASSIGN_OR_RETURN(d, Direction(path, v));
    } else if (std::abs(up.x()) > 0.99) {
      d = Eigen::Vector3d::UnitY();
    }
    const Eigen::Vector3d horizontal = d - up.dot(d) * up;
    if (!(horizontal.norm() >= 1e-6)) {
      return Invalid(path, "must have a horizontal part (it is along gravity)");
    }
    return Eigen::Vector3d(horizontal.normalized());
  }

  absl::Status ConvertWaves() {
    const v1::Fluid& f = proto_.fluid();
    if (!f.has_waves()) return absl::OkStatus();
    const v1::Waves& w = f.waves();
    WavesSpec& spec = scene_.fluid.waves;
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("fluid.waves.ramp_time", w.ramp_time()));
    CABLESIM_RETURN_IF_ERROR(CheckRange("fluid.waves.ramp_time", w.ramp_time(), plausible::kDuration));
    spec.ramp_s = w.ramp_time();
    if (w.regular_size() == 0 && w.jonswap_size() == 0) return absl::OkStatus();
    if (!(f.density() > 0)) return Invalid("fluid.waves", "needs a fluid (fluid.density > 0)");
    if (!(f.water_depth() > 0)) {
      return Invalid("fluid.water_depth", "must be > 0 with waves (their kinematics depend on it)");
    }
    if (!(scene_.gravity_m_s2.norm() > 0)) {
      return Invalid("fluid.waves", "needs gravity (it sets the vertical and the waves' speed)");
    }
    for (int i = 0; i < w.regular_size(); ++i) {
      const v1::Waves::Regular& r = w.regular(i);
      const std::string path = Indexed("fluid.waves", "regular", i);
      RegularWaveSpec out;
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "height"), r.height(), plausible::kSize));
      out.height_m = r.height();
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "period"), r.period(), plausible::kWavePeriod));
      out.period_s = r.period();
      CABLESIM_ASSIGN_OR_RETURN(out.direction,
                                WaveDirection(Sub(path, "direction"), r.has_direction(), r.direction()));
      CABLESIM_RETURN_IF_ERROR(CheckRange(Sub(path, "phase"), r.phase(), plausible::kPhase));
      out.phase_rad = r.phase();
      spec.regular.push_back(out);
    }
    for (int i = 0; i < w.jonswap_size(); ++i) {
      const v1::Waves::Jonswap& j = w.jonswap(i);
      const std::string path = Indexed("fluid.waves", "jonswap", i);
      JonswapSpec out;
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "significant_height"),
                                                    j.significant_height(), plausible::kSize));
      out.significant_height_m = j.significant_height();
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "peak_period"), j.peak_period(), plausible::kWavePeriod));
      out.peak_period_s = j.peak_period();
      if (j.peak_factor() != 0) {
        CABLESIM_RETURN_IF_ERROR(CheckFinite(Sub(path, "peak_factor"), j.peak_factor()));
        if (!(j.peak_factor() >= 1 && j.peak_factor() <= 100)) {
          return Invalid(Sub(path, "peak_factor"),
                         absl::StrCat("must be >= 1 and <= 100 (got ", Num(j.peak_factor()), ")"));
        }
        out.peak_factor = j.peak_factor();
      }
      out.seed = j.seed();
      if (j.components() != 0) {
        CABLESIM_RETURN_IF_ERROR(
            CheckIntRange(Sub(path, "components"), j.components(), 1, kMaxWaveComponents));
        out.components = j.components();
      }
      CABLESIM_ASSIGN_OR_RETURN(out.direction,
                                WaveDirection(Sub(path, "direction"), j.has_direction(), j.direction()));
      spec.jonswap.push_back(out);
    }
    return absl::OkStatus();
  }

  absl::Status ConvertSeabed() {
    if (!proto_.has_seabed()) return absl::OkStatus();
    const v1::Seabed& b = proto_.seabed();
    SeabedSpec& spec = scene_.seabed;
    spec.enabled = true;
    CABLESIM_RETURN_IF_ERROR(CheckRange("seabed.depth", b.depth(), plausible::kCoordinate));
    spec.depth_m = b.depth();
    if (b.has_normal()) {
      CABLESIM_ASSIGN_OR_RETURN(spec.normal, Direction("seabed.normal", b.normal()));
    } else if (scene_.gravity_m_s2.norm() > 0) {
      spec.normal = -scene_.gravity_m_s2.normalized();
    } else {
      return Invalid("seabed.normal", "must be given when gravity is zero");
    }
    CABLESIM_RETURN_IF_ERROR(
        CheckPositiveInRange("seabed.stiffness", b.stiffness(), plausible::kStiffness));
    spec.stiffness_n_m2 = b.stiffness();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("seabed.damping", b.damping()));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange("seabed.damping", b.damping(), plausible::kDampingCoefficient));
    spec.damping_n_s_m2 = b.damping();
    CABLESIM_RETURN_IF_ERROR(CheckNonNegative("seabed.friction_axial", b.friction_axial()));
    CABLESIM_RETURN_IF_ERROR(CheckRange("seabed.friction_axial", b.friction_axial(),
                                        plausible::kFrictionCoefficient));
    spec.friction_axial = b.friction_axial();
    CABLESIM_RETURN_IF_ERROR(
        CheckNonNegative("seabed.friction_transverse", b.friction_transverse()));
    CABLESIM_RETURN_IF_ERROR(CheckRange("seabed.friction_transverse", b.friction_transverse(),
                                        plausible::kFrictionCoefficient));
    spec.friction_transverse = b.friction_transverse();
    if (b.friction_speed() != 0) {
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.friction_speed", b.friction_speed(),
                                                    plausible::kFrictionSpeed));
      spec.friction_speed_m_s = b.friction_speed();
    }
    if (b.friction_length() != 0) {
      CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("seabed.friction_length", b.friction_length(),
                                                    plausible::kFrictionLength));
      spec.friction_length_m = b.friction_length();
    }
    if (b.has_bathymetry()) CABLESIM_RETURN_IF_ERROR(ConvertBathymetry(b));
    return absl::OkStatus();
  }

  absl::Status ConvertSheaves() {
    constexpr int kMaxSheaves = 64;  // MultibodyModel keeps a 64-bit mask per element
    if (proto_.sheaves_size() > kMaxSheaves)
      return Invalid("sheaves", absl::StrCat("at most ", kMaxSheaves, " (got ",
                                             proto_.sheaves_size(), ")"));
    for (int i = 0; i < proto_.sheaves_size(); ++i) {
      const v1::Sheave& w = proto_.sheaves(i);
      const std::string path = absl::StrCat("sheaves[", i, "]");
      SheaveSpec spec;
      CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "name"), w.name()));
      spec.name = w.name();
      if (!w.body().empty()) {
        CABLESIM_RETURN_IF_ERROR(CheckNameLength(Sub(path, "body"), w.body()));
        const auto it = body_index_.find(w.body());
        if (it == body_index_.end())
          return Invalid(Sub(path, "body"), absl::StrCat("no body named \"", w.body(), "\""));
        spec.body = it->second;
        if (w.has_position())
          return Invalid(Sub(path, "position"),
                         "not with body (the wheel is centred on the body's centre of mass)");
      }
      CABLESIM_ASSIGN_OR_RETURN(spec.position_m, FiniteVector(Sub(path, "position"), w.position()));
      for (int k = 0; k < 3; ++k)
        CABLESIM_RETURN_IF_ERROR(
            CheckRange(Sub(path, "position"), spec.position_m(k), plausible::kCoordinate));
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange(Sub(path, "radius"), w.radius(), plausible::kSize));
      spec.radius_m = w.radius();
      if (w.has_axis()) {
        CABLESIM_ASSIGN_OR_RETURN(spec.axis, Direction(Sub(path, "axis"), w.axis()));
      }
      for (int c = 0; c < w.cables_size(); ++c) {
        const std::string cable_path = absl::StrCat(path, ".cables[", c, "]");
        CABLESIM_RETURN_IF_ERROR(CheckNameLength(cable_path, w.cables(c)));
        const auto it = cable_index_.find(w.cables(c));
        if (it == cable_index_.end())
          return Invalid(cable_path, absl::StrCat("no cable named \"", w.cables(c), "\""));
        spec.cables.push_back(it->second);
      }
      if (w.has_stiffness()) {
        CABLESIM_RETURN_IF_ERROR(
            CheckPositiveInRange(Sub(path, "stiffness"), w.stiffness(), plausible::kStiffness));
        spec.stiffness_n_m2 = w.stiffness();
      } else {
        // EA / R^2 of the stiffest cable it touches: a cable under
        // tension T = eps EA sinks p = T / (k R) = eps R into it.
        double ea = 0;
        for (int c = 0; c < static_cast<int>(scene_.cables.size()); ++c) {
          if (!spec.Touches(c)) continue;
          ea = std::max(ea, scene_.cables[c].youngs_modulus_pa * scene_.cables[c].area_m2);
        }
        if (!(ea > 0)) return Invalid(Sub(path, "stiffness"), "must be given (no cable to touch)");
        spec.stiffness_n_m2 = ea / (spec.radius_m * spec.radius_m);
      }
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "damping"), w.damping()));
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(Sub(path, "damping"), w.damping(), plausible::kDampingCoefficient));
      spec.damping_n_s_m2 = w.damping();
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative(Sub(path, "friction"), w.friction()));
      CABLESIM_RETURN_IF_ERROR(
          CheckRange(Sub(path, "friction"), w.friction(), plausible::kFrictionCoefficient));
      spec.friction = w.friction();
      if (w.has_friction_speed()) {
        CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange(Sub(path, "friction_speed"),
                                                      w.friction_speed(), plausible::kFrictionSpeed));
        spec.friction_speed_m_s = w.friction_speed();
      }
      scene_.sheaves.push_back(std::move(spec));
    }
    return absl::OkStatus();
  }

  // The grid replaces the plane: depth 0, the normal a coordinate axis.
  absl::Status ConvertBathymetry(const v1::Seabed& b) {
    const v1::Bathymetry& g = b.bathymetry();
    BathymetrySpec& spec = scene_.seabed.bathymetry;
    constexpr int kMaxNodes = 10000000;
    if (b.depth() != 0)
      return Invalid("seabed.depth", "must be 0 with a bathymetry grid (the grid gives the depths)");
    const Eigen::Vector3d& n = scene_.seabed.normal;
    if (n.cwiseAbs().maxCoeff() != 1.0)
      return Invalid("seabed.normal",
                     "must be along a coordinate axis with a bathymetry grid (the grid's up)");
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("seabed.bathymetry.nx", g.nx(), 1, kMaxNodes));
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("seabed.bathymetry.ny", g.ny(), 1, kMaxNodes));
    const int64_t count = static_cast<int64_t>(g.nx()) * g.ny();
    if (count > kMaxNodes)
      return Invalid("seabed.bathymetry",
                     absl::StrCat("at most ", kMaxNodes, " nodes (got nx*ny = ", count, ")"));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange("seabed.bathymetry.origin_x", g.origin_x(), plausible::kCoordinate));
    CABLESIM_RETURN_IF_ERROR(
        CheckRange("seabed.bathymetry.origin_y", g.origin_y(), plausible::kCoordinate));
    if (g.nx() > 1) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange("seabed.bathymetry.dx", g.dx(), plausible::kCableLength));
    }
    if (g.ny() > 1) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange("seabed.bathymetry.dy", g.dy(), plausible::kCableLength));
    }
    if (g.depths_size() != count)
      return Invalid("seabed.bathymetry.depths", absl::StrCat("expected nx*ny = ", count,
                                                              " values, got ", g.depths_size()));
    spec.depths_m.resize(count);
    for (int i = 0; i < g.depths_size(); ++i) {
      CABLESIM_RETURN_IF_ERROR(CheckRange(absl::StrCat("seabed.bathymetry.depths[", i, "]"),
                                          g.depths(i), plausible::kCoordinate));
      spec.depths_m[i] = g.depths(i);
    }
    spec.enabled = true;
    spec.origin_x_m = g.origin_x();
    spec.origin_y_m = g.origin_y();
    spec.dx_m = g.nx() > 1 ? g.dx() : 1.0;
    spec.dy_m = g.ny() > 1 ? g.dy() : 1.0;
    spec.nx = g.nx();
    spec.ny = g.ny();
    return absl::OkStatus();
  }

  absl::Status ConvertInitialVelocity() {
    const v1::InitialVelocity& v = proto_.initial_velocity();
    InitialVelocitySpec& spec = scene_.initial_velocity;
    CABLESIM_ASSIGN_OR_RETURN(
        spec.linear_m_s,
        VectorInRange("initial_velocity.linear", v.linear(), plausible::kVelocity));
    CABLESIM_ASSIGN_OR_RETURN(
        spec.angular_rad_s,
        VectorInRange("initial_velocity.angular", v.angular(), plausible::kAngularVelocity));
    CABLESIM_ASSIGN_OR_RETURN(
        spec.origin_m, VectorInRange("initial_velocity.origin", v.origin(), plausible::kCoordinate));
    return absl::OkStatus();
  }

  absl::Status ConvertSolver() {
    const v1::Solver& s = proto_.solver();
    SolverSettings& out = scene_.solver;
    CABLESIM_ASSIGN_OR_RETURN(out.analysis, AnalysisFromProto(s.analysis(), "solver.analysis"));
    CABLESIM_ASSIGN_OR_RETURN(out.integrator,
                              IntegratorFromProto(s.integrator(), "solver.integrator"));
    CABLESIM_ASSIGN_OR_RETURN(out.linear_solver,
                              LinearSolverFromProto(s.linear_solver(), "solver.linear_solver"));

    CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.duration", s.duration()));
    CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.step", s.step()));
    CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.output_interval", s.output_interval()));
    out.step_s = s.has_step() ? s.step() : kDefaultStep;
    CABLESIM_RETURN_IF_ERROR(CheckPositiveInRange("solver.step", out.step_s, plausible::kStep));
    out.output_interval_s = s.has_output_interval() ? s.output_interval() : out.step_s;
    CABLESIM_RETURN_IF_ERROR(CheckPositive("solver.output_interval", out.output_interval_s));
    out.duration_s = s.duration();
    CABLESIM_RETURN_IF_ERROR(CheckRange("solver.duration", s.duration(), plausible::kDuration));
    if (out.analysis == Analysis::kDynamic) {
      if (!(s.duration() > 0)) {
        return Invalid("solver.duration", absl::StrCat("must be > 0 for DYNAMIC analysis (got ",
                                                       Num(s.duration()), ")"));
      }
      if (out.duration_s / out.step_s > plausible::kMaxNominalSteps) {
        return Invalid("solver.step",
                       absl::StrCat("solver.duration / solver.step is ",
                                    Num(out.duration_s / out.step_s), " steps (at most ",
                                    Num(plausible::kMaxNominalSteps), ")"));
      }
      if (out.step_s > out.duration_s * (1 + kTimeTolerance)) {
        return Invalid("solver.step",
                       absl::StrCat("must be <= solver.duration (", Num(out.duration_s), "; got ",
                                    Num(out.step_s), ")"));
      }
      if (out.output_interval_s > out.duration_s * (1 + kTimeTolerance)) {
        return Invalid("solver.output_interval",
                       absl::StrCat("must be <= solver.duration (", Num(out.duration_s), "; got ",
                                    Num(out.output_interval_s), ")"));
      }
      if (out.duration_s / out.output_interval_s > kMaxFrames) {
        return Invalid(
            "solver.output_interval",
            absl::StrCat("too many frames (duration / output_interval > ", Num(kMaxFrames), ")"));
      }
    } else {
      CABLESIM_RETURN_IF_ERROR(CheckNonNegative("solver.duration", s.duration()));
    }

    out.load_steps = s.has_load_steps() ? s.load_steps() : kDefaultLoadSteps;
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("solver.load_steps", out.load_steps, 1, kMaxLoadSteps));
    out.newton_tolerance =
        s.has_newton_tolerance() ? s.newton_tolerance() : kDefaultNewtonTolerance;
    CABLESIM_RETURN_IF_ERROR(CheckTolerance("solver.newton_tolerance", out.newton_tolerance));
    out.max_newton_iterations =
        s.has_max_newton_iterations() ? s.max_newton_iterations() : kDefaultMaxNewtonIterations;
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("solver.max_newton_iterations",
                                           out.max_newton_iterations, 1, kMaxNewtonIterations));
    out.max_step_halvings =
        s.has_max_step_halvings() ? s.max_step_halvings() : kDefaultMaxStepHalvings;
    CABLESIM_RETURN_IF_ERROR(
        CheckIntRange("solver.max_step_halvings", out.max_step_halvings, 0, kMaxStepHalvings));
    out.linear_tolerance =
        s.has_linear_tolerance() ? s.linear_tolerance() : kDefaultLinearTolerance;
    CABLESIM_RETURN_IF_ERROR(CheckTolerance("solver.linear_tolerance", out.linear_tolerance));
    out.max_linear_iterations =
        s.has_max_linear_iterations() ? s.max_linear_iterations() : kDefaultMaxLinearIterations;
    CABLESIM_RETURN_IF_ERROR(CheckIntRange("solver.max_linear_iterations",
                                           out.max_linear_iterations, 1, kMaxLinearIterations));
    switch (s.preconditioner()) {
      case v1::Solver::PRECONDITIONER_UNSPECIFIED:
      case v1::Solver::BLOCK:
        out.preconditioner = PreconditionerKind::kBlock;
        break;
      case v1::Solver::JACOBI:
        out.preconditioner = PreconditionerKind::kJacobi;
        break;
      case v1::Solver::NONE:
        out.preconditioner = PreconditionerKind::kNone;
        break;
      default:
        return Invalid("solver.preconditioner", "unknown value");
    }
    out.accept_inexact_solves = s.accept_inexact_solves();
    if (s.has_modes()) {
      if (out.analysis != Analysis::kModal) {
        return Invalid("solver.modes", absl::StrCat("is only for MODAL analysis (solver.analysis is ",
                                                    std::string(AnalysisName(out.analysis)), ")"));
      }
      CABLESIM_RETURN_IF_ERROR(CheckIntRange("solver.modes", s.modes(), 1, kMaxModes));
      out.modes = s.modes();
    }

    const IntegratorTraits& traits = TraitsOf(out.integrator);
    out.auto_integrator = s.integrator() == v1::AUTO_STEPPER;
    if (out.auto_integrator) {
      // The settings that only an implicit stepper uses keep AUTO implicit
      // (rather than be ignored by an explicit one, or refused).
      if (s.has_rho_infinity()) {
        out.auto_keep_implicit = "solver.rho_infinity";
      } else if (s.has_reuse_factorization()) {
        out.auto_keep_implicit = "solver.reuse_factorization";
      } else if (s.linear_solver() == v1::MINRES || s.linear_solver() == v1::GMRES) {
        out.auto_keep_implicit = "solver.linear_solver";
      } else if (const char* field = NewtonSettingGiven(s); field != nullptr) {
        out.auto_keep_implicit = field;
      }
    }
    if (s.has_rho_infinity()) {
      if (!traits.has_rho_infinity) {
        return Invalid("solver.rho_infinity",
                       "applies to GENERALIZED_ALPHA and HHT only (solver.integrator is " +
                           std::string(IntegratorName(out.integrator)) + ")");
      }
      const double lo = traits.min_rho_infinity;
      if (!(s.rho_infinity() >= lo && s.rho_infinity() <= 1)) {
        return Invalid("solver.rho_infinity",
                       absl::StrCat("must be in [", Num(lo), ", 1] for ",
                                    std::string(IntegratorName(out.integrator)), " (got ",
                                    Num(s.rho_infinity()), ")"));
      }
      out.rho_infinity = s.rho_infinity();
    }
    out.adaptive = s.adaptive();
    out.error_estimate = s.error_estimate();
    // Steppers whose Newton matrix can be kept across iterations and steps
    // (IntegratorTraits::keeps_newton_matrix).
    const bool keeps_matrix = traits.keeps_newton_matrix;
    // Default on for the alpha family; off for ENERGY_MOMENTUM, whose point
    // is conservation: with a kept matrix Newton converges linearly and
    // stops just under its tolerance, and those residuals add up (the 100 s
    // falling pendulum drifted by 2e-5 of its energy with it, 5e-7 without).
    out.reuse_factorization =
        s.has_reuse_factorization() ? s.reuse_factorization() : traits.reuses_matrix_by_default;
    if (s.has_reuse_factorization() && s.reuse_factorization() && !keeps_matrix) {
      return Invalid("solver.reuse_factorization",
                     "applies to GENERALIZED_ALPHA, HHT and ENERGY_MOMENTUM only (solver.integrator is " +
                         std::string(IntegratorName(out.integrator)) + ")");
    }
    // Explicit steppers take no Newton iteration and solve only with the
    // constant mass matrix, factored once: the Newton and linear-solver
    // settings do not apply to them, unless a static solve runs first
    // (analysis STATIC or MODAL, or initial_state STATIC), which uses them.
    const bool static_solve = out.analysis != Analysis::kDynamic ||
                              s.initial_state() == v1::Solver::STATIC;
    if (traits.is_explicit && !static_solve) {
      const std::string name(IntegratorName(out.integrator));
      const std::string why = "does not apply to " + name +
                              " (explicit: no Newton iteration; it solves only with the constant "
                              "mass matrix, factored once)";
      if (s.linear_solver() == v1::MINRES || s.linear_solver() == v1::GMRES)
        return Invalid("solver.linear_solver", why);
      if (const char* field = NewtonSettingGiven(s); field != nullptr) return Invalid(field, why);
    }
    // The tolerances hold adaptive steps and every DYNAMIC run's error
    // estimate (engine/run/run_warnings.h).
    for (const auto& [has, name] : {std::pair{s.has_tolerance(), "solver.tolerance"},
                                    std::pair{s.has_relative_tolerance(),
                                              "solver.relative_tolerance"}}) {
      if (has && out.analysis != Analysis::kDynamic) {
        return Invalid(name, absl::StrCat("applies to DYNAMIC analysis only (solver.analysis is ",
                                          std::string(AnalysisName(out.analysis)), ")"));
      }
    }
    out.strict = s.strict();
    switch (s.initial_state()) {
      case v1::Solver::INITIAL_STATE_UNSPECIFIED:
      case v1::Solver::AS_GIVEN:
        break;
      case v1::Solver::STATIC:
        if (out.analysis != Analysis::kDynamic) {
          return Invalid("solver.initial_state", "STATIC applies to DYNAMIC analysis only");
        }
        out.initial_state = InitialState::kStatic;
        break;
      default:
        return Invalid("solver.initial_state",
                       absl::StrCat("unknown value ", static_cast<int>(s.initial_state()),
                                    " (expected AS_GIVEN or STATIC)"));
    }
    if ((out.adaptive || out.error_estimate) && out.analysis != Analysis::kDynamic) {
      return Invalid(out.adaptive ? "solver.adaptive" : "solver.error_estimate",
                     "applies to DYNAMIC analysis only");
    }
    if (s.has_tolerance()) {
      CABLESIM_RETURN_IF_ERROR(
          CheckPositiveInRange("solver.tolerance", s.tolerance(), plausible::kErrorTolerance));
      out.tolerance_m = s.tolerance();
    }
    if (s.has_relative_tolerance()) {
      CABLESIM_RETURN_IF_ERROR(CheckFinite("solver.relative_tolerance", s.relative_tolerance()));
      CABLESIM_RETURN_IF_ERROR(
          CheckNonNegative("solver.relative_tolerance", s.relative_tolerance()));
      if (!(s.relative_tolerance() < 1)) {
        return Invalid("solver.relative_tolerance",
                       absl::StrCat("must be < 1 (got ", Num(s.relative_tolerance()), ")"));
      }
      out.relative_tolerance = s.relative_tolerance();
    }
    // What the run's error estimate is held to: the scene's tolerance, the
    // adaptive controller's default, or for fixed steps a default relative
    // to the scene's size.
    out.error_tolerance_m = s.has_tolerance() || out.adaptive
                                ? out.tolerance_m
                                : kDefaultRelativeErrorTolerance * SceneSize();
    // Settings given that would do nothing in this run (a table).
    return CheckSolverSettingsApply(s, out);
  }

  // The scene's size for the default error tolerance [m]: its longest
  // cable, at least 1 m.
  double SceneSize() const {
    double size = 1;
    for (const v1::Cable& c : proto_.cables()) size = std::max(size, c.length());
    return size;
  }

  const v1::Scene& proto_;
  Scene scene_;
  std::map<std::string, int, std::less<>> cable_index_;
  std::map<std::string, int, std::less<>> body_index_;
  // The PIN joints at the faces of bodies threaded on a cable (Body.on).
  std::vector<JointSpec> threaded_joints_;
  std::map<std::string, int, std::less<>> probe_index_;
};

absl::Status UnknownEnumValue(absl::string_view path, int value, absl::string_view allowed) {
  return Invalid(path, absl::StrCat("unknown value ", value, " (must be ", allowed, ")"));
}

}  // namespace

absl::StatusOr<Scene> SceneFromProto(const v1::Scene& proto) {
  absl::StatusOr<Scene> scene = SceneConverter(proto).Convert();
  if (scene.ok()) scene->warnings = PlausibilityWarnings(proto, *scene);
  return scene;
}

absl::StatusOr<BendingModel> BendingFromProto(v1::Bending bending, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (bending) {
    case v1::BENDING_UNSPECIFIED:
    case v1::EXACT:
      return BendingModel::kExact;
    case v1::LINEAR:
      return BendingModel::kLinear;
    case v1::Solver::NONE:
      return BendingModel::kNone;
    default:
      return UnknownEnumValue(path, bending, "EXACT, LINEAR or NONE");
  }
}

absl::StatusOr<JointType> JointTypeFromProto(v1::JointType type, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (type) {
    case v1::PIN:
      return JointType::kPin;
    case v1::FIXED:
      return JointType::kFixed;
    case v1::SLIDE:
      return JointType::kSlide;
    default:
      return Invalid(path, "must be PIN, FIXED or SLIDE");
  }
}

absl::StatusOr<Analysis> AnalysisFromProto(v1::Analysis analysis, std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (analysis) {
    case v1::ANALYSIS_UNSPECIFIED:
    case v1::DYNAMIC:
      return Analysis::kDynamic;
    case v1::STATIC:
      return Analysis::kStatic;
    case v1::MODAL:
      return Analysis::kModal;
    default:
      return UnknownEnumValue(path, analysis, "DYNAMIC, STATIC or MODAL");
  }
}

absl::StatusOr<Integrator> IntegratorFromProto(v1::Integrator integrator,
                                               std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (integrator) {
    case v1::IMPLICIT_EULER:
      return Integrator::kImplicitEuler;
    case v1::GENERALIZED_ALPHA:
      return Integrator::kGeneralizedAlpha;
    case v1::INTEGRATOR_UNSPECIFIED:
    case v1::HHT:
      return Integrator::kHht;
    case v1::AUTO_STEPPER:  // HHT until the run chooses (SolverSettings::auto_integrator)
      return Integrator::kHht;
    case v1::ENERGY_MOMENTUM:
      return Integrator::kEnergyMomentum;
    case v1::DORMAND_PRINCE:
      return Integrator::kDormandPrince;
    case v1::CENTRAL_DIFFERENCE:
      return Integrator::kCentralDifference;
    default:
      return UnknownEnumValue(path, integrator,
                              "IMPLICIT_EULER, GENERALIZED_ALPHA, HHT, ENERGY_MOMENTUM, "
                              "DORMAND_PRINCE, CENTRAL_DIFFERENCE or AUTO_STEPPER");
  }
}

absl::StatusOr<LinearSolverKind> LinearSolverFromProto(v1::LinearSolver solver,
                                                       std::string_view path_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  switch (solver) {
    case v1::MINRES:
      return LinearSolverKind::kMinres;
    case v1::GMRES:
      return LinearSolverKind::kGmres;
    case v1::DIRECT:
      return LinearSolverKind::kDirect;
    case v1::LINEAR_SOLVER_UNSPECIFIED:
    case v1::AUTO:
      return LinearSolverKind::kAuto;
    default:
      return UnknownEnumValue(path, solver, "MINRES, GMRES, DIRECT or AUTO");
  }
}


}  // namespace cablesim

#undef CABLESIM_ASSIGN_OR_RETURN_IMPL
#undef CABLESIM_ASSIGN_OR_RETURN
#undef CABLESIM_CONCAT
#undef CABLESIM_CONCAT_INNER
#undef CABLESIM_RETURN_IF_ERROR
