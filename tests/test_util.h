#ifndef CABLESIM_TESTS_TEST_UTIL_H_
#define CABLESIM_TESTS_TEST_UTIL_H_

// Shared helpers for engine tests: scenes from JSON, and a sink that keeps
// every frame.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/model/multibody_model.h"
#include "engine/run/simulation.h"
#include "engine/linear/skyline_ldlt.h"

namespace cablesim::testing {

inline Scene SceneFromJson(const std::string& json) {
  auto proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  auto scene = SceneFromProto(*proto);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : Scene{};
}

// The message of the scene's validation error ("ok" when it converts),
// expecting INVALID_ARGUMENT.
inline std::string SceneError(const std::string& json) {
  auto proto = ParseSceneJson(json);
  EXPECT_TRUE(proto.ok()) << proto.status();
  if (!proto.ok()) return "";
  auto scene = SceneFromProto(*proto);
  if (scene.ok()) return "ok";
  EXPECT_EQ(scene.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(scene.status().message());
}

// The scene's error from parsing, converting or building its model (ok
// when all three pass).
inline absl::Status BuildStatus(const std::string& json) {
  auto proto = ParseSceneJson(json);
  if (!proto.ok()) return proto.status();
  auto scene = SceneFromProto(*proto);
  if (!scene.ok()) return scene.status();
  return MultibodyModel::Build(*scene).status();
}

// A winch model's power at rest against its energy's explicit rate: at q
// (the layout off by up to 1e-4 m a coordinate) with qdot = 0 and time t,
// {dE/dt|_q by central differences at 1e-3 and 5e-4 s extrapolated,
// ExternalPower - DampingPower} (the two agree when the winch's power
// books every potential's change with L(t)).
inline std::pair<double, double> EnergyRateAndWinchPower(MultibodyModel& model, double t) {
  Eigen::VectorXd q(model.coordinates());
  model.ToFull(model.initial_z(), &q);
  for (int i = 0; i < q.size(); ++i) q(i) += 1e-4 * std::sin(1.7 * i + 0.3);
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(q.size());
  auto energy = [&](double at) {
    model.SetTime(at);
    return model.Energy(q, rest, 1.0).total;
  };
  auto difference = [&](double h) { return (energy(t + h) - energy(t - h)) / (2 * h); };
  const double rate = (4 * difference(5e-4) - difference(1e-3)) / 3;
  model.SetTime(t);
  return {rate, model.ExternalPower(q, rest) - model.DampingPower(q, rest)};
}

// A sample scene from scenes/ (e.g. "mooring-three-line-buoy.json"), that
// must parse and convert.
inline Scene SampleScene(const std::string& file) {
  auto proto = ReadSceneFile(std::string(CABLESIM_SOURCE_DIR) + "/scenes/" + file);
  EXPECT_TRUE(proto.ok()) << proto.status();
  if (!proto.ok()) return Scene{};
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
  // The tests of momentum read it.
  bool wants_angular_momentum() const override { return true; }
  const ModelInfo& info() const { return info_; }
  const std::vector<Frame>& frames() const { return frames_; }

 private:
  ModelInfo info_;
  std::vector<Frame> frames_;
};

// The index of the probe called `name` in `info`, or -1.
inline int ProbeIndex(const ModelInfo& info, const std::string& name) {
  for (size_t i = 0; i < info.probe_names.size(); ++i)
    if (info.probe_names[i] == name) return static_cast<int>(i);
  return -1;
}

// Runs a scene that must succeed; the frames land in `sink`.
inline RunSummary RunOk(const Scene& scene, CollectingSink* sink) {
  auto summary = RunScene(scene, sink);
  EXPECT_TRUE(summary.ok()) << summary.status();
  if (!summary.ok()) return RunSummary{};
  EXPECT_EQ(summary->status, "ok") << summary->error;
  return *summary;
}

// The damping's share of the Newton matrix against central differences of
// the damping force in the rates (step `step`), at the model's initial
// configuration, its current time and rates `zdot` (empty: 0.3 sin(1.7 i +
// 0.4) for unknown i): returns the largest entry error of C =
// -df/d(zdot), and the largest entry of the difference quotient in `size`.
// Also expects DampingPower to be -zdot . f.
inline double DampingTangentError(MultibodyModel& model, Eigen::VectorXd zdot, double step,
                                  double* size) {
  const int n = model.dofs(), nq = model.coordinates();
  if (zdot.size() == 0) {
    zdot.resize(n);
    for (int i = 0; i < n; ++i) zdot(i) = 0.3 * std::sin(1.7 * i + 0.4);
  }
  Eigen::VectorXd q(nq), qd(nq);
  model.ToFull(model.initial_z(), &q);
  model.RateToFull(zdot, &qd);
  SkylineLdlt c;
  c.SetPattern(model.envelope());
  c.SetZero();
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n);
  model.DampingForce(q, qd, &f, &c, 1.0);
  EXPECT_NEAR(model.DampingPower(q, qd), -zdot.dot(f), 1e-12 * f.lpNorm<1>());
  double worst = 0;
  *size = 0;
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd zp = zdot, zm = zdot, fp = Eigen::VectorXd::Zero(n),
                    fm = Eigen::VectorXd::Zero(n);
    zp(j) += step;
    zm(j) -= step;
    model.RateToFull(zp, &qd);
    model.DampingForce(q, qd, &fp);
    model.RateToFull(zm, &qd);
    model.DampingForce(q, qd, &fm);
    for (int i = 0; i < n; ++i) {
      const int slot = i >= j ? c.Slot(i, j) : c.Slot(j, i);
      const double cij = slot >= 0 ? c.values()[slot] : 0.0;
      const double fd = -(fp(i) - fm(i)) / (2 * step);
      worst = std::max(worst, std::abs(cij - fd));
      *size = std::max(*size, std::abs(fd));
    }
  }
  return worst;
}

}  // namespace cablesim::testing

#endif  // CABLESIM_TESTS_TEST_UTIL_H_
