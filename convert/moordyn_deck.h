#ifndef CABLESIM_CONVERT_MOORDYN_DECK_H_
#define CABLESIM_CONVERT_MOORDYN_DECK_H_

// MoorDyn v2 input files ("decks") read into a cablesim.v1.Scene: line
// types, points (fixed, vessel/coupled, free with mass and volume), lines,
// options and output channels. Every convention is translated into the
// scene's SI fields as docs/moordyn-files.md tabulates (mass per length to
// density through the diameter's area, EA to Young's modulus, kBot and
// cBot per unit area to the seabed's per unit length, a negative BA as a
// damping ratio, ...), and lines get the engineering-strain axial law
// (T = EA e, the law a deck's EA means). What a scene cannot express is
// refused with InvalidArgument naming the file, its line and the field:
//   chain.dat:7: LINE TYPES EA: "poly.txt|1e9": a viscoelastic or Syrope law ...
// never dropped. A line type whose EA names a file (MoorDyn's nonlinear
// line types) gets the TABLE law with the file's knots. The scene is
// MoorDyn's initial-condition problem, a STATIC analysis of the lines as
// the deck places their ends.

#include <functional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "cablesim/v1/scene.pb.h"

namespace cablesim {

// Reads a file a deck names (a tension-strain table), by the name the
// deck gives, relative to the deck's directory as MoorDyn reads it.
using MoorDynFileReader = std::function<absl::StatusOr<std::string>(std::string_view name)>;

// Parses the text of a MoorDyn v2 input file. `file_name` starts every
// error message and names the scene (its base name without extension).
// Without `read_file` (the service, which takes a deck's text alone) a
// line type whose EA names a table file is refused naming its line.
absl::StatusOr<v1::Scene> SceneFromMoorDyn(std::string_view text, std::string_view file_name,
                                           MoorDynFileReader read_file = nullptr);

// True when the file at `path` with contents `text` is a MoorDyn deck: its
// name ends in `.dat`, or (any name but a JSON or text-format scene's) it
// is not JSON and has a dashed section header naming LINE TYPES or LINE
// DICTIONARY, as MoorDyn's own `.txt` inputs do.
bool IsMoorDynDeck(std::string_view path, std::string_view text);

}  // namespace cablesim

#endif  // CABLESIM_CONVERT_MOORDYN_DECK_H_
