#include "convert/moordyn_deck.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "convert/scene/field_checks.h"
#include "convert/scene_from_proto.h"

namespace cablesim {
namespace {

constexpr double kPi = std::numbers::pi;
using Eigen3 = std::array<double, 3>;  // a point [m]
// A sagging line is laid this much longer than it is (a stretch).
constexpr double kSagLayStretch = 1e-3;
// Units that cannot be right in a line type, refused: a diameter above
// kMaxDiameterM [m] (millimetres given), a density (mass per length over
// the diameter's area) or a modulus (EA over that area) outside these
// bounds. They are ten times wider than the scene's plausibility warnings
// (convert/plausibility_warnings.h: 10 to 25,000 kg/m^3, 1e5 to 1e12 Pa),
// which still warn when the deck runs: MoorDyn's own test decks hold
// synthetic lines (a beam of 51,000 kg/m^3, a line of EA 500 N on 0.1 m)
// that are legal and must be read.
constexpr double kMaxDiameterM = 10;
constexpr double kDeckDensityLo = 1, kDeckDensityHi = 1e5;  // [kg/m^3]
constexpr double kDeckModulusLo = 1e3, kDeckModulusHi = 1e13;  // [Pa]

// MoorDyn's defaults (its MoorDyn2.cpp), used when OPTIONS omits them.
constexpr double kDefaultGravity = 9.80665;
constexpr double kDefaultDensity = 1025;
constexpr double kDefaultKBot = 3.0e6;  // [Pa/m]
constexpr double kDefaultCBot = 3.0e5;  // [Pa s/m]
constexpr double kDefaultFricDamp = 200;  // [N s/m per node]

enum class Section {
  kPreamble, kLineTypes, kRodTypes, kBodies, kRods, kPoints, kLines, kOptions, kOutputs,
  kUnsupported, kEnd
};

struct LineType {
  std::string name;
  int line = 0;
  double diameter = 0, mass_per_length = 0, ea = 0, ba = 0, ei = 0;
  double cd = 0, ca = 0, cd_axial = 0, ca_axial = 0;
  // A tension-strain table (EA given as a file): its knots, as the file
  // gives them; empty for a constant EA.
  std::vector<double> table_strains, table_tensions;
  // A viscoelastic type (EA "EA|EA_D" or "EA|alphaMBL|beta", BA "BA|BA_D"):
  // the dynamic stiffness (constant, or the mean-load law's base and
  // slope) and the dynamic dashpot [N s]; ea and ba are the static ones.
  bool visco = false;
  double ea_dynamic = 0, ea_base = 0, ea_slope = 0, ba_dynamic = 0;
};

enum class PointKind { kFixed, kCoupled, kFree };

struct Point {
  int id = 0;
  int line = 0;
  PointKind kind = PointKind::kFixed;
  double x = 0, y = 0, z = 0;
  double mass = 0, volume = 0, cda = 0, ca = 0;
  // A point on a MoorDyn body ("Body<N>"): the body's ID (0: none) and
  // the point in the body's frame relative to its reference point (x, y,
  // z become its place in the world once the bodies are read). A rod's
  // end ("R<N>A", "R<N>B"): the rod's ID (0: none), which end, and the
  // LINES row that named it (x, y, z: the end's place).
  int body = 0;
  Eigen::Vector3d relative = Eigen::Vector3d::Zero();
  int rod = 0;
  bool rod_end_b = false;
};

// A MoorDyn rod type (ROD TYPES): its diameter [m], mass per length in
// air [kg/m], drag and added-mass coefficients across it and at its ends.
struct RodType {
  std::string name;
  int line = 0;
  double diameter = 0, mass_per_length = 0, cd = 0, ca = 0, cd_end = 0, ca_end = 0;
};

// How a MoorDyn body or rod is held: fixed, free, coupled (driven by a
// host), coupled-pinned (its reference point or end A driven, its
// rotation free), pinned (end A on the ground or a body, rotation free),
// or (rods) rigidly on a body.
enum class Mount { kFixed, kFree, kCoupled, kCoupledPinned, kPinned, kOnBody };

struct MdBody {
  int id = 0;
  int line = 0;
  Mount mount = Mount::kFree;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // the reference point [m]
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double mass = 0, volume = 0, ca = 0;
  // Drag areas along and about the body's axes (CdA: MoorDyn's 1, 2, 3 or
  // 6 numbers) [m^2, m^5].
  Eigen::Vector3d cda = Eigen::Vector3d::Zero(), cda_rotation = Eigen::Vector3d::Zero();
  Eigen::Vector3d cg = Eigen::Vector3d::Zero();       // body frame, from the reference [m]
  Eigen::Vector3d inertia = Eigen::Vector3d::Zero();  // about the CG, body axes [kg m^2]
};

struct Rod {
  int id = 0;
  int line = 0;
  const RodType* type = nullptr;
  Mount mount = Mount::kFree;
  int body = 0;  // kOnBody, or kPinned to a body: the body's ID (0: the ground)
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  // world [m]
  Eigen::Vector3d a_rel = Eigen::Vector3d::Zero(), b_rel = Eigen::Vector3d::Zero();
  int segments = 0;  // 0: MoorDyn's rod of zero length (a point)
  double length() const { return (b - a).norm(); }
};

// What a line end at a body point or rod end is joined to: the ground
// (a fixed body or rod; coupled for a coupled one's), or a scene body at
// a point in its axes relative to its centre of mass.
struct Holder {
  bool ground = true;
  bool coupled = false;
  std::string body;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

struct Line {
  int id = 0;
  int line = 0;
  const LineType* type = nullptr;
  int a = 0, b = 0;  // point ids
  double length = 0;
  int segments = 0;
};

// A line end's tension channel (OUTPUTS): the probe's name (as the deck
// spells it), the line's id, which end (B: s = length), the deck's line.
struct TensionChannel {
  std::string name;
  int line_id = 0;
  bool end_b = false;
  int line = 0;
};

// A body's channel (OUTPUTS Body<n>Px ...): the body's id, whether it is
// a rotation's (R, RV: output.orientation) or the reference point's (P,
// V, A: a probe), the channel as spelled, the deck's line.
struct BodyChannel {
  int body = 0;
  bool rotation = false;
  std::string name;
  int line = 0;
};

struct Option {
  double value = 0;
  int line = 0;
};

class DeckReader {
 public:
  DeckReader(absl::string_view text, absl::string_view file_name, MoorDynFileReader read_file)
      : text_(text), file_(file_name), read_file_(std::move(read_file)) {}

  absl::StatusOr<v1::Scene> Read() {
    if (absl::Status s = Parse(); !s.ok()) return s;
    absl::StatusOr<v1::Scene> scene = Build();
    if (!scene.ok()) return scene;
    // A value the deck allows but the scene's ranges refuse (a million
    // segments, a density no material has): the scene's message, led by
    // the deck's line it came from.
    const absl::StatusOr<Scene> checked = SceneFromProto(*scene);
    if (!checked.ok()) return Located(checked.status());
    return scene;
  }

 private:
  // A scene validation error (`cables[1].elements: ...`) led by the deck's
  // line of what became that part of the scene: a line's LINES row (and
  // its type's row), a free point's POINTS row, an option's row.
  absl::Status Located(const absl::Status& status) const {
    const absl::string_view m = status.message();
    int line = 1;
    std::string where;
    int index = -1;
    auto indexed = [&](absl::string_view prefix) {
      if (!absl::StartsWith(m, prefix)) return false;
      const absl::string_view rest = m.substr(prefix.size());
      return absl::SimpleAtoi(rest.substr(0, rest.find(']')), &index);
    };
    if (indexed("cables[") && index >= 0 && index < static_cast<int>(lines_.size())) {
      line = lines_[index].line;
      where = absl::StrCat(" (its line type on line ", lines_[index].type->line, ")");
    } else if (indexed("bodies[") && index >= 0 && index < static_cast<int>(body_points_.size())) {
      line = body_points_[index];
    } else {
      for (const auto& [prefix, key] :
           {std::pair{"seabed", "kbot"}, std::pair{"fluid", "rho"}, std::pair{"gravity", "g"},
            std::pair{"fluid.waves", "wavekin"}, std::pair{"fluid.current", "currents"}}) {
        const auto it = options_.find(key);
        if (absl::StartsWith(m, prefix) && it != options_.end()) line = it->second.line;
      }
    }
    return absl::Status(status.code(), absl::StrCat(file_, ":", line, where, ": ", m));
  }

  absl::Status Error(int line, absl::string_view field, absl::string_view message) const {
    return absl::InvalidArgumentError(absl::StrCat(file_, ":", line, ": ", field, ": ", message));
  }

  // The text of a file the deck names (read relative to the deck's
  // directory), or the deck's error at line `line`, field `field`:
  // `no_directory` when the deck came as text alone (no reader),
  // `cannot_read` followed by the reader's message when it fails.
  absl::StatusOr<std::string> ReadNamedFile(int line, absl::string_view field,
                                            absl::string_view name,
                                            absl::string_view no_directory,
                                            absl::string_view cannot_read) const {
    if (!read_file_) return Error(line, field, no_directory);
    absl::StatusOr<std::string> text = read_file_(std::string_view(name.data(), name.size()));
    if (!text.ok()) return Error(line, field, absl::StrCat(cannot_read, text.status().message()));
    return text;
  }

  static Section SectionOf(std::string upper) {
    // Words only: "---- LINE TYPES ----" -> "LINE TYPES".
    for (char& c : upper)
      if (c == '-' || c == '=') c = ' ';
    std::vector<std::string> words = absl::StrSplit(upper, ' ', absl::SkipEmpty());
    const std::string name = absl::StrJoin(words, " ");
    if (absl::StrContains(name, "NEED THIS LINE") || name == "END") return Section::kEnd;
    if (absl::StrContains(name, "MOORDYN")) return Section::kPreamble;
    if (absl::StrContains(name, "LINE TYPE") || absl::StrContains(name, "LINE DICTIONARY"))
      return Section::kLineTypes;
    if (absl::StrContains(name, "ROD TYPE") || absl::StrContains(name, "ROD DICTIONARY"))
      return Section::kRodTypes;
    if (absl::StrContains(name, "BOD")) return Section::kBodies;
    if (absl::StartsWith(name, "ROD")) return Section::kRods;
    if (absl::StartsWith(name, "POINT") || absl::StartsWith(name, "CONNECTION") ||
        absl::StartsWith(name, "NODE"))
      return Section::kPoints;
    if (absl::StartsWith(name, "LINE")) return Section::kLines;
    if (absl::StrContains(name, "OPTIONS")) return Section::kOptions;  // also SOLVER OPTIONS
    if (absl::StartsWith(name, "OUTPUT")) return Section::kOutputs;
    return Section::kUnsupported;
  }

  absl::StatusOr<double> Number(int line, absl::string_view field, absl::string_view word) const {
    double v = 0;
    if (!absl::SimpleAtod(word, &v) || !std::isfinite(v)) {
      return Error(line, field, absl::StrCat("\"", word, "\" is not a number"));
    }
    return v;
  }
  absl::StatusOr<double> NonNegative(int line, absl::string_view field,
                                     absl::string_view word) const {
    absl::StatusOr<double> v = Number(line, field, word);
    if (v.ok() && *v < 0) return Error(line, field, absl::StrCat("must be >= 0 (got ", word, ")"));
    return v;
  }
  absl::StatusOr<double> Positive(int line, absl::string_view field, absl::string_view word) const {
    absl::StatusOr<double> v = Number(line, field, word);
    if (v.ok() && !(*v > 0)) {
      return Error(line, field, absl::StrCat("must be > 0 (got ", word, ")"));
    }
    return v;
  }

  // Tables start with a line of column names and one of units.
  static bool IsTable(Section section) {
    return section == Section::kLineTypes || section == Section::kRodTypes ||
           section == Section::kBodies || section == Section::kRods ||
           section == Section::kPoints || section == Section::kLines;
  }

  // A row's words; a word starting with '#' starts a comment.
  static std::vector<absl::string_view> RowWords(absl::string_view raw) {
    std::vector<absl::string_view> w = absl::StrSplit(raw, absl::ByAnyChar(" \t"),
                                                    absl::SkipEmpty());
    for (size_t k = 0; k < w.size(); ++k)
      if (absl::StartsWith(w[k], "#")) {
        w.resize(k);
        break;
      }
    return w;
  }

  // MoorDyn's version 1 format (OpenFAST's MoorDyn decks before MoorDyn v2)
  // opens each table with a count line ("1  NTypes  - number of
  // LineTypes") and orders its columns differently. A deck whose first
  // table opens with one is read by rewriting its rows in the version 2
  // columns, line for line, so that every later message names the file's
  // own line (and the version 2 column): LINE TYPES `Name Diam MassDen EA
  // BA/-zeta Can Cat Cdn Cdt` -> `Name Diam MassDen EA BA/-zeta 0 Cdn Can
  // Cdt Cat` (no bending stiffness), CONNECTION PROPERTIES `Node Type X Y Z
  // M V FX FY FZ CdA CA` -> `Node Type X Y Z M V CdA CA` (the initial force
  // guesses dropped, `Connect` -> `Free`), LINE PROPERTIES `Line LineType
  // UnstrLen NumSegs NodeAnch NodeFair Flags` -> `Line LineType NodeAnch
  // NodeFair UnstrLen NumSegs Flags`. Any other deck is left as it is.
  absl::Status FromVersion1(std::vector<absl::string_view>& lines,
                            std::vector<std::string>& rewritten) const {
    static const char* const kCounts[] = {"ntypes", "nconnects", "nlines", "nrodtypes",
                                          "nrods", "nbodies", "npoints"};
    const auto is_count = [](absl::string_view raw) {
      const std::vector<absl::string_view> w = RowWords(raw);
      for (const char* count : kCounts)
        if (w.size() >= 2 && absl::EqualsIgnoreCase(w[1], count)) return true;
      return false;
    };
    bool version1 = false;
    Section section = Section::kPreamble;
    int row = -1;  // within a table: 0 the count line, 1 and 2 names and units
    for (size_t i = 0; i < lines.size(); ++i) {
      const int n = static_cast<int>(i) + 1;
      const absl::string_view raw = absl::StripAsciiWhitespace(lines[i]);
      if (absl::StartsWith(raw, "---")) {
        section = SectionOf(absl::AsciiStrToUpper(raw));
        if (section == Section::kEnd) break;
        row = IsTable(section) ? 0 : -1;
        if (version1 && row == 0 && section != Section::kLineTypes &&
            section != Section::kPoints && section != Section::kLines) {
          return Error(n, "section",
                       "a version 1 deck (its tables open with count lines, NTypes ...) "
                       "with rods or bodies, which version 1 does not have");
        }
        continue;
      }
      if (raw.empty() || row < 0) continue;
      const int at = row++;
      if (at == 0) {
        // The first table decides the format; the others must follow it.
        if (!version1 && !is_count(raw)) return absl::OkStatus();
        if (!is_count(raw)) {
          return Error(n, "section",
                       "a version 1 deck (count lines, NTypes ...) with a table that opens "
                       "without one");
        }
        version1 = true;
        rewritten[i].clear();  // the count line: read as a blank line
        lines[i] = rewritten[i];
        continue;
      }
      if (at < 3) continue;  // column names and units, skipped as in version 2
      const std::vector<absl::string_view> w = RowWords(raw);
      const auto expect = [&](size_t count, absl::string_view columns) -> absl::Status {
        if (w.size() == count) return absl::OkStatus();
        return Error(n, "version 1 row",
                     absl::StrCat("expected the ", count, " columns ", columns, ", got ",
                                  w.size()));
      };
      std::vector<absl::string_view> v2;
      if (section == Section::kLineTypes) {
        if (absl::Status s = expect(9, "Name Diam MassDen EA BA/-zeta Can Cat Cdn Cdt"); !s.ok())
          return s;
        v2 = {w[0], w[1], w[2], w[3], w[4], "0", w[7], w[5], w[8], w[6]};
      } else if (section == Section::kPoints) {
        if (absl::Status s = expect(12, "Node Type X Y Z M V FX FY FZ CdA CA"); !s.ok()) return s;
        const absl::string_view type =
            absl::EqualsIgnoreCase(w[1], "Connect") ? absl::string_view("Free") : w[1];
        v2 = {w[0], type, w[2], w[3], w[4], w[5], w[6], w[10], w[11]};
      } else {
        if (absl::Status s = expect(7, "Line LineType UnstrLen NumSegs NodeAnch NodeFair Flags");
            !s.ok())
          return s;
        v2 = {w[0], w[1], w[4], w[5], w[2], w[3], w[6]};
      }
      rewritten[i] = absl::StrJoin(v2, " ");
      lines[i] = rewritten[i];
    }
    return absl::OkStatus();
  }

