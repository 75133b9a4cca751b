#ifndef CABLESIM_TESTS_TEST_UTIL_H_
#define CABLESIM_TESTS_TEST_UTIL_H_

// Shared helpers for engine tests: scenes from JSON, and a sink that keeps
// every frame.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/simulation.h"

namespace cablesim::testing {

inline Scene SceneFromJson(const std::string& json) {
  auto proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : Scene{};
}

class CollectingSink : public FrameSink {
 public:
  absl::Status OnStart(const ModelInfo& info) override {
    info_ = info;
    return absl::OkStatus();
  }
  absl::Status OnFrame(const Frame& frame) override {
    frames_.push_back(frame);
    return absl::OkStatus();
  }
  const ModelInfo& info() const { return info_; }
  const std::vector<Frame>& frames() const { return frames_; }

 private:
  ModelInfo info_;
  std::vector<Frame> frames_;
};

// Runs a scene that must succeed; the frames land in `sink`.
inline RunSummary RunOk(const Scene& scene, CollectingSink* sink) {
  auto summary = RunScene(scene, sink);
  EXPECT_TRUE(summary.ok()) << summary.status();
  if (!summary.ok()) return RunSummary{};
  EXPECT_EQ(summary->status, "ok") << summary->error;
  return *summary;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_TEST_UTIL_H_
