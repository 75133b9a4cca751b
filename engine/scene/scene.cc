#include "engine/scene/scene.h"

namespace cablesim {

bool IsZero(const TimeVector& v) {
  return v[0].IsZero() && v[1].IsZero() && v[2].IsZero();
}

Eigen::Vector3d Evaluate(const TimeVector& v, double t, int order) {
  Eigen::Vector3d r;
  for (int d = 0; d < 3; ++d) {
    const TimeFunction::Value x = v[d].Evaluate(t);
    r(d) = order == 0 ? x.f : order == 1 ? x.df : x.ddf;
  }
  return r;
}

void AddCoupledBodyDrivers(Scene* scene) {
  for (int b = 0; b < static_cast<int>(scene->bodies.size()); ++b) {
    if (!scene->bodies[b].coupled) continue;
    bool has = false;
    for (const JointSpec& j : scene->joints) has = has || (j.coupled_rotation && j.a.body == b);
    if (has) continue;
    JointSpec driver;
    driver.type = JointType::kFixed;
    driver.a.body = b;
    driver.coupled = true;
    driver.coupled_rotation = true;
    driver.name = scene->bodies[b].name + " (coupled)";
    scene->joints.push_back(driver);
  }
}

std::string_view AnalysisName(Analysis analysis) {
  switch (analysis) {
    case Analysis::kDynamic:
      return "DYNAMIC";
    case Analysis::kStatic:
      return "STATIC";
    case Analysis::kModal:
      return "MODAL";
  }
  return "UNKNOWN";
}

std::string_view LinearSolverName(LinearSolverKind solver) {
  switch (solver) {
    case LinearSolverKind::kMinres:
      return "MINRES";
    case LinearSolverKind::kGmres:
      return "GMRES";
    case LinearSolverKind::kDirect:
      return "DIRECT";
    case LinearSolverKind::kAuto:
      return "AUTO";
  }
  return "UNKNOWN";
}

std::string ReuseCostsNewton(const Scene& scene) {
  if (scene.seabed.enabled)
    return "the seabed contact's tangent (touchdown, bed damping and friction) changes with "
           "the state";
  if (scene.fluid.density_kg_m3 > 0) {
    for (const CableSpec& c : scene.cables)
      if (c.normal_drag > 0 || c.tangential_drag > 0)
        return "the cables' fluid drag tangent changes with the state";
  }
  return "";
}

}  // namespace cablesim