  absl::Status Parse() {
    std::vector<absl::string_view> lines = absl::StrSplit(text_, '\n');
    // A version 1 deck's rows rewritten in the version 2 columns (the
    // lines' numbers kept); `lines` points into it.
    std::vector<std::string> rewritten(lines.size());
    if (absl::Status s = FromVersion1(lines, rewritten); !s.ok()) return s;
    Section section = Section::kPreamble;
    int skip = 0;  // column-name and unit lines still to skip
    absl::string_view header;
    for (size_t i = 0; i < lines.size(); ++i) {
      const int n = static_cast<int>(i) + 1;
      absl::string_view raw = absl::StripAsciiWhitespace(lines[i]);
      if (absl::StartsWith(raw, "---")) {
        section = SectionOf(absl::AsciiStrToUpper(raw));
        header = raw;
        if (section == Section::kEnd) break;
        if (section == Section::kUnsupported) {
          return Error(n, "section", absl::StrCat("\"", raw,
                                                  "\" is not a section cablesim reads (it reads "
                                                  "LINE TYPES, ROD TYPES, BODIES, RODS, POINTS, "
                                                  "LINES, OPTIONS, OUTPUTS)"));
        }
        skip = IsTable(section) ? 2 : 0;
        continue;
      }
      if (raw.empty() || section == Section::kPreamble) continue;
      if (skip > 0) {
        --skip;
        continue;
      }
      const std::vector<absl::string_view> w = RowWords(raw);
      if (w.empty()) continue;
      absl::Status s;
      switch (section) {
        case Section::kLineTypes: s = ParseLineType(n, w); break;
        case Section::kPoints: s = ParsePoint(n, w); break;
        case Section::kLines: s = ParseLine(n, w); break;
        case Section::kOptions: s = ParseOption(n, w); break;
        case Section::kOutputs: s = ParseOutput(n, w); break;
        case Section::kRodTypes: s = ParseRodType(n, w); break;
        case Section::kRods: s = ParseRod(n, w); break;
        case Section::kBodies: s = ParseBody(n, w); break;
        default: break;
      }
      if (!s.ok()) return s;
    }
    // A deck of rods or bodies alone (MoorDyn's RodPinnedFloating.txt)
    // needs no line.
    const bool rigid = !rods_.empty() || !md_bodies_.empty();
    if (line_types_.empty() && !rigid)
      return Error(1, "LINE TYPES", "the deck defines no line type");
    if (lines_.empty() && !rigid) return Error(1, "LINES", "the deck defines no line");
    return ResolveBodiesAndRods();
  }

  absl::Status ParseLineType(int n, const std::vector<absl::string_view>& w) {
    static constexpr const char* kColumns[] = {"TypeName", "Diam", "Mass/m", "EA", "BA/-zeta",
                                               "EI", "Cd", "Ca", "CdAx", "CaAx"};
    if (w.size() < 10 || w.size() > 13) {
      return Error(n, "LINE TYPES",
                   absl::StrCat("expected the 10 columns TypeName Diam Mass/m EA BA/-zeta EI Cd "
                                "Ca CdAx CaAx (and MoorDyn's optional Cl dF cF), got ",
                                w.size()));
    }
    // MoorDyn's 11th to 13th columns: the vortex-induced vibration's lift
    // coefficient and its synchronisation range and centre (which act only
    // with a lift coefficient).
    if (w.size() > 10) {
      double cl = 0;
      if (!absl::SimpleAtod(w[10], &cl) || cl != 0) {
        return Error(n, "LINE TYPES Cl",
                     absl::StrCat("\"", w[10],
                                  "\": vortex-induced vibration (a lift coefficient) cannot be "
                                  "expressed yet (0 only)"));
      }
    }
    LineType t;
    t.name = std::string(w[0]);
    t.line = n;
    for (const LineType& o : line_types_)
      if (o.name == t.name)
        return Error(n, "LINE TYPES TypeName",
                     absl::StrCat("\"", t.name, "\" already defined on line ", o.line));
    auto col = [&](int k) { return absl::StrCat("LINE TYPES ", kColumns[k]); };
    double v = 0;
    // Column k into *out, > 0 (positive) or >= 0.
    auto column = [&](int k, bool positive, double* out) -> absl::Status {
      absl::StatusOr<double> r =
          positive ? Positive(n, col(k), w[k]) : NonNegative(n, col(k), w[k]);
      if (!r.ok()) return r.status();
      *out = *r;
      return absl::OkStatus();
    };
    if (absl::Status s = column(1, true, &t.diameter); !s.ok()) return s;
    if (absl::Status s = column(2, true, &t.mass_per_length); !s.ok()) return s;
    // Units that cannot be right (a deck's numbers are SI): a diameter in
    // millimetres, a mass per length that makes no material's density, an
    // EA in kN or MN that makes no material's modulus. Refused, naming the
    // column, as a deck cannot carry a warning to whoever reads its scene.
    const double area = kPi * t.diameter * t.diameter / 4;
    if (t.diameter > kMaxDiameterM) {
      return Error(n, col(1),
                   absl::StrFormat("%g m: diameters are in metres (a line of 76 mm is 0.076); "
                                   "above %g m is taken for a unit slip",
                                   t.diameter, kMaxDiameterM));
    }
    if (const double rho = t.mass_per_length / area; rho < kDeckDensityLo || rho > kDeckDensityHi) {
      return Error(n, col(2),
                   absl::StrFormat("%g kg/m on a diameter of %g m is a density of %.3g kg/m^3, "
                                   "outside %g to %g: the mass per length is in kg/m and the "
                                   "diameter (volume-equivalent) in m",
                                   t.mass_per_length, t.diameter, rho, kDeckDensityLo, kDeckDensityHi));
    }
    if (absl::SimpleAtod(w[3], &v)) {
      if (absl::Status s = column(3, true, &t.ea); !s.ok()) return s;
      if (const double e = t.ea / area; e < kDeckModulusLo || e > kDeckModulusHi) {
        return Error(n, col(3),
                     absl::StrFormat("%g N over the area of a %g m diameter is a Young's modulus "
                                     "of %.3g Pa, outside %g to %g Pa: EA is in N",
                                     t.ea, t.diameter, e, kDeckModulusLo, kDeckModulusHi));
      }
    } else if (absl::StartsWith(w[3], "SYROPE:")) {
      return Error(n, col(3),
                   absl::StrCat("\"", w[3],
                                "\": the Syrope law (a working curve that moves with the "
                                "largest mean tension) cannot be expressed (a constant EA, a "
                                "tension-strain table file or a viscoelastic EA|EA_D or "
                                "EA|alphaMBL|beta only)"));
    } else if (absl::StrContains(w[3], "|")) {
      // MoorDyn's viscoelastic types: static EA, then the dynamic EA_D
      // (constant) or alphaMBL and beta (the mean-load law).
      const std::vector<absl::string_view> parts = absl::StrSplit(w[3], '|');
      if (parts.size() > 3) {
        return Error(n, col(3),
                     absl::StrCat("\"", w[3], "\": at most 3 values separated by | (EA|EA_D or "
                                  "EA|alphaMBL|beta)"));
      }
      if (!absl::SimpleAtod(parts[0], &v)) {
        return Error(n, col(3),
                     absl::StrCat("\"", w[3], "\": a viscoelastic line's static EA must be a "
                                  "number (a tension-strain table file under a viscoelastic law "
                                  "cannot be expressed)"));
      }
      CABLESIM_ASSIGN_OR_RETURN(t.ea, Positive(n, col(3), parts[0]));
      if (const double e = t.ea / area; e < kDeckModulusLo || e > kDeckModulusHi) {
        return Error(n, col(3),
                     absl::StrFormat("%g N over the area of a %g m diameter is a Young's modulus "
                                     "of %.3g Pa, outside %g to %g Pa: EA is in N",
                                     t.ea, t.diameter, e, kDeckModulusLo, kDeckModulusHi));
      }
      t.visco = true;
      const std::string dyn = absl::StrCat(col(3), " (dynamic)");
      if (parts.size() == 2) {
        CABLESIM_ASSIGN_OR_RETURN(t.ea_dynamic, Positive(n, dyn, parts[1]));
        if (!(t.ea_dynamic > t.ea)) {
          return Error(n, dyn,
                       absl::StrFormat("EA_D %g N must exceed the static EA %g N", t.ea_dynamic,
                                       t.ea));
        }
      } else {
        CABLESIM_ASSIGN_OR_RETURN(t.ea_base, Positive(n, dyn, parts[1]));
        CABLESIM_ASSIGN_OR_RETURN(t.ea_slope, NonNegative(n, dyn, parts[2]));
        if (!(t.ea_base > t.ea)) {
          return Error(n, dyn,
                       absl::StrFormat("alphaMBL %g N must exceed the static EA %g N (the "
                                       "dynamic stiffness at no load)",
                                       t.ea_base, t.ea));
        }
      }
    } else {
      if (absl::Status s = ReadTensionTable(n, col(3), w[3], &t); !s.ok()) return s;
    }
    if (t.visco && absl::StrContains(w[4], "|")) {
      const std::vector<absl::string_view> parts = absl::StrSplit(w[4], '|');
      if (parts.size() > 2) {
        return Error(n, col(4),
                     absl::StrCat("\"", w[4], "\": at most 2 values separated by | (BA|BA_D)"));
      }
      CABLESIM_ASSIGN_OR_RETURN(t.ba, Number(n, col(4), parts[0]));
      CABLESIM_ASSIGN_OR_RETURN(
          t.ba_dynamic,
          NonNegative(n, absl::StrCat(col(4), " (dynamic; a ratio cannot be expressed)"),
                      parts[1]));
    } else if (absl::StrContains(w[4], "|")) {
      return Error(n, col(4),
                   absl::StrCat("\"", w[4],
                                "\": BA|BA_D (a dynamic dashpot) needs a viscoelastic EA "
                                "(EA|EA_D or EA|alphaMBL|beta)"));
    } else if (!absl::SimpleAtod(w[4], &v)) {
      return Error(n, col(4),
                   absl::StrCat("\"", w[4],
                                "\": only one number, a damping coefficient [N s] or a negative "
                                "damping ratio, can be expressed"));
    }
    if (absl::StrContains(w[4], "|")) {
      // (read above)
    } else if (absl::StatusOr<double> r = Number(n, col(4), w[4]); r.ok()) {
      t.ba = *r;
    } else {
      return r.status();
    }
    if (t.visco && t.ba == 0 && t.ba_dynamic == 0) {
      return Error(n, col(4),
                   "a viscoelastic line needs a dashpot: BA or BA_D (after a |) > 0 (without "
                   "one its two springs are one spring of the static EA)");
    }
    if (!absl::SimpleAtod(w[5], &v)) {
      return Error(n, col(5), absl::StrCat("\"", w[5], "\": only a constant EI can be expressed"));
    }
    if (absl::Status s = column(5, false, &t.ei); !s.ok()) return s;
    if (absl::Status s = column(6, false, &t.cd); !s.ok()) return s;
    if (absl::Status s = column(7, false, &t.ca); !s.ok()) return s;
    if (absl::Status s = column(8, false, &t.cd_axial); !s.ok()) return s;
    if (absl::Status s = column(9, false, &t.ca_axial); !s.ok()) return s;
    line_types_.push_back(t);
    return absl::OkStatus();
  }

  // EA given as a file name (MoorDyn's nonlinear line type): the file,
  // relative to the deck's directory, has three header lines, then a knot
  // a line, "strain tension" [-, N] separated by blanks. Its knots become
  // the scene's tension_table (strains from 0 increasing, tensions from 0
  // non-decreasing); the nominal EA is MoorDyn's own for such a type, the
  // last tension over the last strain (what a negative BA, a damping
  // ratio, is scaled by, and EI is divided by).
  absl::Status ReadTensionTable(int n, absl::string_view field, absl::string_view name,
                                LineType* t) const {
    CABLESIM_ASSIGN_OR_RETURN(
        const std::string text,
        ReadNamedFile(n, field, name,
                      absl::StrCat("\"", name,
                                   "\": a tension-strain table file cannot be read here (a deck's "
                                   "text alone, as the service takes it, has no directory): give "
                                   "the scene with cables[].tension_table, or run the deck's file"),
                      absl::StrCat("\"", name, "\": cannot read the tension-strain table: ")));
    auto bad = [&](int row, absl::string_view message) {
      return Error(n, field, absl::StrCat(name, ":", row, ": ", message));
    };
    int row = 0;
    for (absl::string_view raw : absl::StrSplit(text, '\n')) {
      ++row;
      if (row <= 3) continue;  // MoorDyn's three header lines
      const std::vector<absl::string_view> w =
          absl::StrSplit(raw, absl::ByAnyChar(" \t\r,"), absl::SkipEmpty());
      if (w.empty()) continue;
      double strain = 0, tension = 0;
      if (w.size() < 2 || !absl::SimpleAtod(w[0], &strain) ||
          !absl::SimpleAtod(w[1], &tension) || !std::isfinite(strain) ||
          !std::isfinite(tension)) {
        return bad(row, absl::StrCat("expected a strain and a tension, got \"",
                                     absl::StripAsciiWhitespace(raw), "\""));
      }
      if (strain < 0) {
        return bad(row, absl::StrCat("strain ", w[0],
                                     " < 0: compression is not tabulated (the first segment "
                                     "continues into it)"));
      }
      if (!t->table_strains.empty() && !(strain > t->table_strains.back())) {
        return bad(row, absl::StrCat("strain ", w[0], " does not increase"));
      }
      if (strain == 0 && tension != 0) {
        return bad(row, absl::StrCat("tension ", w[1], " at zero strain (must be 0)"));
      }
      if (tension < (t->table_tensions.empty() ? 0.0 : t->table_tensions.back())) {
        return bad(row, absl::StrCat("tension ", w[1],
                                     " is below the row before's (tensions must not decrease)"));
      }
      t->table_strains.push_back(strain);
      t->table_tensions.push_back(tension);
    }
    if (t->table_strains.size() < 2) {
      return Error(n, field,
                   absl::StrCat("\"", name,
                                "\": a tension-strain table needs at least two knots after the "
                                "three header lines (MoorDyn reads one as a constant EA)"));
    }
    if (!(t->table_tensions.back() > 0)) {
      return Error(n, field, absl::StrCat("\"", name, "\": every tension is 0"));
    }
    t->ea = t->table_tensions.back() / t->table_strains.back();
    return absl::OkStatus();
  }

  absl::Status ParsePoint(int n, const std::vector<absl::string_view>& w) {
    static constexpr const char* kColumns[] = {"ID", "Type", "X", "Y", "Z",
                                               "Mass", "Volume", "CdA", "Ca"};
    if (w.size() != 9) {
      return Error(n, "POINTS",
                   absl::StrCat("expected the 9 columns ID Type X Y Z Mass Volume CdA Ca, got ",
                                w.size()));
    }
    auto col = [&](int k) { return absl::StrCat("POINTS ", kColumns[k]); };
    Point p;
    p.line = n;
    if (!absl::SimpleAtoi(w[0], &p.id)) {
      return Error(n, col(0), absl::StrCat("\"", w[0], "\" is not a whole number"));
    }
    if (points_.count(p.id)) {
      return Error(n, col(0), absl::StrCat("point ", p.id, " already defined on line ",
                                           points_[p.id].line));
    }
    const std::string type = absl::AsciiStrToLower(w[1]);
    if (type == "fixed" || type == "fix" || type == "anchor") {
      p.kind = PointKind::kFixed;
    } else if (type == "vessel" || type == "vess" || type == "coupled" || type == "cpld" ||
               type == "fairlead") {
      p.kind = PointKind::kCoupled;
    } else if (type == "free" || type == "connect" || type == "con" || type == "point") {
      p.kind = PointKind::kFree;
    } else if (absl::StartsWith(type, "body") &&
               absl::SimpleAtoi(absl::string_view(type).substr(4), &p.body) && p.body > 0) {
      // On a body: its coordinates are in the body's frame.
      p.kind = PointKind::kFixed;
    } else if (absl::StartsWith(type, "body") || absl::StartsWith(type, "b") ||
               absl::StartsWith(type, "turbine")) {
      return Error(n, col(1), absl::StrCat("\"", w[1],
                                           "\": points on MoorDyn turbines cannot be expressed "
                                           "(Body<N> names a body of BODIES)"));
    } else {
      return Error(n, col(1), absl::StrCat("unknown point type \"", w[1],
                                           "\" (Fixed, Vessel, Coupled or Free)"));
    }
    double* values[] = {&p.x, &p.y, &p.z, &p.mass, &p.volume, &p.cda, &p.ca};
    for (int k = 2; k < 9; ++k) {
      absl::StatusOr<double> v = k < 5 ? Number(n, col(k), w[k]) : NonNegative(n, col(k), w[k]);
      if (!v.ok()) return v.status();
      *values[k - 2] = *v;
    }
    if (p.body > 0) {
      p.relative = Eigen::Vector3d(p.x, p.y, p.z);
      if (p.volume > 0 || p.cda > 0 || p.ca > 0) {
        return Error(n, col(p.volume > 0 ? 6 : p.cda > 0 ? 7 : 8),
                     "a point on a body with volume, drag or added mass cannot be expressed "
                     "(its mass joins the body's; give the volume to the body)");
      }
    }
    points_[p.id] = p;
    return absl::OkStatus();
  }

