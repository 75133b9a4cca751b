#include "server/request_checks.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <new>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "convert/moordyn_deck.h"
#include "convert/run_proto.h"
#include "convert/scene_field_path.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/elements/gauss_quadrature.h"
#include "engine/output/run_statistics.h"

namespace cablesim {

absl::Status CheckStringLengths(const google::protobuf::Message& message,
                                const ServerLimits& limits, const std::string& prefix) {
  using google::protobuf::FieldDescriptor;
  const google::protobuf::Reflection* reflection = message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  for (const FieldDescriptor* field : fields) {
    const std::string path = absl::StrCat(prefix, prefix.empty() ? "" : ".", field->name());
    const int n = field->is_repeated() ? reflection->FieldSize(message, field) : 1;
    for (int i = 0; i < n; ++i) {
      const std::string at = field->is_repeated() ? absl::StrCat(path, "[", i, "]") : path;
      if (field->type() == FieldDescriptor::TYPE_STRING ||
          field->type() == FieldDescriptor::TYPE_BYTES) {
        std::string scratch;
        const std::string& value =
            field->is_repeated()
                ? reflection->GetRepeatedStringReference(message, field, i, &scratch)
                : reflection->GetStringReference(message, field, &scratch);
        if (static_cast<int64_t>(value.size()) > limits.max_name_bytes) {
          return absl::ResourceExhaustedError(
              absl::StrFormat("%s: %d bytes, the server's limit is %d (max_name_bytes)", at,
                              value.size(), limits.max_name_bytes));
        }
      } else if (field->type() == FieldDescriptor::TYPE_MESSAGE) {
        const google::protobuf::Message& sub =
            field->is_repeated() ? reflection->GetRepeatedMessage(message, field, i)
                                 : reflection->GetMessage(message, field);
        if (absl::Status s = CheckStringLengths(sub, limits, at); !s.ok()) return s;
      }
    }
  }
  return absl::OkStatus();
}

namespace {

absl::StatusOr<RunSummary> RunCatchingBadAlloc(const Scene& scene, PreparedRun* prepared,
                                               FrameSink* sink, const RunControl& control) {
  try {
    if (prepared != nullptr && !prepared->used()) return RunPrepared(prepared, sink, control);
    return RunScene(scene, sink, control);
  } catch (const std::bad_alloc&) {
    int64_t elements = 0;
    for (const CableSpec& cable : scene.cables) elements += cable.elements;
    std::string what = absl::StrFormat("%d cable elements", elements);
    if (scene.solver.analysis == Analysis::kModal) {
      absl::StrAppendFormat(&what, ", %d modes", scene.solver.modes);
    }
    return absl::ResourceExhaustedError(absl::StrFormat(
        "cables, solver: the run needs more memory than the server could allocate (%s); "
        "ask for fewer elements, frames or modes",
        what));
  }
}

}  // namespace

namespace {

absl::StatusOr<RunSummary> RunOnComputeThread(const Scene& scene, PreparedRun* prepared,
                                              FrameSink* sink, const RunControl& control,
                                              int compute_nice) {
  absl::StatusOr<RunSummary> result = absl::UnknownError("not run");
  std::thread compute([&] {
    // Linux: a thread's own nice value (setpriority on its thread id).
    const int tid = static_cast<int>(::syscall(SYS_gettid));
    errno = 0;
    const int nice = ::getpriority(PRIO_PROCESS, tid);
    if (errno == 0 && compute_nice > 0)
      ::setpriority(PRIO_PROCESS, tid, std::min(19, nice + compute_nice));
    result = RunCatchingBadAlloc(scene, prepared, sink, control);
  });
  compute.join();
  return result;
}

}  // namespace

absl::StatusOr<RunSummary> RunSceneWithinMemory(const Scene& scene, FrameSink* sink,
                                                const RunControl& control, int compute_nice) {
  return RunOnComputeThread(scene, nullptr, sink, control, compute_nice);
}

absl::StatusOr<RunSummary> RunSceneWithinMemory(CheckedScene* checked, FrameSink* sink,
                                                const RunControl& control, int compute_nice) {
  return RunOnComputeThread(checked->scene, checked->prepared.get(), sink, control,
                            compute_nice);
}

absl::StatusOr<v1::Scene> SceneOfRequest(bool has_scene, const v1::Scene& scene,
                                         const std::string& json, absl::string_view json_field) {
  if (json.empty()) return scene;
  if (has_scene) {
    return absl::InvalidArgumentError(
        absl::StrCat(json_field, ": give the scene either as a message or as JSON text, not both"));
  }
  absl::StatusOr<v1::Scene> parsed = ParseSceneJson(json);
  if (!parsed.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(json_field, ": ", parsed.status().message()));
  }
  return parsed;
}

