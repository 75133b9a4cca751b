#ifndef CABLESIM_TESTS_SAMPLE_SCENE_JSON_H_
#define CABLESIM_TESTS_SAMPLE_SCENE_JSON_H_

// A sample scene's JSON with its solver section replaced, for tests that
// run a scene from scenes/ with other settings and need the JSON (field
// checks in convert/ read JSON, not the Scene struct).

#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace cablesim::testing {

// scenes/`file` with everything from its "solver" key on replaced by `more`
// (top-level fields, each followed by a comma, or empty) and a solver
// section holding `solver`'s fields. The solver must be the file's last key.
inline std::string SampleSceneJsonWithSolver(const std::string& file, const std::string& more,
                                             const std::string& solver) {
  std::ifstream in(std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + file);
  std::stringstream text;
  text << in.rdbuf();
  const std::string json = text.str();
  const size_t at = json.find("\"solver\"");
  EXPECT_NE(at, std::string::npos) << file;
  return json.substr(0, at) + more + "\"solver\": {" + solver + "}}";
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_SAMPLE_SCENE_JSON_H_