  absl::StatusOr<int> PointRef(int n, absl::string_view field, absl::string_view word) {
    // A rod's end, R<N>A or R<N>B (also Rod<N>A): a point of its own,
    // placed once the rods are read (ResolveBodiesAndRods).
    {
      const std::string upper = absl::AsciiStrToUpper(word);
      absl::string_view r = upper;
      if (absl::ConsumePrefix(&r, "ROD") || absl::ConsumePrefix(&r, "R")) {
        int rod = 0;
        const bool end_b = absl::EndsWith(r, "B");
        if ((absl::EndsWith(r, "A") || end_b) && absl::SimpleAtoi(r.substr(0, r.size() - 1), &rod) &&
            rod > 0) {
          const int id = -(2 * rod + (end_b ? 1 : 0));  // below every deck's point ID
          if (!points_.count(id)) {
            Point p;
            p.id = id;
            p.line = n;
            p.rod = rod;
            p.rod_end_b = end_b;
            points_[id] = p;
          }
          return id;
        }
      }
    }
    absl::string_view id = word;
    if (absl::StartsWithIgnoreCase(id, "point")) {
      id.remove_prefix(5);
    } else if (absl::StartsWithIgnoreCase(id, "p")) {
      id.remove_prefix(1);
    }
    int k = 0;
    if (!absl::SimpleAtoi(id, &k)) {
      return Error(n, field, absl::StrCat("\"", word,
                                          "\": a line end is a point (N or PN) or a rod's end "
                                          "(R<N>A, R<N>B); a line on a body ends at a point "
                                          "of type Body<N>"));
    }
    if (!points_.count(k)) {
      return Error(n, field, absl::StrCat("point ", k, " does not exist (define it in POINTS "
                                          "before the LINES section)"));
    }
    return k;
  }

  absl::Status ParseLine(int n, const std::vector<absl::string_view>& w) {
    if (w.size() != 6 && w.size() != 7) {
      return Error(n, "LINES",
                   absl::StrCat("expected the columns ID LineType AttachA AttachB UnstrLen "
                                "NumSegs [LineOutputs], got ",
                                w.size()));
    }
    Line l;
    l.line = n;
    if (!absl::SimpleAtoi(w[0], &l.id)) {
      return Error(n, "LINES ID", absl::StrCat("\"", w[0], "\" is not a whole number"));
    }
    for (const Line& o : lines_)
      if (o.id == l.id)
        return Error(n, "LINES ID", absl::StrCat("line ", l.id, " already defined on line ",
                                                 o.line));
    for (const LineType& t : line_types_)
      if (t.name == w[1]) l.type = &t;
    if (l.type == nullptr) {
      return Error(n, "LINES LineType", absl::StrCat("unknown line type \"", w[1], "\""));
    }
    absl::StatusOr<int> a = PointRef(n, "LINES AttachA", w[2]);
    if (!a.ok()) return a.status();
    absl::StatusOr<int> b = PointRef(n, "LINES AttachB", w[3]);
    if (!b.ok()) return b.status();
    if (*a == *b) return Error(n, "LINES AttachB", "a line cannot start and end at one point");
    l.a = *a;
    l.b = *b;
    absl::StatusOr<double> length = Positive(n, "LINES UnstrLen", w[4]);
    if (!length.ok()) return length.status();
    l.length = *length;
    if (!absl::SimpleAtoi(w[5], &l.segments) || l.segments < 1) {
      return Error(n, "LINES NumSegs",
                   absl::StrCat("must be a whole number >= 1 (got ", w[5], ")"));
    }
    lines_.push_back(l);
    return absl::OkStatus();
  }

  absl::Status ParseOption(int n, const std::vector<absl::string_view>& w) {
    if (w.size() < 2) {
      return Error(n, "OPTIONS", "expected a value and an option name");
    }
    const std::string name = absl::AsciiStrToLower(w[1]);
    const std::string field = absl::StrCat("OPTIONS ", w[1]);
    // Options about MoorDyn's own run (its time step and integrator, how
    // it searches for the initial condition, its log and output files):
    // they do not change the equilibrium the scene solves, and cablesim's
    // STATIC analysis (Newton) has no counterpart (docs/moordyn-files.md).
    static const char* const kNoEffect[] = {
        "dtm", "dt", "cfl", "tscheme", "writelog", "writeunits", "disableoutput",
        "disableouttime", "dtout", "dtic", "icdt", "tmaxic", "ictmax", "cdscaleic", "icdfac",
        "threshic", "icthresh", "icgendynamic", "gendynamicic", "fileic", "icfile", "echo",
        "cv", "unifycurrentgrid"};
    for (const char* k : kNoEffect)
      if (name == k) return absl::OkStatus();
    // Names of the translated options and their MoorDyn synonyms.
    static const std::map<std::string, std::string> kTranslated = {
        {"g", "g"},          {"gravity", "g"},     {"rho", "rho"},
        {"wtrdnsty", "rho"}, {"wtrdpth", "depth"}, {"kbot", "kbot"},
        {"kb", "kbot"},      {"cbot", "cbot"},     {"cb", "cbot"},
        {"frictioncoefficient", "mu"}, {"mu_kt", "mu_t"}, {"mu_ka", "mu_a"},
        {"wavekin", "wavekin"}, {"currents", "currents"}, {"statdynfricscale", "mc"},
        {"mc", "mc"}, {"seafloorfile", "seafloor"}, {"dtwave", "dtwave"},
        {"fricdamp", "fricdamp"}};
    const auto it = kTranslated.find(name);
    if (it == kTranslated.end()) {
      return Error(n, field, "an option cablesim does not know (nothing is dropped: remove it or "
                             "ask for its translation)");
    }
    const std::string& key = it->second;
    if (key == "seafloor") {
      // Read in Build (ReadSeafloor): the file's name and this row.
      seafloor_file_ = std::string(w[0]);
      seafloor_line_ = n;
      return absl::OkStatus();
    }
    absl::StatusOr<double> v = Number(n, field, w[0]);
    if (!v.ok()) return v.status();
    if (key == "wavekin" || key == "currents") {
      // The files each value reads are read by Build (WaterKinematics).
      const int mode = static_cast<int>(*v);
      const bool known = key == "wavekin" ? (mode == 0 || mode == 1 || mode == 2 || mode == 3 ||
                                             mode == 7)
                                          : (mode >= 0 && mode <= 5);
      if (mode != *v || !known) {
        return Error(n, field,
                     key == "wavekin"
                         ? absl::StrCat("WaveKin ", w[0], " is not read (0 still water, 1 "
                                        "kinematics from the calling program, 2 and 7 "
                                        "wave_frequencies.txt, 3 wave_elevation.txt; MoorDyn's "
                                        "own setup reads files for 2, 3 and 7 only)")
                         : absl::StrCat("Currents ", w[0], " is not one of MoorDyn's 0 to 5"));
      }
    }
    if (key == "dtwave" && !(*v > 0))
      return Error(n, field, absl::StrCat("must be > 0 (got ", w[0], ")"));
    if (key == "mc" || key == "fricdamp") {
      // MoorDyn's friction law (MoorDynFriction).
      if (!(*v > 0)) return Error(n, field, absl::StrCat("must be > 0 (got ", w[0], ")"));
    }
    // g 0 and WtrDnsty 0 are MoorDyn's weightless and dry scenes.
    if (key == "depth" || key == "kbot") {
      if (!(*v > 0)) return Error(n, field, absl::StrCat("must be > 0 (got ", w[0], ")"));
    } else if (*v < 0) {
      return Error(n, field, absl::StrCat("must be >= 0 (got ", w[0], ")"));
    }
    options_[key] = Option{*v, n};
    return absl::OkStatus();
  }

  // FricDamp or StatDynFricScale given: MoorDyn's friction law (its
  // viscous-then-Coulomb saturation) in place of the regularised Coulomb
  // law. FricDamp [N s/m] acts per node, so per unit length it is FricDamp
  // over the segment length, one value per scene: every line must share
  // its segment length (else refused). MoorDyn's default FricDamp is 200.
  absl::Status MoorDynFriction(v1::Seabed* bed) const {
    const auto damp = options_.find("fricdamp"), scale = options_.find("mc");
    if (damp == options_.end() && scale == options_.end()) return absl::OkStatus();
    const int line = damp != options_.end() ? damp->second.line : scale->second.line;
    const std::string field =
        damp != options_.end() ? "OPTIONS FricDamp" : "OPTIONS StatDynFricScale";
    const double segment = lines_.front().length / lines_.front().segments;
    for (const Line& l : lines_) {
      const double own = l.length / l.segments;
      if (std::abs(own - segment) > 1e-9 * segment) {
        return Error(line, field,
                     absl::StrCat("lines ", lines_.front().id, " and ", l.id,
                                  " differ in segment length (", segment, " and ", own,
                                  " m), and MoorDyn's per-node friction damping becomes one "
                                  "value per unit length per scene"));
      }
    }
    bed->set_friction_law(v1::Seabed::MOORDYN);
    bed->set_friction_damping(OptionOr("fricdamp", kDefaultFricDamp) / segment);
    bed->set_static_friction_scale(OptionOr("mc", 1));
    return absl::OkStatus();
  }

  // The rows of a file WaveKin or Currents names (MoorDyn's fixed names,
  // in the deck's directory): its lines, trailing blanks and carriage
  // returns removed, blank ones kept (MoorDyn counts them).
  absl::StatusOr<std::vector<std::string>> KinematicsFile(const std::string& key,
                                                          absl::string_view name) const {
    const Option& o = options_.at(key);
    const std::string field = key == "wavekin" ? "OPTIONS WaveKin" : "OPTIONS Currents";
    CABLESIM_ASSIGN_OR_RETURN(
        const std::string text,
        ReadNamedFile(o.line, field, name,
                      absl::StrCat(name, " cannot be read here (a deck's text alone, as the "
                                         "service takes it, has no directory): give the scene's "
                                         "fluid fields, or run the deck's file"),
                      absl::StrCat("cannot read ", name, ": ")));
    std::vector<std::string> lines;
    for (absl::string_view raw : absl::StrSplit(text, '\n'))
      lines.emplace_back(absl::StripTrailingAsciiWhitespace(raw));
    while (!lines.empty() && lines.back().empty()) lines.pop_back();
    return lines;
  }

  // The numbers of row `row` (0-based) of file `name`, at least `least`.
  absl::StatusOr<std::vector<double>> Row(const std::string& key, absl::string_view name,
                                          const std::vector<std::string>& lines, size_t row,
                                          size_t least) const {
    const Option& o = options_.at(key);
    const std::string field = key == "wavekin" ? "OPTIONS WaveKin" : "OPTIONS Currents";
    auto bad = [&](absl::string_view message) {
      return Error(o.line, field, absl::StrCat(name, ":", row + 1, ": ", message));
    };
    if (row >= lines.size()) return bad("missing (the file ends before it)");
    std::vector<double> out;
    for (absl::string_view word :
         absl::StrSplit(lines[row], absl::ByAnyChar(" \t,"), absl::SkipEmpty())) {
      double v = 0;
      if (!absl::SimpleAtod(word, &v) || !std::isfinite(v))
        return bad(absl::StrCat("\"", word, "\" is not a number"));
      out.push_back(v);
    }
    if (out.size() < least)
      return bad(absl::StrCat("expected at least ", least, " numbers, got ", out.size()));
    return out;
  }

  // WaveKin and Currents (MoorDyn's Waves setup) as the scene's fluid
  // fields (docs/moordyn-files.md, "Wave and current kinematics").
  absl::Status WaterKinematics(v1::Fluid* fluid) const {
    const int wave_mode = static_cast<int>(OptionOr("wavekin", 0));
    const int current_mode = static_cast<int>(OptionOr("currents", 0));
    if (wave_mode == 2 || wave_mode == 7) {
      if (absl::Status s = WaveFrequencies(wave_mode, fluid->mutable_waves()); !s.ok()) return s;
    } else if (wave_mode == 3) {
      if (absl::Status s = WaveElevation(fluid->mutable_waves()); !s.ok()) return s;
    }
    if (current_mode == 1 || current_mode == 3) return SteadyCurrent(fluid);
    if (current_mode == 2 || current_mode == 4) return DynamicCurrent(fluid);
    if (current_mode == 5) return Current4d(fluid);
    return absl::OkStatus();
  }

  // wave_frequencies.txt: rows "omega Re(A) Im(A) [beta]" (rad/s, m, m,
  // rad), the first at omega = 0. WaveKin 7 sums them as
  // |A| sin(omega t - k l + arg A) (l = x cos beta + y sin beta), WaveKin 2
  // interpolates them linearly onto the multiples of the smallest spacing
  // and sums |A| cos(omega t - k l + arg A) (its inverse FFT): the scene's
  // components with phase pi/2 - arg A and -arg A.
  absl::Status WaveFrequencies(int mode, v1::Waves* waves) const {
    const absl::string_view name = "wave_frequencies.txt";
    absl::StatusOr<std::vector<std::string>> lines = KinematicsFile("wavekin", name);
    if (!lines.ok()) return lines.status();
    const Option& o = options_.at("wavekin");
    auto bad = [&](size_t row, absl::string_view message) {
      return Error(o.line, "OPTIONS WaveKin", absl::StrCat(name, ":", row + 1, ": ", message));
    };
    struct Freq {
      double omega;
      std::complex<double> a;
      double beta;
    };
    std::vector<Freq> rows;
    for (size_t r = 0; r < lines->size(); ++r) {
      absl::StatusOr<std::vector<double>> v = Row("wavekin", name, *lines, r, 3);
      if (!v.ok()) return v.status();
      const double beta = v->size() >= 4 ? (*v)[3] : 0.0;
      if (std::abs(beta) > 2 * kPi)
        return bad(r, "the direction (4th column) must be in [-2 pi, 2 pi] rad");
      if (r == 0 && (*v)[0] != 0)
        return bad(r, "the first frequency must be 0 rad/s (as MoorDyn requires)");
      if (r > 0 && !((*v)[0] > rows.back().omega))
        return bad(r, "frequencies must increase");
      rows.push_back({(*v)[0], {(*v)[1], (*v)[2]}, beta});
    }
    if (rows.size() < 2) return bad(rows.size(), "at least 2 frequencies (the first 0 rad/s)");
    if (std::abs(rows[0].a) != 0)
      return bad(0, "a non-zero amplitude at 0 rad/s (a constant offset of the surface) cannot "
                    "be expressed");
    std::vector<Freq> comps;
    if (mode == 7) {
      comps.assign(rows.begin() + 1, rows.end());
    } else {
      // MoorDyn's even spacing: the smallest spacing dw, components at
      // i dw up to the last frequency, amplitudes and directions linear
      // between the rows; the last is the FFT's Nyquist bin.
      double dw = rows[1].omega;
      for (size_t r = 1; r < rows.size(); ++r) dw = std::min(dw, rows[r].omega - rows[r - 1].omega);
      const int nw = static_cast<int>(std::floor(rows.back().omega / dw)) + 1;
      size_t r = 1;
      for (int i = 1; i < nw; ++i) {
        double w = i * dw;
        while (r + 1 < rows.size() && rows[r].omega < w * (1 - 1e-9)) ++r;
        // A row at this frequency (to round-off): its values as given.
        if (std::abs(rows[r].omega - w) <= 1e-9 * w) w = rows[r].omega;
        const double f = std::clamp((w - rows[r - 1].omega) / (rows[r].omega - rows[r - 1].omega),
                                    0.0, 1.0);
        Freq c{w, rows[r - 1].a + f * (rows[r].a - rows[r - 1].a),
               rows[r - 1].beta + f * (rows[r].beta - rows[r - 1].beta)};
        if (i == nw - 1 && std::abs(c.a) != 0)
          return bad(rows.size() - 1,
                     "a non-zero amplitude at the last frequency (WaveKin 2's Nyquist bin, "
                     "halved by its inverse FFT) cannot be expressed");
        comps.push_back(c);
      }
    }
    for (const Freq& c : comps) {
      if (std::abs(c.a) == 0) continue;
      v1::Waves::Component* out = waves->add_components();
      out->set_amplitude(std::abs(c.a));
      out->set_angular_frequency(c.omega);
      SetVec(out->mutable_direction(), std::cos(c.beta), std::sin(c.beta), 0);
      out->set_phase((mode == 7 ? kPi / 2 : 0.0) - std::arg(c.a));
    }
    return absl::OkStatus();
  }

  // wave_elevation.txt: rows "t eta" (s, m) at the origin; MoorDyn
  // resamples it every dtWave from t = 0, takes its FFT, drops harmonics
  // above 0.5 Hz and sums the rest by linear theory along x.
  absl::Status WaveElevation(v1::Waves* waves) const {
    const absl::string_view name = "wave_elevation.txt";
    absl::StatusOr<std::vector<std::string>> lines = KinematicsFile("wavekin", name);
    if (!lines.ok()) return lines.status();
    v1::Waves::ElevationSeries* e = waves->mutable_elevation_series();
    for (size_t r = 0; r < lines->size(); ++r) {
      absl::StatusOr<std::vector<double>> v = Row("wavekin", name, *lines, r, 2);
      if (!v.ok()) return v.status();
      if (r == 0 && (*v)[0] < 0) {
        return Error(options_.at("wavekin").line, "OPTIONS WaveKin",
                     absl::StrCat(name, ":1: the series must start at t >= 0 (MoorDyn samples "
                                        "it from 0)"));
      }
      // Held at its first value from t = 0, as MoorDyn's interpolation.
      if (r == 0 && (*v)[0] > 0) {
        e->add_times(0);
        e->add_elevations((*v)[1]);
      }
      e->add_times((*v)[0]);
      e->add_elevations((*v)[1]);
    }
    e->set_interval(OptionOr("dtwave", 0.25));  // MoorDyn's default dtWave
    e->set_cutoff_frequency(2 * kPi * 0.5);
    SetVec(e->mutable_direction(), 1, 0, 0);
    return absl::OkStatus();
  }