absl::StatusOr<v1::Scene> SceneOrDeckOfRequest(bool has_scene, const v1::Scene& scene,
                                               const std::string& json,
                                               const std::string& moordyn) {
  if (moordyn.empty()) return SceneOfRequest(has_scene, scene, json);
  if (has_scene || !json.empty()) {
    return absl::InvalidArgumentError(
        "scene_moordyn: give the scene as a message, as JSON text or as a MoorDyn file, only one");
  }
  if (moordyn.size() > static_cast<size_t>(kMaxSceneBytes)) {
    return absl::InvalidArgumentError(
        absl::StrCat("scene_moordyn: larger than ", kMaxSceneBytes, " bytes"));
  }
  return SceneFromMoorDyn(moordyn, "scene_moordyn");
}

ServerLimits DefaultServerLimits() {
  ServerLimits limits;
  limits.max_elements = 5000;
  limits.max_steps = 5'000'000;
  limits.max_frames = 200'000;
  limits.max_trajectory_values = 32 << 20;
  limits.max_sweep_items = 1000;
  limits.max_streams = 64;
  limits.max_streams_per_peer = 16;
  limits.max_queued_jobs_per_peer = 1000;
  limits.max_modes = 200;
  limits.max_modal_bytes = int64_t{1} << 30;
  limits.max_name_bytes = 256;
  limits.max_coordinates = 1'000'000;
  limits.max_message_bytes = 16 << 20;
  limits.stall_timeout = absl::Seconds(30);
  limits.max_unary_calls = 64;
  limits.max_unary_calls_per_peer = 16;
  limits.max_inflight_bytes = int64_t{1} << 30;
  // What max_steps and max_elements allow a plain cable (2e11): only
  // wave components (and contacts, wraps) beyond that are refused.
  limits.max_work_units = limits.max_steps * limits.max_elements * GaussRule::kMaxPoints;
  return limits;
}

int64_t WorkPerStep(const Scene& scene, int64_t elements) {
  int64_t components = static_cast<int64_t>(scene.fluid.waves.regular.size());
  for (const JonswapSpec& sea : scene.fluid.waves.jonswap) components += sea.components;
  components += static_cast<int64_t>(scene.fluid.waves.components.size());
  // An elevation series: at most half its resampled points as components.
  for (const ElevationSeriesSpec& e : scene.fluid.waves.elevation_series) {
    const double period = e.times_s.back() - e.times_s.front();
    const double interval =
        e.interval_s > 0 ? e.interval_s : period / static_cast<double>(e.times_s.size() - 1);
    components += static_cast<int64_t>(std::min(1e12, period / interval)) / 2 + 1;
  }
  int64_t contacts = 0;
  for (const BodySpec& body : scene.bodies) {
    contacts += static_cast<int64_t>(body.contact_points_m.size());
  }
  int64_t wraps = 0;
  for (const SheaveSpec& sheave : scene.sheaves) {
    for (int c = 0; c < static_cast<int>(scene.cables.size()); ++c) {
      if (sheave.Touches(c)) wraps += scene.cables[c].elements;
    }
  }
  const int64_t bed = scene.seabed.enabled ? elements : 0;
  return elements * GaussRule::kMaxPoints * (1 + components) + contacts + wraps + bed;
}

