// Fuzz target: a scene file's bytes through everything `cablesim validate`
// does with them: strict JSON parsing (or text format, or a MoorDyn deck),
// validation and conversion, and building the model. Any input must end in a status, never
// a crash, a sanitizer report or a hang.
//
// Built as a libFuzzer binary with clang (-DCABLESIM_FUZZ=ON), and in every
// build as a replay driver (replay_main.cc) that CTest runs over the corpus.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "absl/status/statusor.h"
#include "convert/moordyn_deck.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/run/simulation.h"

namespace {

// Larger models are valid but slow to build: they test the fuzzer's patience,
// not the code.
constexpr long kMaxFuzzElements = 2000;

void Check(const absl::StatusOr<cablesim::v1::Scene>& proto) {
  if (!proto.ok()) return;
  const absl::StatusOr<cablesim::Scene> scene = cablesim::SceneFromProto(*proto);
  if (!scene.ok()) return;
  long elements = 0;
  for (const cablesim::CableSpec& cable : scene->cables) elements += cable.elements;
  if (elements + 20 * static_cast<long>(scene->joints.size() + scene->loads.size() +
                                        scene->probes.size()) >
      kMaxFuzzElements) {
    return;
  }
  (void)cablesim::DescribeModel(*scene);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Check(cablesim::ParseSceneJson(text));
  Check(cablesim::ParseSceneTextFormat(text));
  Check(cablesim::SceneFromMoorDyn(text, "fuzz.dat"));
  return 0;
}