  // current_profile.txt: three header lines, then rows "z ux [uy [uz]]"
  // (m, m/s): the scene's current_profile, depth = -z.
  absl::Status SteadyCurrent(v1::Fluid* fluid) const {
    const absl::string_view name = "current_profile.txt";
    absl::StatusOr<std::vector<std::string>> lines = KinematicsFile("currents", name);
    if (!lines.ok()) return lines.status();
    std::vector<std::pair<double, std::array<double, 3>>> knots;
    for (size_t r = 3; r < lines->size(); ++r) {
      absl::StatusOr<std::vector<double>> v = Row("currents", name, *lines, r, 2);
      if (!v.ok()) return v.status();
      v->resize(std::max<size_t>(v->size(), 4), 0.0);
      if (!knots.empty() && !(-(*v)[0] < knots.back().first) && !(-(*v)[0] > knots.back().first))
        return Error(options_.at("currents").line, "OPTIONS Currents",
                     absl::StrCat(name, ":", r + 1, ": a depth given twice"));
      knots.push_back({-(*v)[0], {(*v)[1], (*v)[2], (*v)[3]}});
    }
    if (knots.empty()) {
      return Error(options_.at("currents").line, "OPTIONS Currents",
                   absl::StrCat(name, ": no rows after its three header lines"));
    }
    std::sort(knots.begin(), knots.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [depth, u] : knots) {
      v1::Fluid::CurrentPoint* p = fluid->add_current_profile();
      p->set_depth(depth);
      SetVec(p->mutable_velocity(), u[0], u[1], u[2]);
    }
    return absl::OkStatus();
  }

  // current_profile_dynamic.txt: four header lines, the depths row (z,
  // m), a line skipped, then rows "t ux(z_1..z_n) [uy(...) [uz(...)]]":
  // the scene's current_grid with one x and one y.
  absl::Status DynamicCurrent(v1::Fluid* fluid) const {
    const absl::string_view name = "current_profile_dynamic.txt";
    absl::StatusOr<std::vector<std::string>> lines = KinematicsFile("currents", name);
    if (!lines.ok()) return lines.status();
    absl::StatusOr<std::vector<double>> z = Row("currents", name, *lines, 4, 1);
    if (!z.ok()) return z.status();
    const size_t nz = z->size();
    std::vector<double> times;
    std::vector<std::vector<double>> rows;
    for (size_t r = 6; r < lines->size(); ++r) {
      absl::StatusOr<std::vector<double>> v = Row("currents", name, *lines, r, nz + 1);
      if (!v.ok()) return v.status();
      times.push_back((*v)[0]);
      v->resize(std::max(v->size(), 3 * nz + 1), 0.0);
      rows.push_back(*std::move(v));
    }
    if (times.empty()) {
      return Error(options_.at("currents").line, "OPTIONS Currents",
                   absl::StrCat(name, ": no time rows (from line 7)"));
    }
    v1::Fluid::CurrentGrid* g = fluid->mutable_current_grid();
    g->add_x(0);
    g->add_y(0);
    for (double v : *z) g->add_z(v);
    for (double t : times) g->add_times(t);
    for (size_t c = 0; c < nz; ++c)
      for (const std::vector<double>& row : rows)
        SetVec(g->add_velocities(), row[1 + c], row[1 + nz + c], row[1 + 2 * nz + c]);
    return absl::OkStatus();
  }

  // current_profile_4d.txt: "nx ny nz nt", the x, y, z and t rows, then
  // one row "x y z t ux uy uz" per node in any order: the scene's
  // current_grid.
  absl::Status Current4d(v1::Fluid* fluid) const {
    const absl::string_view name = "current_profile_4d.txt";
    absl::StatusOr<std::vector<std::string>> lines = KinematicsFile("currents", name);
    if (!lines.ok()) return lines.status();
    const int line = options_.at("currents").line;
    absl::StatusOr<std::vector<double>> counts = Row("currents", name, *lines, 0, 4);
    if (!counts.ok()) return counts.status();
    std::array<std::vector<double>, 4> axes;
    std::array<size_t, 4> size{};
    for (int a = 0; a < 4; ++a) {
      const double c = (*counts)[a];
      if (!(c >= 1 && c <= 1e7 && c == std::floor(c)))
        return Error(line, "OPTIONS Currents",
                     absl::StrCat(name, ":1: the counts must be whole numbers >= 1"));
      size[a] = static_cast<size_t>(c);
      absl::StatusOr<std::vector<double>> v = Row("currents", name, *lines, 1 + a, size[a]);
      if (!v.ok()) return v.status();
      v->resize(size[a]);
      axes[a] = *std::move(v);
    }
    const size_t nodes = size[0] * size[1] * size[2] * size[3];
    if (nodes > 10000000)
      return Error(line, "OPTIONS Currents", absl::StrCat(name, ": more than 1e7 nodes"));
    std::vector<std::array<double, 3>> u(nodes);
    std::vector<bool> given(nodes, false);
    for (size_t r = 5; r < lines->size(); ++r) {
      if (absl::StripAsciiWhitespace((*lines)[r]).empty()) continue;
      absl::StatusOr<std::vector<double>> v = Row("currents", name, *lines, r, 7);
      if (!v.ok()) return v.status();
      size_t flat = 0;
      for (int a = 0; a < 4; ++a) {
        const auto it = std::find(axes[a].begin(), axes[a].end(), (*v)[a]);
        if (it == axes[a].end()) {
          return Error(line, "OPTIONS Currents",
                       absl::StrCat(name, ":", r + 1, ": ", std::string(1, "xyzt"[a]), " = ", (*v)[a],
                                    " is not on the grid's axis (line ", a + 2, ")"));
        }
        flat = flat * size[a] + static_cast<size_t>(it - axes[a].begin());
      }
      if (given[flat])
        return Error(line, "OPTIONS Currents",
                     absl::StrCat(name, ":", r + 1, ": a node given twice"));
      given[flat] = true;
      u[flat] = {(*v)[4], (*v)[5], (*v)[6]};
    }
    for (size_t k = 0; k < nodes; ++k) {
      if (!given[k])
        return Error(line, "OPTIONS Currents",
                     absl::StrCat(name, ": ", nodes - std::count(given.begin(), given.end(), true),
                                  " of the grid's ", nodes, " nodes have no row"));
    }
    v1::Fluid::CurrentGrid* g = fluid->mutable_current_grid();
    for (double v : axes[0]) g->add_x(v);
    for (double v : axes[1]) g->add_y(v);
    for (double v : axes[2]) g->add_z(v);
    for (double v : axes[3]) g->add_times(v);
    for (const auto& v : u) SetVec(g->add_velocities(), v[0], v[1], v[2]);
    return absl::OkStatus();
  }

  absl::Status ParseOutput(int n, const std::vector<absl::string_view>& w) {
    // OpenFAST's decks (MoorDyn's v1 format) close the list with a line
    // END. MoorDyn-F stops reading there and MoorDyn-C warns and goes on, so
    // a channel after it is refused rather than guessed at.
    if (w.size() == 1 && absl::EqualsIgnoreCase(w[0], "END")) {
      outputs_ended_ = n;
      return absl::OkStatus();
    }
    if (outputs_ended_ > 0) {
      return Error(n, absl::StrCat("OUTPUTS ", w[0]),
                   absl::StrCat("a channel after END (line ", outputs_ended_,
                                "): MoorDyn's readers disagree on it; remove END or move "
                                "the channel before it"));
    }
    for (absl::string_view channel : w) {
      for (absl::string_view c : absl::StrSplit(channel, ',', absl::SkipEmpty())) {
        const std::string lower = absl::AsciiStrToLower(c);
        // A line end's tension: FairTen<n> (= Line<n>TenB, end B) and
        // AnchTen<n> (= Line<n>TenA, end A), MoorDyn's own names.
        if (std::optional<TensionChannel> t = LineEndTension(lower, n, c)) {
          tension_channels_.push_back(*t);
          continue;
        }
        // Point<n> position channels: Point<n>Px, PointnPy, PointnPz.
        absl::string_view rest = c;
        if (absl::ConsumePrefix(&rest, "Point") || absl::ConsumePrefix(&rest, "point") ||
            absl::ConsumePrefix(&rest, "POINT")) {
          const size_t digits = rest.find_first_not_of("0123456789");
          int id = 0;
          if (digits != 0 && digits != absl::string_view::npos &&
              absl::SimpleAtoi(rest.substr(0, digits), &id) &&
              absl::EqualsIgnoreCase(rest.substr(digits, 1), "p") && rest.size() == digits + 2) {
            if (!points_.count(id)) {
              return Error(n, absl::StrCat("OUTPUTS ", c), absl::StrCat("point ", id,
                                                                        " does not exist"));
            }
            if (std::find(probe_points_.begin(), probe_points_.end(), id) == probe_points_.end())
              probe_points_.push_back(id);
            continue;
          }
        }
        // Body<n> channels: the reference point's position, velocity and
        // acceleration (P, V, A), the rotation and its rate (R, RV).
        if (absl::StartsWith(lower, "body")) {
          absl::string_view tail = absl::string_view(lower).substr(4);
          const size_t digits = tail.find_first_not_of("0123456789");
          int id = 0;
          const absl::string_view kind =
              digits == absl::string_view::npos ? absl::string_view() : tail.substr(digits);
          static const char* const kPoint[] = {"px", "py", "pz", "vx", "vy", "vz", "ax", "ay", "az"};
          static const char* const kTurn[] = {"rx", "ry", "rz", "rvx", "rvy", "rvz"};
          bool point = false, turn = false;
          for (const char* k : kPoint) point = point || kind == k;
          for (const char* k : kTurn) turn = turn || kind == k;
          if (digits != 0 && (point || turn) && absl::SimpleAtoi(tail.substr(0, digits), &id)) {
            if (id < 1 || id > static_cast<int>(md_bodies_.size())) {
              return Error(n, absl::StrCat("OUTPUTS ", c),
                           absl::StrCat("body ", id, " does not exist (define it in BODIES)"));
            }
            body_channels_.push_back(BodyChannel{id, turn, std::string(c), n});
            continue;
          }
        }
        return Error(n, absl::StrCat("OUTPUTS ", c),
                     "only point positions (Point<n>Px, Py, Pz), line-end tensions "
                     "(FairTen<n>, AnchTen<n>, Line<n>TenA, Line<n>TenB) and a body's position, "
                     "velocity, acceleration, rotation and its rate (Body<n>Px ... Az, Rx ... "
                     "RVz) are translated (as probes and output.orientation)");
      }
    }
    return absl::OkStatus();
  }

  // `lower`: the channel in lower case; nullopt unless it names a line
  // end's tension.
  static std::optional<TensionChannel> LineEndTension(absl::string_view lower, int n,
                                                      absl::string_view channel) {
    absl::string_view rest = lower;
    bool end_b = false;
    if (absl::ConsumePrefix(&rest, "fairten")) {
      end_b = true;
    } else if (!absl::ConsumePrefix(&rest, "anchten")) {
      if (!absl::ConsumePrefix(&rest, "line")) return std::nullopt;
      if (absl::ConsumeSuffix(&rest, "tenb")) {
        end_b = true;
      } else if (!absl::ConsumeSuffix(&rest, "tena")) {
        return std::nullopt;
      }
    }
    int id = 0;
    if (rest.empty() || rest.find_first_not_of("0123456789") != absl::string_view::npos ||
        !absl::SimpleAtoi(rest, &id)) {
      return std::nullopt;
    }
    return TensionChannel{std::string(channel), id, end_b, n};
  }

  double OptionOr(const std::string& key, double fallback) const {
    const auto it = options_.find(key);
    return it == options_.end() ? fallback : it->second.value;
  }

  static void SetVec(v1::Vec3* v, double x, double y, double z) {
    v->set_x(x);
    v->set_y(y);
    v->set_z(z);
  }

  // The polyline a line is laid along at the start of the static solve:
  // straight when taut, else with one corner below the chord (on the
  // seabed when an end lies on it or the corner of the symmetric sag would
  // lie below it), so that its length is the unstretched length (a free
  // sag: stretched by kSagLayStretch).
  std::vector<Eigen3> Layout(const Point& a, const Point& b, double length, double depth) const {
    const Eigen3 pa{a.x, a.y, a.z}, pb{b.x, b.y, b.z};
    const double span = Dist(pa, pb);
    if (length <= span * (1 + 1e-9)) return {pa, pb};
    // The sag, laid 0.1 % longer than the line: a line hanging free from
    // a kink with no tension has no stiffness across it at the first load
    // increment (measured: MoorDyn's local_euler/hanging.txt failed there;
    // 0.01 % still failed), a little tension gives it some.
    const double laid = length * (1 + kSagLayStretch);
    // Both ends at one place: a square loop below them (scene polylines
    // may turn by at most 135 degrees at a corner).
    if (span < 1e-9 * length) {
      const double q = laid / 4;
      return {pa, {pa[0], pa[1], pa[2] - q}, {pa[0] + q, pa[1], pa[2] - q},
              {pa[0] + q, pa[1], pa[2]}, pb};
    }
    // "Down": the unit vector across the chord in its vertical plane,
    // pointing down (straight down for a horizontal chord; beside a
    // vertical chord, along x).
    const Eigen3 chord{(pb[0] - pa[0]) / span, (pb[1] - pa[1]) / span, (pb[2] - pa[2]) / span};
    Eigen3 down{chord[2] * chord[0], chord[2] * chord[1], chord[2] * chord[2] - 1};
    const double dn = std::sqrt(down[0] * down[0] + down[1] * down[1] + down[2] * down[2]);
    if (dn > 1e-12) {
      for (double& x : down) x /= dn;
    } else {
      down = {1, 0, 0};
    }
    // A V (one corner below the midpoint) while its corner turns by at
    // most 120 degrees, else a U (two right-angled corners, the ends
    // moved down by the same distance) for a very slack line.
    const double h = std::sqrt(std::max(0.0, laid * laid - span * span)) / 2;
    std::vector<Eigen3> sag;
    Eigen3 corner{(pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2};
    if (std::atan2(span / 2, h) >= kPi / 6) {
      for (int d = 0; d < 3; ++d) corner[d] += h * down[d];
      sag = {pa, corner, pb};
    } else {
      const double u = (laid - span) / 2;
      Eigen3 ca = pa, cb = pb;
      for (int d = 0; d < 3; ++d) {
        ca[d] += u * down[d];
        cb[d] += u * down[d];
      }
      sag = {pa, ca, cb, pb};
      corner = ca[2] < cb[2] ? ca : cb;
    }
    // An end on the bed (an anchor, within 1 % of the depth) lays the line
    // along the bed first, as a catenary mooring lies: a sag hanging free
    // from it has no tension to hold its kink at the start of the solve
    // (measured: the 600 m chain case's first load increment failed so).
    const bool a_low = pa[2] <= pb[2];
    const Eigen3& low = a_low ? pa : pb;
    const Eigen3& high = a_low ? pb : pa;
    const bool anchored = low[2] <= -depth + 0.01 * depth;
    if (corner[2] >= -depth && !anchored) return sag;
    // On the seabed: the corner at z = -depth on the horizontal path from
    // a to b, where the two legs add up to the length (bisection: the sum
    // grows with the corner's distance from the end nearer the bed).
    auto corner_at = [&](double t) {
      return Eigen3{low[0] + t * (high[0] - low[0]), low[1] + t * (high[1] - low[1]), -depth};
    };
    auto legs = [&](double t) {
      const Eigen3 c = corner_at(t);
      return Dist(low, c) + Dist(c, high);
    };
    double lo = 0, hi = 1;
    // Too short to reach the bed as an L, or one end above the other (the
    // legs' sum does not grow along the bed): the sag.
    const double run = std::hypot(high[0] - low[0], high[1] - low[1]);
    if (legs(0) > length || run < 1e-9 * length) return sag;
    while (legs(hi) < length) hi *= 2;  // grows by about run per doubling: ends
    for (int k = 0; k < 200; ++k) {
      const double t = (lo + hi) / 2;
      (legs(t) < length ? lo : hi) = t;
    }
    const Eigen3 c = corner_at((lo + hi) / 2);
    // Beyond the higher end the rising leg folds back over the bed run: kept
    // while the corner turns by at most 120 degrees, as the V's (a line from
    // an anchor to a free point a little above the bed and closer than the
    // line's length: MoorDyn's BodiesAndRods.dat, whose V would lie 46 m
    // inside the bed); a sharper fold, the sag.
    if ((lo + hi) / 2 > 1) {
      // The bed run's direction (horizontal) against the rising leg's.
      const double ax = c[0] - low[0], ay = c[1] - low[1];
      const double cos_turn = (ax * (high[0] - c[0]) + ay * (high[1] - c[1])) /
                              (std::hypot(ax, ay) * Dist(c, high));
      if (!(cos_turn >= std::cos(2 * kPi / 3))) return sag;
    }
    if (Dist(low, c) < 1e-9 * length || Dist(high, c) < 1e-9 * length) return {pa, pb};
    return {pa, c, pb};
  }
  static double Dist(const Eigen3& p, const Eigen3& q) {
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                     (p[2] - q[2]) * (p[2] - q[2]));
  }