absl::StatusOr<CheckedScene> CheckScene(const v1::Scene& proto, const ServerLimits& limits,
                                        const std::function<bool()>& should_stop) {
  CheckedScene checked;
  if (absl::Status s = CheckStringLengths(proto, limits); !s.ok()) return s;
  absl::StatusOr<Scene> scene = SceneFromProto(proto);
  if (!scene.ok()) return scene.status();
  checked.scene = std::move(*scene);
  const SolverSettings& solver = checked.scene.solver;
  // Steps and frames from the settings, before building anything large.
  if (solver.analysis == Analysis::kDynamic) {
    checked.end_time_s = solver.duration_s;
    checked.nominal_steps = static_cast<int64_t>(
        std::min(9e18, std::ceil(solver.duration_s / solver.step_s * (1 - 1e-12))));
    const double interval = solver.output_interval_s > 0 ? solver.output_interval_s : solver.step_s;
    checked.frames = 1 + static_cast<int64_t>(
                             std::min(9e18, std::ceil(solver.duration_s / interval * (1 - 1e-12))));
  } else {
    checked.end_time_s = 1;
    checked.nominal_steps = solver.load_steps;
    checked.frames = solver.load_steps;
  }
  if (checked.nominal_steps > limits.max_steps) {
    return absl::ResourceExhaustedError(
        absl::StrFormat("solver: %d steps asked for, the server's limit is %d (max_steps)",
                        checked.nominal_steps, limits.max_steps));
  }
  if (checked.frames > limits.max_frames) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "solver.output_interval: %d frames asked for, the server's limit is %d (max_frames)",
        checked.frames, limits.max_frames));
  }
  // Probes on a moving support add 3 columns (its force): counted for
  // every probe held by one (as the model builder matches them, by cable
  // and arc length or by body and point).
  int64_t force_values = 0;
  for (const ProbeSpec& probe : checked.scene.probes) {
    for (const JointSpec& joint : checked.scene.joints) {
      if (!joint.HasMotion()) continue;
      const Attachment& held = joint.a.IsGround() ? joint.b : joint.a;
      const Attachment& at = probe.at;
      const bool same =
          at.cable >= 0
              ? held.cable == at.cable &&
                    std::abs(held.s_m - at.s_m) <=
                        1e-9 * checked.scene.cables[at.cable].length_m
              : held.body == at.body && at.body >= 0 && held.point_body_m == at.point_body_m;
      if (same) {
        force_values += 3;
        break;
      }
    }
    // A probe at a winch's end (its cable's last point) reports the line
    // tension, unless a moving support there already counted it.
    if (probe.at.cable >= 0) {
      const CableSpec& cable = checked.scene.cables[probe.at.cable];
      bool counted = false;
      for (const JointSpec& joint : checked.scene.joints) {
        if (!joint.HasMotion()) continue;
        const Attachment& held = joint.a.IsGround() ? joint.b : joint.a;
        counted |= held.cable == probe.at.cable &&
                   std::abs(held.s_m - probe.at.s_m) <= 1e-9 * cable.length_m;
      }
      if (!counted && cable.winch.enabled &&
          std::abs(probe.at.s_m - cable.length_m) <= 1e-9 * cable.length_m)
        force_values += 3;
    }
  }
  // output.reactions adds every joint's reaction to every row.
  if (checked.scene.output.reactions) {
    for (const JointSpec& joint : checked.scene.joints)
      force_values += joint.type == JointType::kSlide ? 0 : joint.type == JointType::kFixed ? 6 : 3;
  }
  // output.tension adds NAME.tension and output.bending_moment
  // NAME.bending_moment per probe on a cable, and output.orientation 10
  // values per body, to every row.
  for (const bool on : {checked.scene.output.tension, checked.scene.output.bending_moment}) {
    if (!on) continue;
    for (const ProbeSpec& probe : checked.scene.probes) force_values += probe.at.cable >= 0 ? 1 : 0;
  }
  if (checked.scene.output.orientation)
    force_values += 10 * static_cast<int64_t>(checked.scene.bodies.size());
  // A seabed or a sheave adds energy.contact to every row.
  const bool contact = checked.scene.seabed.enabled || !checked.scene.sheaves.empty();
  const int64_t values =
      checked.frames * FrameRowSize(static_cast<int64_t>(checked.scene.probes.size()),
                                    static_cast<int64_t>(checked.scene.cables.size()),
                                    static_cast<int64_t>(checked.scene.bodies.size()),
                                    /*force_probes=*/0, contact) +
      checked.frames * force_values;
  if (values > limits.max_trajectory_values) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "probes: %d frames of %d probes (with the energy per part) make %d numbers, the server's "
        "limit is %d "
        "(max_trajectory_values)",
        checked.frames, checked.scene.probes.size(), values, limits.max_trajectory_values));
  }
  int64_t requested_elements = 0;
  for (const CableSpec& cable : checked.scene.cables) requested_elements += cable.elements;
  if (requested_elements > limits.max_elements) {
    return absl::ResourceExhaustedError(
        absl::StrFormat("cables: %d elements asked for, the server's limit is %d (max_elements)",
                        requested_elements, limits.max_elements));
  }
  // The work the run will do, before anything is built: a scene within
  // every other limit can still ask for hours of wave kinematics.
  {
    const int64_t per_step = WorkPerStep(checked.scene, requested_elements);
    const double work = static_cast<double>(per_step) * static_cast<double>(checked.nominal_steps);
    if (work > static_cast<double>(limits.max_work_units)) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "solver, fluid.waves: %d steps of %d work units (elements x Gauss points x (1 + wave "
          "components), plus contact points and sheave wraps) make %.3g, the server's limit is "
          "%d (max_work_units)",
          checked.nominal_steps, per_step, work, limits.max_work_units));
    }
  }
  absl::StatusOr<PreparedRun> prepared = Prepare(checked.scene, should_stop);
  if (!prepared.ok()) return prepared.status();
  checked.info = prepared->info();
  checked.prepared = std::make_shared<PreparedRun>(std::move(*prepared));
  if (checked.info.shape) {
    // output.shape adds x, y, z of every node to every row.
    const int64_t shape_values =
        checked.frames *
        (FrameRowSize(static_cast<int64_t>(checked.scene.probes.size()),
                      static_cast<int64_t>(checked.scene.cables.size()),
                      static_cast<int64_t>(checked.scene.bodies.size()), /*force_probes=*/0,
                      contact) +
         force_values + 3 * static_cast<int64_t>(checked.info.node_s.size()));
    if (shape_values > limits.max_trajectory_values) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "output.shape: %d frames of %d nodes make %d numbers, the server's limit is %d "
          "(max_trajectory_values)",
          checked.frames, checked.info.node_s.size(), shape_values,
          limits.max_trajectory_values));
    }
  }
  if (checked.info.elements > limits.max_elements) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "cables: the model has %d elements, the server's limit is %d (max_elements)",
        checked.info.elements, limits.max_elements));
  }
  if (checked.info.coordinates > limits.max_coordinates) {
    return absl::ResourceExhaustedError(absl::StrFormat(
        "cables, bodies: the model has %d coordinates, the server's limit is %d "
        "(max_coordinates)",
        checked.info.coordinates, limits.max_coordinates));
  }
  if (solver.analysis == Analysis::kModal) {
    // As the engine: the modes asked for, or 10 (at most every unknown).
    const int64_t dofs = checked.info.dofs;
    const int64_t modes = solver.modes > 0 ? solver.modes : std::min<int64_t>(10, dofs);
    if (modes > limits.max_modes) {
      return absl::ResourceExhaustedError(
          absl::StrFormat("solver.modes: %d modes asked for, the server's limit is %d (max_modes)",
                          modes, limits.max_modes));
    }
    const double bytes = 8.0 * static_cast<double>(dofs) * static_cast<double>(3 * modes + 1);
    if (bytes > static_cast<double>(limits.max_modal_bytes)) {
      return absl::ResourceExhaustedError(absl::StrFormat(
          "solver.modes: %d modes of %d unknowns need about %.0f MB, the server's limit is "
          "%.0f MB (max_modal_bytes)",
          modes, dofs, bytes / 1e6, static_cast<double>(limits.max_modal_bytes) / 1e6));
    }
  }
  return checked;
}