  absl::StatusOr<v1::Scene> Build() const {
    v1::Scene scene;
    absl::string_view base = file_;
    if (const size_t slash = base.find_last_of('/'); slash != absl::string_view::npos)
      base.remove_prefix(slash + 1);
    if (const size_t dot = base.find_last_of('.'); dot != absl::string_view::npos && dot > 0)
      base = base.substr(0, dot);
    scene.set_name(std::string(base));
    const double g = OptionOr("g", kDefaultGravity);
    const double rho = OptionOr("rho", kDefaultDensity);
    SetVec(scene.mutable_gravity(), 0, 0, -g);
    scene.mutable_fluid()->set_density(rho);
    const auto depth_it = options_.find("depth");
    if (depth_it == options_.end()) {
      return Error(1, "OPTIONS WtrDpth",
                   "required (MoorDyn's default of 0 puts the seabed at the water surface)");
    }
    const double depth = depth_it->second.value;
    scene.mutable_fluid()->set_water_depth(depth);
    // MoorDyn's lines carry buoyancy, drag and added mass only where they
    // are under the (instantaneous) surface: a level needs gravity (the
    // vertical) and water (WtrDnsty 0 or g 0: MoorDyn's lines are wet
    // everywhere or feel no fluid at all).
    if (g > 0 && rho > 0) scene.mutable_fluid()->set_free_surface(true);
    if (absl::Status s = WaterKinematics(scene.mutable_fluid()); !s.ok()) return s;

    // The seabed: kBot [Pa/m] and cBot [Pa s/m] act on the line's
    // diameter, cablesim's per unit length: the scene's from the first
    // line type's diameter, and a line of another diameter gets its own
    // (cables[].seabed_stiffness, seabed_damping; Build's line loop).
    if (line_types_.empty()) return BuildRigidOnly(scene);
    const double d0 = line_types_.front().diameter;
    v1::Seabed* bed = scene.mutable_seabed();
    bed->set_depth(depth);
    bed->set_stiffness(OptionOr("kbot", kDefaultKBot) * d0);
    bed->set_damping(OptionOr("cbot", kDefaultCBot) * d0);
    const double mu = OptionOr("mu", 0);
    bed->set_friction_axial(OptionOr("mu_a", mu));
    bed->set_friction_transverse(OptionOr("mu_t", mu));
    if (!(g > 0)) SetVec(bed->mutable_normal(), 0, 0, 1);  // g 0: MoorDyn's bed is still at -WtrDpth
    if (absl::Status s = MoorDynFriction(bed); !s.ok()) return s;
    if (!seafloor_file_.empty()) {
      if (absl::Status s = ReadSeafloor(bed->mutable_bathymetry()); !s.ok()) return s;
      bed->set_depth(0);  // the grid's depths are below the origin
    }
    scene.mutable_solver()->set_analysis(v1::STATIC);

    // The points where free points become bodies (mass or volume) or where
    // line ends join each other.
    std::map<int, std::string> body_of;
    for (const auto& [id, p] : points_) {
      if (p.kind != PointKind::kFree) continue;
      if (p.mass == 0 && p.volume == 0 && p.cda == 0 && p.ca == 0) continue;
      if (!(p.mass > 0)) {
        return Error(p.line, "POINTS Mass",
                     "a free point with volume, drag or added mass needs a mass > 0 (cablesim's "
                     "bodies have mass)");
      }
      if (p.volume > 0 && HasWater() && !HasGravity() && (p.cda > 0 || p.ca > 0)) {
        return Error(p.line, p.cda > 0 ? "POINTS CdA" : "POINTS CA",
                     "a point's drag or added mass with a volume but without gravity cannot be "
                     "expressed (its fluid loads are a buoyed cylinder's, which needs the "
                     "vertical)");
      }
      v1::Body* body = scene.add_bodies();
      body_points_.push_back(p.line);
      const std::string name = absl::StrCat("point", id);
      body->set_name(name);
      body_of[id] = name;
      body->set_mass(p.mass);
      // The lines hold the body at its centre, so its rotation is free and
      // unloaded; a sphere of its volume (or of 0.1 m) gives it inertia.
      const double r = p.volume > 0 ? std::cbrt(3 * p.volume / (4 * kPi)) : 0.1;
      const double inertia = 0.4 * p.mass * r * r;
      SetVec(body->mutable_inertia(), inertia, inertia, inertia);
      SetVec(body->mutable_position(), p.x, p.y, p.z);
      if (p.volume == 0 && p.cda > 0 && HasWater()) {
        // MoorDyn's 1/2 rho CdA |v| v without a volume (no buoyancy; its
        // added mass Ca rho V is nothing): drag areas alone.
        SetVec(body->mutable_hydrodynamics()->mutable_drag_area(), p.cda, p.cda, p.cda);
      }
      if (p.volume > 0 && HasWater() && HasGravity()) {
        // A vertical cylinder as tall as wide with the point's volume.
        const double d = std::cbrt(4 * p.volume / kPi);
        v1::BodyHydrodynamics* h = body->mutable_hydrodynamics();
        h->set_diameter(d);
        h->set_height(d);
        h->set_drag_coefficient(p.cda / (d * d));
        h->set_heave_drag_coefficient(p.cda / (kPi * d * d / 4));
        h->set_added_mass(p.ca);
        h->set_heave_added_mass(p.ca);
      }
    }

    if (absl::Status s = BuildBodiesAndRods(&scene); !s.ok()) return s;
    if (absl::Status s = JoinAtPointRods(depth); !s.ok()) return s;

    std::map<int, std::pair<std::string, double>> first_end_at;  // free point -> (cable, s)
    for (const Line& l : lines_) {
      const int index = static_cast<int>(&l - lines_.data());
      const LineType& t = *l.type;
      v1::Cable* c = scene.add_cables();
      const std::string name = absl::StrCat("line", l.id);
      c->set_name(name);
      std::vector<Eigen3> laid = laid_[index];
      if (laid.empty()) {
        // An end at a rod of zero length that a chain moved: there.
        Point a = points_.at(l.a), b = points_.at(l.b);
        for (Point* p : {&a, &b}) {
          const auto moved = point_rod_at_.find(p->rod);
          if (p->rod > 0 && moved != point_rod_at_.end()) {
            p->x = moved->second[0];
            p->y = moved->second[1];
            p->z = moved->second[2];
          }
        }
        laid = Layout(a, b, l.length, depth);
      }
      for (const Eigen3& p : laid) SetVec(c->add_points(), p[0], p[1], p[2]);
      c->set_length(l.length);
      c->set_elements(l.segments);
      const double area = kPi * t.diameter * t.diameter / 4;
      c->set_area(area);
      c->set_density(t.mass_per_length / area);
      c->set_youngs_modulus(t.ea / area);
      if (t.ei > 0) {
        c->set_bending(v1::EXACT);
        c->set_second_moment(t.ei / (t.ea / area));
      } else {
        c->set_bending(v1::NONE);
      }
      if (t.visco) {
        c->set_axial_law(v1::VISCOELASTIC);
      } else if (t.table_strains.empty()) {
        c->set_axial_law(v1::ENGINEERING);
      } else {
        c->set_axial_law(v1::TABLE);
        for (size_t k = 0; k < t.table_strains.size(); ++k) {
          c->mutable_tension_table()->add_strains(t.table_strains[k]);
          c->mutable_tension_table()->add_tensions(t.table_tensions[k]);
        }
      }
      // BA: a coefficient [N s] on the strain rate, or minus a damping
      // ratio of a segment's axial mode (MoorDyn: BA = zeta (L / N)
      // sqrt(EA m)); cablesim's Kelvin-Voigt time is BA / EA.
      const double ba =
          t.ba < 0 ? -t.ba * (l.length / l.segments) * std::sqrt(t.ea * t.mass_per_length) : t.ba;
      if (t.visco) {
        // The static dashpot BA beside EA_1 and the dynamic one beside
        // EA_2 (a ratio BA < 0 as MoorDyn scales it, on the static EA).
        v1::Viscoelastic* ve = c->mutable_viscoelastic();
        if (t.ea_dynamic > 0) {
          ve->set_dynamic_ea(t.ea_dynamic);
        } else {
          ve->set_dynamic_ea_base(t.ea_base);
          ve->set_dynamic_ea_slope(t.ea_slope);
        }
        ve->set_static_damping(ba);
        ve->set_dynamic_damping(t.ba_dynamic);
      } else if (ba > 0) {
        c->mutable_damping()->set_axial_time(ba / t.ea);
      }
      if (rho > 0) {  // WtrDnsty 0: no fluid for the coefficients to act in
        v1::Hydrodynamics* h = c->mutable_hydrodynamics();
        h->set_normal_drag(t.cd);
        h->set_tangential_drag(t.cd_axial);
        h->set_added_mass(t.ca);
        h->set_axial_added_mass(t.ca_axial);
        h->set_diameter(t.diameter);
        SetTipLoads(index, rho, h);
      }
      if (std::abs(t.diameter - d0) > 1e-12 * d0) {
        c->set_seabed_stiffness(OptionOr("kbot", kDefaultKBot) * t.diameter);
        c->set_seabed_damping(OptionOr("cbot", kDefaultCBot) * t.diameter);
      }
      for (const auto& [end, pid] : {std::pair{0.0, l.a}, std::pair{l.length, l.b}}) {
        const Point& p = points_.at(pid);
        if (p.rod > 0 && rods_[p.rod - 1].segments == 0) {
          // At a rod of zero length: joined to its reference end (PIN, or
          // FIXED between two lines with bending stiffness).
          const PointRodJoin& join = point_rods_.at(p.rod);
          const PointRodEnd& ref = join.ends[join.reference];
          const bool end_b = end != 0.0;
          if (ref.line == index && ref.line_end_b == end_b) continue;
          const Line& other = lines_[ref.line];
          v1::Joint* j = scene.add_joints();
          j->set_type(t.ei > 0 && ref.bending ? v1::FIXED : v1::PIN);
          j->mutable_a()->set_cable(name);
          j->mutable_a()->set_s(end);
          j->mutable_b()->set_cable(absl::StrCat("line", other.id));
          j->mutable_b()->set_s(ref.line_end_b ? other.length : 0.0);
          continue;
        }
        if (const auto h = holders_.find(pid); h != holders_.end() && !h->second.ground) {
          // On a body or rod: pinned to its point.
          v1::Joint* j = scene.add_joints();
          j->set_type(v1::PIN);
          j->mutable_a()->set_cable(name);
          j->mutable_a()->set_s(end);
          j->mutable_b()->set_body(h->second.body);
          const Eigen::Vector3d& q = h->second.point;
          SetVec(j->mutable_b()->mutable_point(), q.x(), q.y(), q.z());
          continue;
        }
        if (p.kind != PointKind::kFree) {
          // Named by the point, so that the reactions' columns and a
          // coupling host (couple/moordyn/MoorDyn2.h) find it; a Vessel
          // point is a coupled support (held where it is in a run).
          v1::Joint* j = scene.add_joints();
          // A fixed rod's end: named by the rod and end.
          j->set_name(p.rod > 0 ? absl::StrCat("rod", p.rod, p.rod_end_b ? "B" : "A")
                                : absl::StrCat("point", pid));
          j->set_type(v1::PIN);
          j->mutable_a()->set_cable(name);
          j->mutable_a()->set_s(end);
          if (p.kind == PointKind::kCoupled) j->set_coupled(true);
          continue;
        }
        if (const auto body = body_of.find(pid); body != body_of.end()) {
          v1::Joint* j = scene.add_joints();
          j->set_type(v1::PIN);
          j->mutable_a()->set_cable(name);
          j->mutable_a()->set_s(end);
          j->mutable_b()->set_body(body->second);
          continue;
        }
        // A massless connection: the ends that meet there are pinned to
        // the first one.
        const auto first = first_end_at.find(pid);
        if (first == first_end_at.end()) {
          first_end_at[pid] = {name, end};
          continue;
        }
        v1::Joint* j = scene.add_joints();
        j->set_type(v1::PIN);
        j->mutable_a()->set_cable(name);
        j->mutable_a()->set_s(end);
        j->mutable_b()->set_cable(first->second.first);
        j->mutable_b()->set_s(first->second.second);
      }
    }
    for (int id : probe_points_) {
      const Point& p = points_.at(id);
      v1::Probe* probe = scene.add_probes();
      probe->set_name(absl::StrCat("Point", id));
      if (const auto h = holders_.find(id); h != holders_.end() && !h->second.ground) {
        probe->set_body(h->second.body);
        SetVec(probe->mutable_point(), h->second.point.x(), h->second.point.y(),
               h->second.point.z());
        continue;
      }
      if (const auto body = body_of.find(id); body != body_of.end()) {
        probe->set_body(body->second);
        continue;
      }
      // On the first line end at the point.
      bool found = false;
      for (const Line& l : lines_) {
        if (l.a != id && l.b != id) continue;
        probe->set_cable(absl::StrCat("line", l.id));
        probe->set_s(l.a == id ? 0.0 : l.length);
        found = true;
        break;
      }
      if (!found) {
        return Error(p.line, "POINTS ID",
                     absl::StrCat("point ", id, " has an output channel but no line"));
      }
    }
    if (absl::Status s = AddBodyChannels(&scene); !s.ok()) return s;
    for (const TensionChannel& t : tension_channels_) {
      const auto line = std::find_if(lines_.begin(), lines_.end(),
                                     [&](const Line& l) { return l.id == t.line_id; });
      if (line == lines_.end()) {
        return Error(t.line, absl::StrCat("OUTPUTS ", t.name),
                     absl::StrCat("line ", t.line_id, " does not exist"));
      }
      v1::Probe* probe = scene.add_probes();
      probe->set_name(t.name);
      probe->set_cable(absl::StrCat("line", t.line_id));
      probe->set_s(t.end_b ? line->length : 0.0);
      scene.mutable_output()->set_tension(true);
    }
    return scene;
  }

  // ---- MoorDyn's rods of zero length (NumSegs 0) ----
  //
  // MoorDyn (Rod.cpp, N = 0): a free rod of zero length has no mass, no
  // volume and no buoyancy (its two ends' buoyancy and pressure cancel);
  // it moves as a point with the lines' end masses. Its direction q is the
  // unit sum over its lines of (end segment's unit vector, signed to run
  // along q) EI / stretched segment length (Line::getEndSegmentMoment), and
  // each line's end is clamped in bending to q (Line::setEndOrientation):
  // two lines with EI > 0 are tangent to each other there, a line of EI 0
  // adds nothing and is pinned, and with no line of EI > 0 q is the zero
  // vector (Eigen's normalized()). Both ends' axial drag and added mass act
  // at the point along q: 2 x 1/2 rho CdEnd (pi d^2 / 4) |v_q| v_q and
  // 2 x rho CaEnd (pi d^3 / 12) along q, with the flow's acceleration.

  // A line's end at a rod of zero length.
  struct PointRodEnd {
    int line = 0;  // index into lines_
    bool line_end_b = false;
    bool rod_end_b = false;
    bool bending = false;  // the line's EI > 0
    // MoorDyn's sense of the line's tangent against the rod's q: +1 when
    // the line's end B is at the rod's end A or its end A at end B.
    int sign() const { return line_end_b != rod_end_b ? 1 : -1; }
  };
  struct PointRodJoin {
    std::vector<PointRodEnd> ends;  // in LINES order
    // The end the others are joined to: the first with EI > 0, else the
    // first; it carries the rod's end loads when it has EI > 0.
    int reference = 0;
  };

  // Fills point_rods_, laid_ (the lines welded end to end at rods of zero
  // length, laid as one chain) and point_rod_at_, or refuses what a chain
  // of FIXED joints cannot express.
  absl::Status JoinAtPointRods(double depth) const {
    point_rods_.clear();
    point_rod_at_.clear();
    laid_.assign(lines_.size(), {});
    for (size_t i = 0; i < lines_.size(); ++i) {
      for (const bool end_b : {false, true}) {
        const Point& p = points_.at(end_b ? lines_[i].b : lines_[i].a);
        if (p.rod == 0 || rods_[p.rod - 1].segments != 0) continue;
        PointRodJoin& join = point_rods_[p.rod];
        for (const PointRodEnd& o : join.ends) {
          if (o.line == static_cast<int>(i)) {
            return Error(lines_[i].line, "LINES AttachB",
                         absl::StrCat("a line with both ends at rod ", p.rod,
                                      " (of zero length) cannot be expressed"));
          }
        }
        join.ends.push_back({static_cast<int>(i), end_b, p.rod_end_b, lines_[i].type->ei > 0});
      }
    }
    std::vector<int> next(lines_.size(), -1), prev(lines_.size(), -1);
    for (const Rod& r : rods_) {
      if (r.segments != 0) continue;
      const auto it = point_rods_.find(r.id);
      if (it == point_rods_.end()) {
        return Error(r.line, "RODS ID",
                     "a rod of zero length with no line cannot be expressed (it has no mass: "
                     "MoorDyn's moves with its lines' ends)");
      }
      PointRodJoin& join = it->second;
      std::vector<int> bent;
      for (size_t k = 0; k < join.ends.size(); ++k)
        if (join.ends[k].bending) bent.push_back(static_cast<int>(k));
      join.reference = bent.empty() ? 0 : bent[0];
      if (bent.size() < 2) continue;
      if (bent.size() > 2) {
        return Error(r.line, "RODS NumSegs",
                     absl::StrCat("rod ", r.id, " of zero length joins ", bent.size(),
                                  " lines with bending stiffness (EI > 0): only two, welded end "
                                  "to end as one chain, can be laid out"));
      }
      const PointRodEnd& a = join.ends[bent[0]];
      const PointRodEnd& b = join.ends[bent[1]];
      const Line& la = lines_[a.line];
      const Line& lb = lines_[b.line];
      const char* field = b.line_end_b ? "LINES AttachB" : "LINES AttachA";
      if (a.sign() != b.sign() || a.line_end_b == b.line_end_b) {
        return Error(lb.line, field,
                     absl::StrCat(
                         "lines ", la.id, " and ", lb.id, " meet at rod ", r.id,
                         " (of zero length) ",
                         a.sign() != b.sign()
                             ? "with tangents MoorDyn holds opposite (a line ending at the "
                               "rod's end A runs along its direction, one ending at end B "
                               "against it, one starting there the other way)"
                             : "both arriving (or both leaving)",
                         ": only one line ending at the rod and the other starting there, "
                         "tangent in the same sense (a FIXED joint between cables), can be "
                         "expressed; give one line the other way round or use the rod's "
                         "other end"));
      }
      const LineType& ta = *la.type;
      const LineType& tb = *lb.type;
      if (ta.ea != tb.ea || !ta.table_strains.empty() || !tb.table_strains.empty() || ta.visco ||
          tb.visco) {
        return Error(lb.line, "LINES LineType",
                     absl::StrCat("lines ", la.id, " and ", lb.id, " meet at rod ", r.id,
                                  " (of zero length) with ",
                                  ta.visco || tb.visco ? "a viscoelastic law"
                                  : ta.table_strains.empty() && tb.table_strains.empty()
                                      ? "different EA"
                                      : "a tension-strain table",
                                  ": the FIXED joint between them holds their stretches equal "
                                  "there, right only for one constant EA"));
      }
      const int first = a.line_end_b ? a.line : b.line;
      const int second = a.line_end_b ? b.line : a.line;
      next[first] = second;
      prev[second] = first;
    }
    std::vector<bool> seen(lines_.size(), false);
    for (size_t i = 0; i < lines_.size(); ++i) {
      if (prev[i] >= 0 || next[i] < 0) continue;
      std::vector<int> chain;
      for (int k = static_cast<int>(i); k >= 0; k = next[k]) {
        chain.push_back(k);
        seen[k] = true;
      }
      LayChain(chain, depth);
    }
    for (size_t i = 0; i < lines_.size(); ++i) {
      if (next[i] >= 0 && !seen[i]) {
        return Error(lines_[i].line, "LINES AttachB",
                     "lines welded end to end at rods of zero length close a loop, which cannot "
                     "be laid out");
      }
    }
    return absl::OkStatus();
  }

  // Lays the lines of `chain` (each line's end B welded to the next one's
  // end A at a rod of zero length) as one line from the first one's end A
  // to the last one's end B, cut at their lengths: every line gets the same
  // stretch and, at each weld, both lines' end legs lie on one leg of the
  // chain (a weld that falls on a corner of it gets a chamfer of 1e-6 of
  // the shorter leg there), as the FIXED joint needs at the start. The
  // rods of zero length inside the chain move to the welds (their deck
  // place is MoorDyn's starting guess too).
  void LayChain(const std::vector<int>& chain, double depth) const {
    double total = 0;
    for (int k : chain) total += lines_[k].length;
    const std::vector<Eigen3> poly =
        Layout(points_.at(lines_[chain.front()].a), points_.at(lines_[chain.back()].b), total,
               depth);
    auto vec = [](const Eigen3& p) { return Eigen::Vector3d(p[0], p[1], p[2]); };
    auto arr = [](const Eigen::Vector3d& v) { return Eigen3{v.x(), v.y(), v.z()}; };
    std::vector<double> cum(1, 0.0);
    for (size_t v = 1; v < poly.size(); ++v) cum.push_back(cum.back() + Dist(poly[v - 1], poly[v]));
    const double scale = cum.back() / total;
    const double tol = 1e-9 * cum.back();
    auto at = [&](double s) {
      size_t v = 1;
      while (v + 1 < poly.size() && cum[v] < s) ++v;
      const double f = std::clamp((s - cum[v - 1]) / (cum[v] - cum[v - 1]), 0.0, 1.0);
      return arr(vec(poly[v - 1]) + f * (vec(poly[v]) - vec(poly[v - 1])));
    };
    double start = 0;
    for (size_t k = 0; k < chain.size(); ++k) {
      const double s0 = start * scale;
      start += lines_[chain[k]].length;
      const double s1 = k + 1 == chain.size() ? cum.back() : start * scale;
      std::vector<Eigen3>& out = laid_[chain[k]];
      out.push_back(k == 0 ? poly.front() : at(s0));
      for (size_t v = 1; v + 1 < poly.size(); ++v)
        if (cum[v] > s0 + tol && cum[v] < s1 - tol) out.push_back(poly[v]);
      out.push_back(k + 1 == chain.size() ? poly.back() : at(s1));
    }
    // The welds: on a corner, a chamfer; the rods move there.
    for (size_t k = 0; k + 1 < chain.size(); ++k) {
      std::vector<Eigen3>& in = laid_[chain[k]];
      std::vector<Eigen3>& out = laid_[chain[k + 1]];
      for (size_t v = 1; v + 1 < poly.size(); ++v) {
        const Eigen::Vector3d weld = vec(in.back());
        if ((weld - vec(poly[v])).norm() > tol) continue;
        const Eigen::Vector3d u_in = (vec(poly[v]) - vec(poly[v - 1])).normalized();
        const Eigen::Vector3d u_out = (vec(poly[v + 1]) - vec(poly[v])).normalized();
        const double delta =
            1e-6 * std::min({cum[v] - cum[v - 1], cum[v + 1] - cum[v],
                             lines_[chain[k]].length, lines_[chain[k + 1]].length});
        const Eigen::Vector3d corner = vec(poly[v]);
        const Eigen::Vector3d mid = corner + delta / 2 * (u_out - u_in);
        in.back() = arr(corner - delta * u_in);
        in.push_back(arr(mid));
        out.front() = arr(mid);
        out.insert(out.begin() + 1, arr(corner + delta * u_out));
        break;
      }
      const Point& weld_point = points_.at(lines_[chain[k]].b);
      point_rod_at_[weld_point.rod] = in.back();
    }
  }

  // The end loads of the rods of zero length whose reference end (with
  // EI > 0: MoorDyn's direction is its tangent, shared by a FIXED joint)
  // is one of line `index`'s ends, as its tip loads.
  void SetTipLoads(int index, double rho, v1::Hydrodynamics* h) const {
    for (const auto& [id, join] : point_rods_) {
      const PointRodEnd& ref = join.ends[join.reference];
      if (ref.line != index || !ref.bending) continue;
      const RodType& type = *rods_[id - 1].type;
      const double d = type.diameter;
      v1::TipLoad* tip = ref.line_end_b ? h->mutable_end_tip() : h->mutable_start_tip();
      tip->set_drag_area(tip->drag_area() + 2 * type.cd_end * kPi * d * d / 4);
      tip->set_added_mass(tip->added_mass() + 2 * rho * type.ca_end * kPi * d * d * d / 12);
    }
  }

  // The body channels (OUTPUTS Body<n>...): a probe "Body<n>" on the
  // scene body at the reference point (the columns Body<n>.x ... .az), and
  // output.orientation for a rotation's (the scene body's axes are the
  // world's at the start, so only a body that MoorDyn does not turn there).
  absl::Status AddBodyChannels(v1::Scene* scene) const {
    std::vector<int> probed;
    for (const BodyChannel& c : body_channels_) {
      const MdBody& b = md_bodies_[c.body - 1];
      const std::string field = absl::StrCat("OUTPUTS ", c.name);
      if (b.mount == Mount::kFixed) {
        return Error(c.line, field, "a fixed body's channels cannot be expressed (it has no "
                                    "scene body; it stays where the deck puts it)");
      }
      if (c.rotation) {
        if (!b.rotation.isIdentity(0)) {
          return Error(c.line, field,
                       "a rotation channel of a body with r0, p0 or y0 cannot be expressed (its "
                       "scene body's axes are the world's at the start, MoorDyn's turned)");
        }
        scene->mutable_output()->set_orientation(true);
        continue;
      }
      if (std::find(probed.begin(), probed.end(), c.body) != probed.end()) continue;
      probed.push_back(c.body);
      const std::string name = absl::StrCat("body", c.body);
      for (const v1::Body& o : scene->bodies()) {
        if (o.name() != name) continue;
        v1::Probe* probe = scene->add_probes();
        probe->set_name(absl::StrCat("Body", c.body));
        probe->set_body(name);
        const Eigen::Vector3d rel =
            b.position - Eigen::Vector3d(o.position().x(), o.position().y(), o.position().z());
        SetVec(probe->mutable_point(), rel.x(), rel.y(), rel.z());
      }
    }
    return absl::OkStatus();
  }

  // A deck of rods or bodies alone (no line types): the environment, the
  // bodies and rods (MoorDyn's RodPinnedFloating.txt). No seabed: bodies
  // do not touch it, as MoorDyn's.
  absl::StatusOr<v1::Scene> BuildRigidOnly(v1::Scene scene) const {
    if (absl::Status s = BuildBodiesAndRods(&scene); !s.ok()) return s;
    if (absl::Status s = JoinAtPointRods(0); !s.ok()) return s;  // refuses a rod of zero length
    if (absl::Status s = AddBodyChannels(&scene); !s.ok()) return s;
    scene.mutable_solver()->set_analysis(v1::STATIC);
    return scene;
  }

  // SeafloorFile: MoorDyn's 3D seafloor file, relative to the deck's
  // directory: "nx ny", the nx x ticks, the ny y ticks, then one node a
  // row, "x y z" with z the bed's height (negative below the surface).
  // It becomes seabed.bathymetry (depths -z), which needs a regular grid:
  // evenly spaced ticks and every node given once.
  absl::Status ReadSeafloor(v1::Bathymetry* grid) const {
    const int n = seafloor_line_;
    const std::string field = "OPTIONS SeafloorFile";
    const std::string& name = seafloor_file_;
    CABLESIM_ASSIGN_OR_RETURN(
        const std::string text,
        ReadNamedFile(n, field, name,
                      absl::StrCat("\"", name,
                                   "\": a seafloor file cannot be read here (a deck's text alone, "
                                   "as the service takes it, has no directory): give the scene "
                                   "with seabed.bathymetry, or run the deck's file"),
                      absl::StrCat("\"", name, "\": cannot read the seafloor file: ")));
    auto bad = [&](int row, absl::string_view message) {
      return Error(n, field, absl::StrCat(name, ":", row, ": ", message));
    };
    std::vector<std::vector<double>> rows;
    std::vector<int> row_line;
    int row = 0;
    for (absl::string_view raw : absl::StrSplit(text, '\n')) {
      ++row;
      const std::vector<absl::string_view> w =
          absl::StrSplit(raw, absl::ByAnyChar(" \t\r,"), absl::SkipEmpty());
      if (w.empty()) continue;
      std::vector<double> v;
      for (absl::string_view word : w) {
        double x = 0;
        if (!absl::SimpleAtod(word, &x) || !std::isfinite(x))
          return bad(row, absl::StrCat("\"", word, "\" is not a number"));
        v.push_back(x);
      }
      rows.push_back(std::move(v));
      row_line.push_back(row);
    }
    if (rows.size() < 4 || rows[0].size() != 2) {
      return bad(rows.empty() ? 1 : row_line[0],
                 "expected \"nx ny\", the x ticks, the y ticks and a node per row");
    }
    const int nx = static_cast<int>(rows[0][0]), ny = static_cast<int>(rows[0][1]);
    if (nx < 1 || ny < 1 || nx != rows[0][0] || ny != rows[0][1])
      return bad(row_line[0], "nx and ny must be whole numbers >= 1");
    std::vector<double> spacing(2, 0.0);
    for (int axis = 0; axis < 2; ++axis) {
      const std::vector<double>& ticks = rows[1 + axis];
      const int count = axis == 0 ? nx : ny;
      if (static_cast<int>(ticks.size()) != count) {
        return bad(row_line[1 + axis], absl::StrCat("expected ", count, " ticks, got ",
                                                    ticks.size()));
      }
      if (count > 1) spacing[axis] = (ticks.back() - ticks.front()) / (count - 1);
      for (int i = 0; i < count; ++i) {
        if (count > 1 && !(spacing[axis] > 0)) return bad(row_line[1 + axis], "ticks must increase");
        if (std::abs(ticks[i] - (ticks.front() + i * spacing[axis])) > 1e-6 * spacing[axis]) {
          return bad(row_line[1 + axis],
                     absl::StrCat("tick ", ticks[i],
                                  " is off the even spacing: a non-rectangular (unevenly "
                                  "spaced) grid cannot be expressed (seabed.bathymetry is a "
                                  "regular grid)"));
        }
      }
    }
    std::vector<double> depths(static_cast<size_t>(nx) * ny, std::nan(""));
    auto index = [&](int axis, double x, int count) {
      if (count == 1) return std::abs(x - rows[1 + axis][0]) <= 1e-9 * (1 + std::abs(x)) ? 0 : -1;
      const double f = (x - rows[1 + axis][0]) / spacing[axis];
      const long i = std::lround(f);
      return i >= 0 && i < count && std::abs(f - i) <= 1e-6 ? static_cast<int>(i) : -1;
    };
    for (size_t k = 3; k < rows.size(); ++k) {
      if (rows[k].size() != 3) return bad(row_line[k], "expected a node \"x y z\"");
      const int i = index(0, rows[k][0], nx), j = index(1, rows[k][1], ny);
      if (i < 0 || j < 0) {
        return bad(row_line[k], "the node is not on the grid's ticks (a non-rectangular grid "
                                "cannot be expressed)");
      }
      double& d = depths[static_cast<size_t>(j) * nx + i];
      if (!std::isnan(d)) return bad(row_line[k], "a node given twice");
      d = -rows[k][2];
    }
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if (std::isnan(depths[static_cast<size_t>(j) * nx + i])) {
          return Error(n, field, absl::StrCat(name, ": the node (", rows[1][i], ", ", rows[2][j],
                                              ") is missing (a non-rectangular grid cannot be "
                                              "expressed)"));
        }
    grid->set_origin_x(rows[1][0]);
    grid->set_origin_y(rows[2][0]);
    if (nx > 1) grid->set_dx(spacing[0]);
    if (ny > 1) grid->set_dy(spacing[1]);
    grid->set_nx(nx);
    grid->set_ny(ny);
    for (double d : depths) grid->add_depths(d);
    return absl::OkStatus();
  }

  // ---- MoorDyn rods and bodies (docs/moordyn-files.md, "Bodies and rods") ----

  // A word of numbers separated by '|' (MoorDyn's CG, I, CdA and Ca
  // columns): 1 or one of `many` of them.
  absl::StatusOr<std::vector<double>> Numbers(int n, absl::string_view field,
                                              absl::string_view word, int many, int many2 = 0,
                                              int many3 = 0) const {
    std::vector<double> out;
    for (absl::string_view part : absl::StrSplit(word, '|')) {
      absl::StatusOr<double> v = Number(n, field, part);
      if (!v.ok()) return v.status();
      out.push_back(*v);
    }
    const int size = static_cast<int>(out.size());
    if (size != 1 && size != many && (many2 == 0 || size != many2) &&
        (many3 == 0 || size != many3)) {
      std::string counts = absl::StrCat(many);
      if (many2 > 0) counts = absl::StrCat(many, many3 > 0 ? ", " : " or ", many2);
      if (many3 > 0) absl::StrAppend(&counts, " or ", many3);
      return Error(n, field,
                   absl::StrCat("\"", word, "\": 1", many2 > 0 ? ", " : " or ", counts,
                                " numbers separated by '|' can be expressed"));
    }
    return out;
  }

  absl::Status ParseRodType(int n, const std::vector<absl::string_view>& w) {
    static constexpr const char* kColumns[] = {"TypeName", "Diam", "Mass/m", "Cd",
                                               "Ca",       "CdEnd", "CaEnd"};
    if (w.size() != 7) {
      return Error(n, "ROD TYPES",
                   absl::StrCat("expected the 7 columns TypeName Diam Mass/m Cd Ca CdEnd CaEnd, "
                                "got ",
                                w.size()));
    }
    RodType t;
    t.name = std::string(w[0]);
    t.line = n;
    for (const RodType& o : rod_types_)
      if (o.name == t.name)
        return Error(n, "ROD TYPES TypeName",
                     absl::StrCat("\"", t.name, "\" already defined on line ", o.line));
    double* values[] = {&t.diameter, &t.mass_per_length, &t.cd, &t.ca, &t.cd_end, &t.ca_end};
    for (int k = 1; k < 7; ++k) {
      const std::string field = absl::StrCat("ROD TYPES ", kColumns[k]);
      absl::StatusOr<double> v = k == 1 ? Positive(n, field, w[k]) : NonNegative(n, field, w[k]);
      if (!v.ok()) return v.status();
      *values[k - 1] = *v;
    }
    rod_types_.push_back(t);
    return absl::OkStatus();
  }