void SetFieldError(const absl::Status& status, v1::FieldError* error) {
  const std::string message(status.message());
  error->set_code(absl::StatusCodeToString(status.code()));
  const size_t colon = message.find(": ");
  if (colon != std::string::npos && message.find(' ') >= colon) {
    error->set_path(message.substr(0, colon));
    error->set_message(message.substr(colon + 2));
  } else {
    error->set_message(message);
  }
}

std::vector<double> SweepAxisValues(const google::protobuf::RepeatedPtrField<v1::SweepAxis>& axes,
                                    int64_t index) {
  std::vector<double> values(axes.size());
  for (int a = axes.size() - 1; a >= 0; --a) {
    const int64_t n = axes[a].values_size();
    values[a] = axes[a].values(static_cast<int>(index % n));
    index /= n;
  }
  return values;
}

absl::StatusOr<std::vector<v1::Scene>> ExpandSweep(const v1::SubmitSweepRequest& request,
                                                   const ServerLimits& limits,
                                                   std::vector<double>* end_times_s) {
  if (absl::Status s = CheckStringLengths(request, limits); !s.ok()) return s;
  if (request.axes().empty()) return absl::InvalidArgumentError("axes: at least one axis");
  int64_t items = 1;
  for (int a = 0; a < request.axes_size(); ++a) {
    const v1::SweepAxis& axis = request.axes(a);
    if (axis.values().empty()) {
      return absl::InvalidArgumentError(absl::StrCat("axes[", a, "].values: at least one value"));
    }
    // Each path must name a settable field of the base scene.
    v1::Scene probe = request.base();
    if (absl::Status s = SetSceneField(&probe, axis.path(), axis.values(0)); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("axes[", a, "].path: ", s.message()));
    }
    items *= axis.values_size();
    if (items > limits.max_sweep_items) {
      return absl::ResourceExhaustedError(
          absl::StrFormat("axes: more than %d items, the server's limit (max_sweep_items)",
                          limits.max_sweep_items));
    }
  }
  for (int k = 0; k < request.thresholds_size(); ++k) {
    const v1::SweepThreshold& t = request.thresholds(k);
    const std::string field = absl::StrCat("thresholds[", k, "]");
    if (t.column().empty()) return absl::InvalidArgumentError(field + ".column: empty");
    if (!t.has_max() && !t.has_min()) {
      return absl::InvalidArgumentError(field + ": set max, min or both");
    }
    if ((t.has_max() && !std::isfinite(t.max())) || (t.has_min() && !std::isfinite(t.min()))) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, t.has_max() && !std::isfinite(t.max()) ? ".max" : ".min", ": not finite"));
    }
  }
  std::vector<v1::Scene> scenes;
  end_times_s->clear();
  for (int64_t i = 0; i < items; ++i) {
    v1::Scene scene = request.base();
    int64_t rest = i;
    std::vector<int> which(request.axes_size());
    for (int a = request.axes_size() - 1; a >= 0; --a) {
      which[a] = static_cast<int>(rest % request.axes(a).values_size());
      rest /= request.axes(a).values_size();
    }
    for (int a = 0; a < request.axes_size(); ++a) {
      if (absl::Status s =
              SetSceneField(&scene, request.axes(a).path(), request.axes(a).values(which[a]));
          !s.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("axes[", a, "].values[", which[a], "]: ", s.message()));
      }
    }
    // Thresholds are judged on the items' statistics.
    if (request.thresholds_size() > 0) scene.mutable_output()->set_statistics(true);
    absl::StatusOr<CheckedScene> checked = CheckScene(scene, limits);
    if (checked.ok()) {
      for (int k = 0; k < request.thresholds_size(); ++k) {
        if (absl::Status s = CheckStatisticsColumn(checked->info, request.thresholds(k).column(),
                                                   absl::StrCat("thresholds[", k, "].column"));
            !s.ok()) {
          return s;
        }
      }
    }
    if (!checked.ok()) {
      // Name the axis values that make the item invalid.
      std::string where;
      for (int a = 0; a < request.axes_size(); ++a) {
        absl::StrAppend(&where, a ? ", " : "", "axes[", a, "].values[", which[a], "]");
      }
      return absl::Status(checked.status().code(),
                          absl::StrCat(where, " (item ", i, "): ", checked.status().message()));
    }
    if (scene.name().empty()) scene.set_name(request.name());
    end_times_s->push_back(checked->end_time_s);
    scenes.push_back(std::move(scene));
  }
  return scenes;
}

}  // namespace cablesim

namespace cablesim {

std::vector<std::string> ThresholdFailures(
    const google::protobuf::RepeatedPtrField<v1::SweepThreshold>& thresholds,
    const v1::RunSummary& summary) {
  std::vector<std::string> failures;
  for (const v1::SweepThreshold& t : thresholds) {
    const v1::ColumnStatistics* found = nullptr;
    for (const v1::ColumnStatistics& c : summary.statistics().columns()) {
      if (c.column() == t.column()) found = &c;
    }
    if (found == nullptr || found->count() == 0) {
      failures.push_back(absl::StrCat(t.column(), ": no statistics in the item's summary"));
      continue;
    }
    if (t.has_max() && !(found->max() <= t.max())) {
      failures.push_back(absl::StrCat(t.column(), " max ", absl::StrFormat("%.9g", found->max()),
                                      " at t = ", absl::StrFormat("%.9g", found->max_t()),
                                      " s exceeds ", absl::StrFormat("%.9g", t.max())));
    }
    if (t.has_min() && !(found->min() >= t.min())) {
      failures.push_back(absl::StrCat(t.column(), " min ", absl::StrFormat("%.9g", found->min()),
                                      " at t = ", absl::StrFormat("%.9g", found->min_t()),
                                      " s is below ", absl::StrFormat("%.9g", t.min())));
    }
  }
  return failures;
}

}  // namespace cablesim