  // Rotation of MoorDyn's roll, pitch and yaw [deg]: about x, then the
  // new y, then the new z (R = Rx Ry Rz).
  static Eigen::Matrix3d Rotation(double roll, double pitch, double yaw) {
    const double k = kPi / 180;
    return (Eigen::AngleAxisd(roll * k, Eigen::Vector3d::UnitX()) *
            Eigen::AngleAxisd(pitch * k, Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(yaw * k, Eigen::Vector3d::UnitZ()))
        .toRotationMatrix();
  }

  absl::Status ParseBody(int n, const std::vector<absl::string_view>& w) {
    static constexpr const char* kColumns[] = {"ID", "Attachment", "X0", "Y0", "Z0", "r0", "p0",
                                               "y0", "Mass", "CG",  "I",  "Volume", "CdA",
                                               "Ca"};
    if (w.size() != 14) {
      return Error(n, "BODIES",
                   absl::StrCat("expected the 14 columns ID Attachment X0 Y0 Z0 r0 p0 y0 Mass CG "
                                "I Volume CdA Ca, got ",
                                w.size()));
    }
    auto col = [&](int k) { return absl::StrCat("BODIES ", kColumns[k]); };
    MdBody b;
    b.line = n;
    if (!absl::SimpleAtoi(w[0], &b.id) || b.id != static_cast<int>(md_bodies_.size()) + 1) {
      return Error(n, col(0), absl::StrCat("\"", w[0], "\": bodies are numbered 1, 2, ... in "
                                           "order (MoorDyn's rule); expected ",
                                           md_bodies_.size() + 1));
    }
    const std::string type = absl::AsciiStrToLower(w[1]);
    if (type == "fixed" || type == "fix" || type == "anchor") {
      b.mount = Mount::kFixed;
    } else if (type == "vessel" || type == "ves" || type == "coupled" || type == "cpld") {
      b.mount = Mount::kCoupled;
    } else if (type == "vesselpinned" || type == "vespin" || type == "cpldpin" ||
               type == "coupledpinned") {
      b.mount = Mount::kCoupledPinned;
    } else if (type == "free" || type == "point" || type == "con") {
      b.mount = Mount::kFree;
    } else {
      return Error(n, col(1), absl::StrCat("unknown body type \"", w[1],
                                           "\" (Fixed, Free, Coupled or CoupledPinned)"));
    }
    double r6[6];
    for (int k = 2; k < 8; ++k) {
      absl::StatusOr<double> v = Number(n, col(k), w[k]);
      if (!v.ok()) return v.status();
      r6[k - 2] = *v;
    }
    b.position = Eigen::Vector3d(r6[0], r6[1], r6[2]);
    b.rotation = Rotation(r6[3], r6[4], r6[5]);
    absl::StatusOr<double> mass = NonNegative(n, col(8), w[8]);
    if (!mass.ok()) return mass.status();
    b.mass = *mass;
    absl::StatusOr<std::vector<double>> cg = Numbers(n, col(9), w[9], 3);
    if (!cg.ok()) return cg.status();
    // One number: the CG's z (MoorDyn's rule).
    b.cg = cg->size() == 1 ? Eigen::Vector3d(0, 0, (*cg)[0])
                           : Eigen::Vector3d((*cg)[0], (*cg)[1], (*cg)[2]);
    absl::StatusOr<std::vector<double>> inertia = Numbers(n, col(10), w[10], 3);
    if (!inertia.ok()) return inertia.status();
    for (double v : *inertia)
      if (v < 0) return Error(n, col(10), absl::StrCat("must be >= 0 (got ", w[10], ")"));
    b.inertia = inertia->size() == 1 ? Eigen::Vector3d::Constant((*inertia)[0])
                                     : Eigen::Vector3d((*inertia)[0], (*inertia)[1], (*inertia)[2]);
    absl::StatusOr<double> volume = NonNegative(n, col(11), w[11]);
    if (!volume.ok()) return volume.status();
    b.volume = *volume;
    // Drag areas per body axis, as MoorDyn's manual gives them: one for
    // all six degrees of freedom; two, translation then rotation; three,
    // x, y, z for both; six, x, y, z then about x, y, z.
    absl::StatusOr<std::vector<double>> cda = Numbers(n, col(12), w[12], 2, 3, 6);
    if (!cda.ok()) return cda.status();
    for (double v : *cda)
      if (v < 0) return Error(n, col(12), absl::StrCat("must be >= 0 (got ", w[12], ")"));
    const std::vector<double>& a = *cda;
    switch (a.size()) {
      case 1: b.cda = b.cda_rotation = Eigen::Vector3d::Constant(a[0]); break;
      case 2:
        b.cda = Eigen::Vector3d::Constant(a[0]);
        b.cda_rotation = Eigen::Vector3d::Constant(a[1]);
        break;
      case 3: b.cda = b.cda_rotation = Eigen::Vector3d(a[0], a[1], a[2]); break;
      default:
        b.cda = Eigen::Vector3d(a[0], a[1], a[2]);
        b.cda_rotation = Eigen::Vector3d(a[3], a[4], a[5]);
    }
    absl::StatusOr<std::vector<double>> ca = Numbers(n, col(13), w[13], 3);
    if (!ca.ok()) return ca.status();
    for (double v : *ca) {
      if (v < 0) return Error(n, col(13), absl::StrCat("must be >= 0 (got ", w[13], ")"));
      if (v != (*ca)[0]) {
        return Error(n, col(13), absl::StrCat("\"", w[13], "\": added mass per axis cannot be "
                                              "expressed (one Ca, the same in every direction)"));
      }
    }
    b.ca = (*ca)[0];
    md_bodies_.push_back(b);
    return absl::OkStatus();
  }

  absl::Status ParseRod(int n, const std::vector<absl::string_view>& w) {
    if (w.size() != 11) {
      return Error(n, "RODS",
                   absl::StrCat("expected the 11 columns ID RodType Attachment Xa Ya Za Xb Yb Zb "
                                "NumSegs RodOutputs, got ",
                                w.size()));
    }
    Rod r;
    r.line = n;
    if (!absl::SimpleAtoi(w[0], &r.id) || r.id != static_cast<int>(rods_.size()) + 1) {
      return Error(n, "RODS ID", absl::StrCat("\"", w[0], "\": rods are numbered 1, 2, ... in "
                                              "order (MoorDyn's rule); expected ",
                                              rods_.size() + 1));
    }
    for (const RodType& t : rod_types_)
      if (t.name == w[1]) r.type = &t;
    if (r.type == nullptr) {
      return Error(n, "RODS RodType", absl::StrCat("unknown rod type \"", w[1],
                                                   "\" (define it in ROD TYPES before RODS)"));
    }
    const std::string type = absl::AsciiStrToLower(w[2]);
    absl::string_view rest = type;
    if (type == "fixed" || type == "fix" || type == "anchor") {
      r.mount = Mount::kFixed;
    } else if (type == "pinned" || type == "pin") {
      r.mount = Mount::kPinned;
    } else if (type == "vessel" || type == "ves" || type == "coupled" || type == "cpld") {
      r.mount = Mount::kCoupled;
    } else if (type == "vesselpinned" || type == "vespin" || type == "cpldpin" ||
               type == "coupledpinned") {
      r.mount = Mount::kCoupledPinned;
    } else if (type == "free" || type == "point" || type == "con") {
      r.mount = Mount::kFree;
    } else if (absl::ConsumePrefix(&rest, "body")) {
      const size_t digits = rest.find_first_not_of("0123456789");
      const absl::string_view suffix =
          digits == absl::string_view::npos ? absl::string_view() : rest.substr(digits);
      if (!absl::SimpleAtoi(rest.substr(0, digits), &r.body) || r.body < 1) {
        return Error(n, "RODS Attachment",
                     absl::StrCat("\"", w[2], "\": Body<N> needs the body's number"));
      }
      if (r.body > static_cast<int>(md_bodies_.size())) {
        return Error(n, "RODS Attachment",
                     absl::StrCat("body ", r.body,
                                  " does not exist (define it in BODIES before RODS)"));
      }
      if (suffix.empty()) {
        r.mount = Mount::kOnBody;
      } else if (suffix == "pinned" || suffix == "pin") {
        r.mount = Mount::kPinned;
      } else {
        return Error(n, "RODS Attachment",
                     absl::StrCat("\"", w[2], "\": Body<N> or Body<N>Pinned"));
      }
    } else {
      return Error(n, "RODS Attachment",
                   absl::StrCat("unknown rod attachment \"", w[2],
                                "\" (Fixed, Pinned, Free, Coupled, CoupledPinned, Body<N>, "
                                "Body<N>Pinned)"));
    }
    double e[6];
    for (int k = 3; k < 9; ++k) {
      static constexpr const char* kEnds[] = {"Xa", "Ya", "Za", "Xb", "Yb", "Zb"};
      absl::StatusOr<double> v = Number(n, absl::StrCat("RODS ", kEnds[k - 3]), w[k]);
      if (!v.ok()) return v.status();
      e[k - 3] = *v;
    }
    r.a_rel = Eigen::Vector3d(e[0], e[1], e[2]);
    r.b_rel = Eigen::Vector3d(e[3], e[4], e[5]);
    // NumSegs only divides a MoorDyn rod's loads along it (the rod is
    // rigid either way); 0 makes a rod of zero length at end A: a joint of
    // the lines at it with its ends' loads (JoinAtPointRods).
    if (!absl::SimpleAtoi(w[9], &r.segments) || r.segments < 0) {
      return Error(n, "RODS NumSegs",
                   absl::StrCat("must be a whole number >= 0 (got ", w[9], ")"));
    }
    const bool zero_length = !((r.b_rel - r.a_rel).norm() > 0);
    if (r.segments == 0 && !zero_length) {
      return Error(n, "RODS NumSegs",
                   "0 makes a rod of zero length at end A (MoorDyn ignores end B's "
                   "coordinates): give end B at end A");
    }
    if (r.segments > 0 && zero_length) {
      return Error(n, "RODS NumSegs",
                   "a rod of zero length has no direction: MoorDyn's point-like rod has "
                   "NumSegs 0");
    }
    if (r.segments == 0 && r.mount != Mount::kFree) {
      const bool pinned = r.mount == Mount::kPinned || r.mount == Mount::kCoupledPinned;
      return Error(n, "RODS Attachment",
                   pinned ? "a pinned rod of zero length cannot be expressed (MoorDyn turns a "
                            "pinned rod by its rotational inertia, which a rod of zero length "
                            "does not have)"
                          : "a rod of zero length that is not Free (Fixed, Coupled, on a body) "
                            "cannot be expressed yet");
    }
    rods_.push_back(r);
    return absl::OkStatus();
  }

  // After parsing: rods and points on bodies placed in the world, rod-end
  // points placed on their rods.
  absl::Status ResolveBodiesAndRods() {
    for (Rod& r : rods_) {
      if (r.body > 0 && (r.mount == Mount::kOnBody || r.mount == Mount::kPinned)) {
        const MdBody& b = md_bodies_[r.body - 1];
        r.a = b.position + b.rotation * r.a_rel;
        r.b = b.position + b.rotation * r.b_rel;
      } else {
        r.a = r.a_rel;
        r.b = r.b_rel;
      }
    }
    for (auto& [id, p] : points_) {
      if (p.body > 0) {
        if (p.body > static_cast<int>(md_bodies_.size())) {
          return Error(p.line, "POINTS Type",
                       absl::StrCat("body ", p.body, " does not exist (define it in BODIES)"));
        }
        const MdBody& b = md_bodies_[p.body - 1];
        const Eigen::Vector3d world = b.position + b.rotation * p.relative;
        p.x = world.x();
        p.y = world.y();
        p.z = world.z();
      }
      if (p.rod > 0) {
        if (p.rod > static_cast<int>(rods_.size())) {
          return Error(p.line, "LINES Attach",
                       absl::StrCat("rod ", p.rod, " does not exist (define it in RODS)"));
        }
        const Rod& r = rods_[p.rod - 1];
        const Eigen::Vector3d& end = p.rod_end_b ? r.b : r.a;
        p.x = end.x();
        p.y = end.y();
        p.z = end.z();
      }
    }
    return absl::OkStatus();
  }

  // A rigid part of a scene body: its mass [kg], centre of mass and
  // inertia about it in world axes.
  struct Part {
    double mass = 0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  };
  static Part RodPart(const Rod& r) {
    const double length = r.length();
    const double m = r.type->mass_per_length * length;
    const double radius = r.type->diameter / 2;
    // A solid cylinder of uniform line density.
    const double axial = m * radius * radius / 2;
    const double transverse = m * (3 * radius * radius + length * length) / 12;
    const Eigen::Vector3d u = (r.b - r.a) / length;
    return Part{m, (r.a + r.b) / 2,
                transverse * Eigen::Matrix3d::Identity() + (axial - transverse) * u * u.transpose()};
  }

  // The cylinder a wet part displaces: centre, unit axis, diameter,
  // length, and the rod type's coefficients (null for a body's own
  // volume: MoorDyn's Volume, CdA and Ca), the deck's line.
  struct Wet {
    Eigen::Vector3d centre, axis;
    double diameter = 0, length = 0;
    const RodType* rod = nullptr;
    const MdBody* body = nullptr;
    int line = 0;
  };

  // Sets the fluid loads of a free scene body whose centre of mass is
  // `com` from its wet parts, one BodyHydrodynamics each (the first in
  // `hydrodynamics`, the others in `hydrodynamics_parts`), or refuses what
  // they cannot express (a cylinder buoyed as a vertical one). A part whose
  // centre is off the centre of mass (a rod on a body, a body's volume at
  // its CG when points or rods move the centre of mass) gets that offset as
  // its `center`, in the body's frame: the world's at the start, as a
  // body's axes are here (a rod's own body has one part, at its centre).
  // `own_rod`: the body is the one rod's, its x axis the rod's
  // (BodyHydrodynamics.along_axis); a tilted rod on a body splits its loads
  // along its own axis (BodyHydrodynamics.axis, in the body's frame).
  absl::Status SetHydrodynamics(const std::vector<Wet>& wet, const Eigen::Vector3d& com,
                                v1::Body* body, bool own_rod = false) const {
    for (size_t k = 0; k < wet.size(); ++k) {
      const Wet& p = wet[k];
      v1::BodyHydrodynamics* h =
          k == 0 ? body->mutable_hydrodynamics() : body->add_hydrodynamics_parts();
      if (absl::Status s = SetPart(p, own_rod, h); !s.ok()) return s;
      const Eigen::Vector3d offset = p.centre - com;
      if (offset.norm() > 1e-6 * std::max(p.length, p.diameter))
        SetVec(h->mutable_center(), offset.x(), offset.y(), offset.z());
    }
    return absl::OkStatus();
  }

  // One wet part's cylinder and coefficients into `h` (SetHydrodynamics).
  absl::Status SetPart(const Wet& p, bool own_rod, v1::BodyHydrodynamics* h) const {
    if (p.body != nullptr) {
      // A body's volume: a vertical cylinder as tall as wide, as a free
      // point's (MoorDyn buoys it by rho g V at its CG and adds Ca rho V;
      // its drag is SetDragAreas').
      const double d = std::cbrt(4 * p.body->volume / kPi);
      h->set_diameter(d);
      h->set_height(d);
      h->set_added_mass(p.body->ca);
      h->set_heave_added_mass(p.body->ca);
      return absl::OkStatus();
    }
    const RodType& t = *p.rod;
    const bool vertical = std::abs(std::abs(p.axis.z()) - 1) < 1e-9;
    const bool loads = t.cd > 0 || t.ca > 0 || t.cd_end > 0 || t.ca_end > 0;
    // A tilted rod's buoyancy is the vertical cylinder's of its length:
    // the same while both are wholly under water (or above it).
    if (!vertical && p.centre.z() + p.length / 2 >= 0 && p.centre.z() - p.length / 2 <= 0) {
      return Error(p.line, "RODS Zb",
                   "a rod that is not vertical within half its length of the water surface "
                   "cannot be expressed: cablesim's body buoyancy is that of a vertical cylinder "
                   "(exact for a tilted rod only while it is wholly under water or above it)");
    }
    if (own_rod) {
      h->set_along_axis(true);
    } else if (!vertical && loads) {
      // A rod on a body: its loads split along its own axis, turning with
      // the body (a vertical one keeps the vertical split, as before).
      h->set_along_axis(true);
      SetVec(h->mutable_axis(), p.axis.x(), p.axis.y(), p.axis.z());
    }
    h->set_diameter(t.diameter);
    h->set_height(p.length);
    const double area = kPi * t.diameter * t.diameter / 4;
    // Across: MoorDyn's Cd on d per length and Ca on the section, as the
    // body's. Along: CdEnd on the end area and CaEnd on the volume
    // (2/3) pi r^3 of each wet end; cablesim's heave terms act on the end
    // area and on rho V_ref (V_ref the submerged volume where the body is
    // placed), so they take the ends wet there.
    const double submerged = std::clamp(p.length / 2 - p.centre.z(), 0.0, p.length);
    const double half_rise = p.length / 2 * std::abs(p.axis.z());
    const int ends = (p.centre.z() - half_rise < 0 ? 1 : 0) + (p.centre.z() + half_rise < 0 ? 1 : 0);
    h->set_drag_coefficient(t.cd);
    h->set_added_mass(t.ca);
    h->set_heave_drag_coefficient(ends * t.cd_end);
    const double end_volume = 2.0 / 3.0 * kPi * std::pow(t.diameter / 2, 3);
    if (submerged > 0) h->set_heave_added_mass(ends * t.ca_end * end_volume / (area * submerged));
    return absl::OkStatus();
  }

  // Whether the deck has water (WtrDnsty > 0) and weight (g > 0).
  bool HasWater() const { return OptionOr("rho", kDefaultDensity) > 0; }
  bool HasGravity() const { return OptionOr("g", kDefaultGravity) > 0; }

  // Whether rod `r` gets fluid loads: in water; without gravity its
  // buoyancy is nothing, and its drag and added mass, which cablesim splits
  // about the vertical or a buoyed cylinder's axis, are refused.
  absl::StatusOr<bool> RodWet(const Rod& r) const {
    if (!HasWater()) return false;
    if (HasGravity()) return true;
    const RodType& t = *r.type;
    if (t.cd > 0 || t.ca > 0 || t.cd_end > 0 || t.ca_end > 0) {
      return Error(t.line, "ROD TYPES Cd",
                   absl::StrCat("rod ", r.id, " (line ", r.line,
                                "): drag or added mass without gravity cannot be expressed (a "
                                "rod's fluid loads are those of a buoyed cylinder, which needs "
                                "the vertical)"));
    }
    return false;
  }

  // MoorDyn's body drag (BODIES CdA): 1/2 rho R diag(CdA) R^T |v| v at the
  // body's reference point and -1/2 rho R diag(CdA_rot) R^T |w| w, in the
  // body's axes R, as BodyHydrodynamics.drag_area and rotational_drag_area
  // (at the centre of mass, in the scene body's axes, the world's).
  absl::Status SetDragAreas(const MdBody& b, const Eigen::Vector3d& com, v1::Body* body) const {
    if (!HasWater() || (b.cda.isZero(0) && b.cda_rotation.isZero(0))) return absl::OkStatus();
    if ((b.position - com).norm() > 1e-9 * std::max(1.0, b.position.norm())) {
      return Error(b.line, "BODIES CG",
                   absl::StrCat("drag (CdA) on a body whose centre of mass lies ",
                                (b.position - com).norm(),
                                " m from its reference point cannot be expressed (MoorDyn's body "
                                "drag acts at the reference point, cablesim's at the centre of "
                                "mass)"));
    }
    Eigen::Vector3d areas[2];
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d& a = k == 0 ? b.cda : b.cda_rotation;
      const Eigen::Matrix3d world = b.rotation * a.asDiagonal() * b.rotation.transpose();
      areas[k] = world.diagonal();
      const Eigen::Matrix3d off = world - Eigen::Matrix3d(areas[k].asDiagonal());
      if (off.cwiseAbs().maxCoeff() > 1e-9 * a.cwiseAbs().maxCoeff()) {
        return Error(b.line, "BODIES CdA",
                     "drag areas that differ between the axes of a body turned off the "
                     "world's axes cannot be expressed (the scene body keeps the world's axes)");
      }
    }
    // On the body's own cylinder, or in a part of their own when that
    // cylinder is off the centre of mass (drag areas act at the centre).
    v1::BodyHydrodynamics* h = body->has_hydrodynamics() && body->hydrodynamics().has_center()
                                   ? body->add_hydrodynamics_parts()
                                   : body->mutable_hydrodynamics();
    SetVec(h->mutable_drag_area(), areas[0].x(), areas[0].y(), areas[0].z());
    SetVec(h->mutable_rotational_drag_area(), areas[1].x(), areas[1].y(), areas[1].z());
    return absl::OkStatus();
  }

  // One scene body of `parts` (mass, centre, inertia in world axes): its
  // mass, position and inertia; axes the world's unless `axis` (a rod's)
  // is given. Returns its centre of mass; refuses an inertia whose
  // principal axes are not the body's.
  absl::StatusOr<Eigen::Vector3d> SetRigid(const std::vector<Part>& parts, int line,
                                           absl::string_view field, const Eigen::Vector3d* axis,
                                           v1::Body* body) const {
    double m = 0;
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    for (const Part& p : parts) {
      m += p.mass;
      com += p.mass * p.centre;
    }
    if (!(m > 0)) {
      return Error(line, field,
                   "a free body needs a mass > 0 (the body's, its points' and its rods')");
    }
    com /= m;
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    for (const Part& p : parts) {
      const Eigen::Vector3d c = p.centre - com;
      inertia += p.inertia + p.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() -
                                       c * c.transpose());
    }
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    if (axis != nullptr) {
      // The scene's body frame from its x axis: y = normalize(e_z x x)
      // (e_x x x when x is along z), z = x x y.
      const Eigen::Vector3d x = *axis;
      Eigen::Vector3d y = Eigen::Vector3d::UnitZ().cross(x);
      if (y.norm() < 1e-9) y = Eigen::Vector3d::UnitX().cross(x);
      y.normalize();
      axes.col(0) = x;
      axes.col(1) = y;
      axes.col(2) = x.cross(y);
      SetVec(body->mutable_axis(), x.x(), x.y(), x.z());
    }
    const Eigen::Matrix3d local = axes.transpose() * inertia * axes;
    const double off = std::max({std::abs(local(0, 1)), std::abs(local(0, 2)),
                                 std::abs(local(1, 2))});
    if (off > 1e-9 * local.trace()) {
      return Error(line, "BODIES I",
                   "with its rods and points the body's principal axes are not the world's "
                   "axes at the start (cablesim takes principal moments of inertia)");
    }
    // Mass all on a line through the centre (point masses on a body of
    // I 0, MoorDyn's orbitalBody.txt) leaves no inertia about that line,
    // where nothing turns it: there the parts get the sphere of 0.1 m a
    // free point gets.
    Eigen::Vector3d moments = local.diagonal();
    for (int k = 0; k < 3; ++k)
      if (!(local(k, k) > 1e-12 * local.trace())) moments(k) = 0.4 * m * 0.1 * 0.1;
    body->set_mass(m);
    SetVec(body->mutable_inertia(), moments.x(), moments.y(), moments.z());
    SetVec(body->mutable_position(), com.x(), com.y(), com.z());
    return com;
  }

  // The scene bodies and joints of the deck's bodies and rods, and what
  // each body point and rod end is joined to (holders_).
  absl::Status BuildBodiesAndRods(v1::Scene* scene) const {
    // On a fixed body or rod: held by the ground where it is.
    auto held = [] { return Holder{}; };
    auto rod_ends = [&](int rod_id, auto&& holder_of_end) {
      for (const auto& [id, p] : points_)
        if (p.rod == rod_id) holders_[id] = holder_of_end(p);
    };
    // Bodies.
    for (const MdBody& b : md_bodies_) {
      std::vector<int> rods;  // rigidly on the body
      for (const Rod& r : rods_)
        if (r.mount == Mount::kOnBody && r.body == b.id) rods.push_back(r.id);
      if (b.mount == Mount::kFixed) {
        for (const auto& [id, p] : points_)
          if (p.body == b.id) holders_[id] = held();
        for (int r : rods) rod_ends(r, [&](const Point&) { return held(); });
        continue;
      }
      v1::Body* body = scene->add_bodies();
      body_points_.push_back(b.line);
      const std::string name = absl::StrCat("body", b.id);
      body->set_name(name);
      Eigen::Vector3d com;
      if (b.mount == Mount::kCoupled) {
        // A coupled body's mass, volume and loads are the host's (MoorDyn
        // ignores them too); the host drives the reference point. Rods on
        // it would have their fluid loads reported to the host by MoorDyn.
        if (!rods.empty()) {
          return Error(rods_[rods.front() - 1].line, "RODS Attachment",
                       "a rod on a coupled body cannot be expressed (its fluid loads, which "
                       "MoorDyn reports to the host, would be dropped)");
        }
        body->set_coupled(true);
        body->set_mass(b.mass > 0 ? b.mass : 1.0);
        SetVec(body->mutable_inertia(), 1, 1, 1);
        com = b.position;
        SetVec(body->mutable_position(), com.x(), com.y(), com.z());
      } else {
        std::vector<Part> parts;
        std::vector<Wet> wet;
        const Eigen::Vector3d cg = b.position + b.rotation * b.cg;
        parts.push_back(Part{b.mass, cg,
                             b.rotation * b.inertia.asDiagonal() * b.rotation.transpose()});
        // The volume buoys the body and carries its added mass Ca rho V
        // (nothing in a dry deck; without gravity, nothing but the added
        // mass, which needs the vertical of cablesim's buoyed cylinder).
        // A body without volume has no added mass (MoorDyn's is Ca rho V).
        if (b.volume > 0 && HasWater()) {
          if (HasGravity()) {
            wet.push_back(Wet{cg, Eigen::Vector3d::UnitZ(), 0, 0, nullptr, &b, b.line});
          } else if (b.ca > 0) {
            return Error(b.line, "BODIES Ca",
                         "added mass without gravity cannot be expressed (a body's added mass "
                         "is that of its buoyed cylinder, which needs the vertical)");
          }
        }
        for (const auto& [id, p] : points_)
          if (p.body == b.id && p.mass > 0)
            parts.push_back(Part{p.mass, Eigen::Vector3d(p.x, p.y, p.z),
                                 Eigen::Matrix3d::Zero()});
        for (int id : rods) {
          const Rod& r = rods_[id - 1];
          parts.push_back(RodPart(r));
          absl::StatusOr<bool> rod_wet = RodWet(r);
          if (!rod_wet.ok()) return rod_wet.status();
          if (*rod_wet) {
            wet.push_back(Wet{(r.a + r.b) / 2, (r.b - r.a) / r.length(), r.type->diameter,
                              r.length(), r.type, nullptr, r.line});
          }
        }
        absl::StatusOr<Eigen::Vector3d> c = SetRigid(parts, b.line, "BODIES Mass", nullptr, body);
        if (!c.ok()) return c.status();
        com = *c;
        if (absl::Status s = SetHydrodynamics(wet, com, body); !s.ok()) return s;
        if (absl::Status s = SetDragAreas(b, com, body); !s.ok()) return s;
        if (b.mount == Mount::kCoupledPinned) {
          // Its reference point driven by the host, its rotation free.
          v1::Joint* j = scene->add_joints();
          j->set_name(absl::StrCat("body", b.id));
          j->set_type(v1::PIN);
          j->mutable_a()->set_body(name);
          const Eigen::Vector3d rel = b.position - com;
          SetVec(j->mutable_a()->mutable_point(), rel.x(), rel.y(), rel.z());
          j->set_coupled(true);
        }
      }
      for (const auto& [id, p] : points_) {
        if (p.body != b.id) continue;
        holders_[id] = Holder{false, false, name, Eigen::Vector3d(p.x, p.y, p.z) - com};
      }
      for (int r : rods) {
        rod_ends(r, [&](const Point& p) {
          return Holder{false, false, name, Eigen::Vector3d(p.x, p.y, p.z) - com};
        });
      }
    }
    // Rods of their own.
    for (const Rod& r : rods_) {
      if (r.mount == Mount::kOnBody) continue;
      if (r.segments == 0) continue;  // a joint of its lines (JoinAtPointRods)
      const bool on_fixed_body = r.body > 0 && md_bodies_[r.body - 1].mount == Mount::kFixed;
      if (r.mount == Mount::kFixed) {
        rod_ends(r.id, [&](const Point&) { return held(); });
        continue;
      }
      v1::Body* body = scene->add_bodies();
      body_points_.push_back(r.line);
      const std::string name = absl::StrCat("rod", r.id);
      body->set_name(name);
      const double length = r.length();
      const Eigen::Vector3d axis = (r.b - r.a) / length;
      absl::StatusOr<Eigen::Vector3d> com =
          SetRigid({RodPart(r)}, r.line, "ROD TYPES Mass/m", &axis, body);
      if (!com.ok()) return com.status();
      absl::StatusOr<bool> rod_wet = r.mount == Mount::kCoupled ? absl::StatusOr<bool>(false) : RodWet(r);
      if (!rod_wet.ok()) return rod_wet.status();
      if (r.mount == Mount::kCoupled) {
        body->set_coupled(true);
      } else if (*rod_wet) {
        absl::Status s = SetHydrodynamics(
            {Wet{*com, axis, r.type->diameter, length, r.type, nullptr, r.line}}, *com, body,
            /*own_rod=*/true);
        if (!s.ok()) return s;
      }
      if (r.mount == Mount::kPinned || r.mount == Mount::kCoupledPinned) {
        // End A pinned: to the ground, a fixed body, or a body's point.
        v1::Joint* j = scene->add_joints();
        j->set_name(absl::StrCat("rod", r.id, "A"));
        j->set_type(v1::PIN);
        j->mutable_a()->set_body(name);
        SetVec(j->mutable_a()->mutable_point(), -length / 2, 0, 0);
        if (r.mount == Mount::kCoupledPinned) j->set_coupled(true);
        if (r.body > 0 && !on_fixed_body) {
          const MdBody& b = md_bodies_[r.body - 1];
          if (b.mount == Mount::kCoupled) {
            return Error(r.line, "RODS Attachment",
                         "a rod pinned to a coupled body cannot be expressed yet");
          }
          // The body's scene name and centre of mass: from the scene.
          const std::string body_name = absl::StrCat("body", b.id);
          for (const v1::Body& o : scene->bodies()) {
            if (o.name() != body_name) continue;
            const Eigen::Vector3d rel =
                r.a - Eigen::Vector3d(o.position().x(), o.position().y(), o.position().z());
            j->mutable_b()->set_body(body_name);
            SetVec(j->mutable_b()->mutable_point(), rel.x(), rel.y(), rel.z());
          }
        }
      }
      rod_ends(r.id, [&](const Point& p) {
        return Holder{false, false, name,
                      Eigen::Vector3d(p.rod_end_b ? length / 2 : -length / 2, 0, 0)};
      });
    }
    return absl::OkStatus();
  }

  absl::string_view text_;
  std::string file_;
  MoorDynFileReader read_file_;  // null: files the deck names cannot be read
  std::vector<LineType> line_types_;
  std::map<int, Point> points_;
  std::vector<Line> lines_;
  std::map<std::string, Option> options_;
  std::vector<int> probe_points_;
  std::vector<BodyChannel> body_channels_;
  std::vector<TensionChannel> tension_channels_;
  // The file line of OUTPUTS' closing END (0: none yet).
  int outputs_ended_ = 0;
  // The POINTS (BODIES, RODS) row of each body Build made, in scene order
  // (for Located).
  mutable std::vector<int> body_points_;
  std::string seafloor_file_;  // OPTIONS SeafloorFile, empty: a flat bed
  int seafloor_line_ = 0;
  std::vector<RodType> rod_types_;
  std::vector<MdBody> md_bodies_;  // in ID order, from 1
  std::vector<Rod> rods_;          // in ID order, from 1
  // What each body point and rod end (by point ID) is joined to (Build).
  mutable std::map<int, Holder> holders_;
  // The rods of zero length (by rod ID), the lines laid as chains through
  // them (by line index; empty: laid alone) and where the chains put the
  // rods (JoinAtPointRods).
  mutable std::map<int, PointRodJoin> point_rods_;
  mutable std::vector<std::vector<Eigen3>> laid_;
  mutable std::map<int, Eigen3> point_rod_at_;
};

}  // namespace

absl::StatusOr<v1::Scene> SceneFromMoorDyn(std::string_view text, std::string_view file_name,
                                           MoorDynFileReader read_file) {
  return DeckReader(absl::string_view(text.data(), text.size()),
                    absl::string_view(file_name.data(), file_name.size()), std::move(read_file))
      .Read();
}

bool IsMoorDynDeck(std::string_view path_std, std::string_view text_std) {
  const absl::string_view path(path_std.data(), path_std.size());
  const absl::string_view text(text_std.data(), text_std.size());
  if (absl::EndsWithIgnoreCase(path, ".dat")) return true;
  if (absl::EndsWith(path, ".json") || absl::EndsWith(path, ".txtpb") ||
      absl::EndsWith(path, ".textproto") || absl::EndsWith(path, ".pbtxt"))
    return false;
  const absl::string_view start = absl::StripLeadingAsciiWhitespace(text);
  if (absl::StartsWith(start, "{")) return false;
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    line = absl::StripAsciiWhitespace(line);
    if (!absl::StartsWith(line, "---")) continue;
    const std::string upper = absl::AsciiStrToUpper(line);
    // MoorDyn's title line, or any of its section headers: a deck of rods or bodies alone
    // (MoorDyn's RodPinnedFloating.txt, body_tests/orbitalBody.txt) has no LINE TYPES.
    for (absl::string_view header :
         {"MOORDYN", "LINE TYPES", "LINE DICTIONARY", "ROD TYPES", "ROD DICTIONARY",
          "POINT PROPERTIES", "CONNECTION PROPERTIES", "BODIES", "BODY LIST", "RODS", "ROD LIST"}) {
      if (absl::StrContains(upper, header)) return true;
    }
  }
  return false;
}

}  // namespace cablesim
