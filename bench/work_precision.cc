// The work-precision report: for each scene of a configuration file, every
// integrator setting x linear solver over a range of fixed steps (and of
// tolerances for adaptive runs), the error against a converged reference
// run of the same mesh and the median wall time; then a scaling run (time
// per step against elements, per linear solver). Writes two CSV files;
// bench/plot_work_precision.py turns them into PNG plots, and
// bench/work_precision.sh does all of it.
//
//   work_precision [--config bench/work_precision.json] [--out bench/results]
//                  [--source-dir DIR]
//
// Everything that varies is data: the configuration file names the scenes
// (a scene file or an inline scene), JSON patches merged into them
// (convert/json_merge.h), the integrator settings as solver-field patches,
// the linear solvers, the steps and tolerances and the reference settings.
// A variant whose merged scene the parser or the engine rejects (a field or
// enum value this build does not know yet, or a spatial scene before the
// spatial model) is written as `skipped` with the reason, so the same file
// runs before and after those land.
//
// Error [m]: the largest distance between a probe of the run and the same
// probe of the reference run at every common output frame
// (engine/output/probe_trajectory.h). Wall time [s]: RunScene, model build
// included, frames kept in memory; median of `repeats` runs. CPU time [s]
// (cpu_s_median): the process's CPU time over the same runs, median; on a
// shared machine it is the steadier of the two (other processes' load
// stretches wall time, not this process's CPU time). The reference
// is the first of the scene's `reference` patches that runs; its own error
// is estimated by rerunning it at twice its step (reference_self_error_m:
// for a first-order reference about its error, for a second-order one about
// three times it).

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/struct.pb.h>
#include <google/protobuf/util/json_util.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/match.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "convert/json_merge.h"
#include "convert/scene_file.h"
#include "convert/scene_from_proto.h"
#include "engine/output/probe_trajectory.h"
#include "engine/run/simulation.h"

namespace cablesim {
namespace {

using google::protobuf::Struct;
using google::protobuf::Value;
using Clock = std::chrono::steady_clock;

// ---- small helpers on the configuration (generic JSON) ---------------------

const Value* Get(const Struct& s, const std::string& key) {
  auto it = s.fields().find(key);
  return it == s.fields().end() ? nullptr : &it->second;
}

double Number(const Struct& s, const std::string& key, double fallback) {
  const Value* v = Get(s, key);
  return v && v->has_number_value() ? v->number_value() : fallback;
}

std::string String(const Struct& s, const std::string& key, const std::string& fallback = "") {
  const Value* v = Get(s, key);
  return v && v->kind_case() == Value::kStringValue ? v->string_value() : fallback;
}

std::vector<double> Numbers(const Struct& s, const std::string& key) {
  std::vector<double> out;
  if (const Value* v = Get(s, key); v && v->has_list_value())
    for (const Value& x : v->list_value().values())
      if (x.has_number_value()) out.push_back(x.number_value());
  return out;
}

std::vector<const Value*> List(const Struct& s, const std::string& key) {
  std::vector<const Value*> out;
  if (const Value* v = Get(s, key); v && v->has_list_value())
    for (const Value& x : v->list_value().values()) out.push_back(&x);
  return out;
}

std::string ToJson(const google::protobuf::Message& m) {
  std::string out;
  if (!google::protobuf::util::MessageToJsonString(m, &out).ok()) return "{}";
  return out;
}

// The shortest decimal form that reads back to the same double.
std::string Num(double x) {
  for (int digits = 6; digits < 17; ++digits) {
    std::string s = absl::StrFormat("%.*g", digits, x);
    if (std::strtod(s.c_str(), nullptr) == x) return s;
  }
  return absl::StrFormat("%.17g", x);
}

// A CSV field: quoted when it holds a comma, quote or newline.
std::string Csv(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  return absl::StrCat("\"", absl::StrReplaceAll(s, {{"\"", "\"\""}, {"\n", " "}}), "\"");
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// ---- running one variant ---------------------------------------------------

struct Outcome {
  std::string status;  // "ok", "failed" (numerically), "skipped" (rejected)
  std::string note;
  std::vector<double> walls;
  std::vector<double> cpus;  // process CPU time of each run [s]
  RunSummary summary;
  ProbeTrajectory trajectory;
};

// Wall-clock limit of one run [s] (configuration key max_run_seconds): a run
// past it is stopped and reported as failed, so one pathological variant
// cannot stall the report.
double g_max_run_seconds = 60;

// CPU time of this process so far [s] (all its threads).
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Merges `patches` into `scene_json` in order and runs it `repeats` times.
Outcome RunVariant(const std::string& scene_json, const std::vector<std::string>& patches,
                   int repeats) {
  Outcome out;
  std::string json = scene_json;
  for (const std::string& patch : patches) {
    absl::StatusOr<std::string> merged = MergeJson(json, patch);
    if (!merged.ok()) {
      out.status = "skipped";
      out.note = std::string(merged.status().message());
      return out;
    }
    json = *merged;
  }
  absl::StatusOr<v1::Scene> proto = ParseSceneJson(json);
  if (!proto.ok()) {
    out.status = "skipped";
    out.note = std::string(proto.status().message());
    return out;
  }
  absl::StatusOr<Scene> scene = SceneFromProto(*proto);
  if (!scene.ok()) {
    out.status = "skipped";
    out.note = std::string(scene.status().message());
    return out;
  }
  for (int r = 0; r < std::max(1, repeats); ++r) {
    ProbeTrajectory trajectory;
    const auto start = Clock::now();
    const double cpu_start = ProcessCpuSeconds();
    RunControl control;
    control.should_stop = [start] {
      return std::chrono::duration<double>(Clock::now() - start).count() > g_max_run_seconds;
    };
    absl::StatusOr<RunSummary> summary = RunScene(*scene, &trajectory, control);
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    const double cpu = ProcessCpuSeconds() - cpu_start;
    if (!summary.ok()) {
      out.status = "skipped";
      out.note = std::string(summary.status().message());
      return out;
    }
    out.summary = *summary;
    out.trajectory = std::move(trajectory);
    if (summary->status != "ok") {
      out.status = "failed";
      out.note = summary->status == "cancelled"
                     ? absl::StrFormat("stopped after max_run_seconds = %g s at t = %g s",
                                       g_max_run_seconds, summary->end_time_s)
                     : summary->error;
      return out;
    }
    out.walls.push_back(wall);
    out.cpus.push_back(cpu);
  }
  out.status = "ok";
  return out;
}

std::string SolverPatch(const std::string& fields) {
  return absl::StrCat(R"({"solver":{)", fields, "}}");
}

// ---- the report ------------------------------------------------------------

constexpr char kHeader[] =
    "scene,integrator,linear_solver,mode,step_s,tolerance,status,wall_s_median,wall_s_min,"
    "wall_s_max,repeats,steps,rejected_steps,newton_iterations,linear_iterations,"
    "max_probe_error_m,reference,reference_self_error_m,note,cpu_s_median";

struct Reference {
  std::string label;
  ProbeTrajectory trajectory;
  double self_error = NAN;
  bool ok = false;
};

class Report {
 public:
  Report(std::ostream* csv, std::filesystem::path source_dir)
      : csv_(csv), source_dir_(std::move(source_dir)) {}

  void RunOneScene(const Struct& config, const Struct& spec) {
    const std::string name = String(spec, "name", "scene");
    const int repeats = static_cast<int>(Number(spec, "repeats", Number(config, "repeats", 3)));
    std::string scene_json;
    if (const Value* inline_scene = Get(spec, "scene"); inline_scene && inline_scene->has_struct_value()) {
      scene_json = ToJson(inline_scene->struct_value());
    } else {
      const std::filesystem::path file = source_dir_ / String(spec, "file");
      std::ifstream in(file);
      if (!in) {
        Note(name, absl::StrCat("scene file ", file.string(), " is missing: scene skipped"));
        return;
      }
      std::stringstream ss;
      ss << in.rdbuf();
      scene_json = ss.str();
    }
    if (const Value* patch = Get(spec, "patch"); patch && patch->has_struct_value()) {
      absl::StatusOr<std::string> merged = MergeJson(scene_json, ToJson(patch->struct_value()));
      if (!merged.ok()) {
        Note(name, std::string(merged.status().message()));
        return;
      }
      scene_json = *merged;
    }

    // The reference: the first candidate that runs.
    Reference ref;
    for (const Value* candidate : List(spec, "reference")) {
      if (!candidate->has_struct_value()) continue;
      const std::string patch = ToJson(candidate->struct_value());
      std::cerr << name << ": reference " << patch << "\n";
      Outcome o = RunVariant(scene_json, {patch}, 1);
      if (o.status != "ok") {
        std::cerr << "  " << o.status << ": " << o.note << "\n";
        ref.label = patch;
        if (o.status == "skipped" && absl::StrContains(o.note, "spatial")) break;
        continue;
      }
      ref.ok = true;
      ref.label = patch;
      ref.trajectory = std::move(o.trajectory);
      // Its own error: the same settings at twice the step.
      const double h = ReferenceStep(candidate->struct_value(), scene_json);
      Outcome coarse = RunVariant(scene_json, {patch, SolverPatch(absl::StrCat(R"("step":)", Num(2 * h)))}, 1);
      if (coarse.status == "ok") {
        if (auto e = MaxProbePositionError(coarse.trajectory, ref.trajectory); e.ok())
          ref.self_error = *e;
      }
      std::cerr << "  ok: " << o.walls[0] << " s, self error " << ref.self_error << " m\n";
      break;
    }
    if (!ref.ok) {
      Note(name, absl::StrCat("no reference run succeeded (last tried: ", ref.label, ")"));
      return;
    }

    const std::vector<double> steps = Numbers(spec, "steps");
    const std::vector<double> tolerances = Numbers(spec, "tolerances");
    std::vector<std::string> solvers;
    for (const Value* v : List(config, "linear_solvers"))
      if (v->kind_case() == Value::kStringValue) solvers.push_back(v->string_value());
    for (const Value* integ : List(config, "integrators")) {
      if (!integ->has_struct_value()) continue;
      const Struct& is = integ->struct_value();
      const std::string label = String(is, "label", "?");
      const Value* solver_patch = Get(is, "patch");
      const std::string ipatch =
          solver_patch && solver_patch->has_struct_value() ? ToJson(solver_patch->struct_value()) : "{}";
      for (const std::string& ls : solvers) {
        const std::string lpatch = SolverPatch(absl::StrCat(R"("linear_solver":")", ls, "\""));
        // Fixed steps.
        for (double h : steps) {
          Outcome o = RunVariant(scene_json, {ipatch, lpatch, SolverPatch(absl::StrCat(R"("step":)", Num(h)))}, repeats);
          Row(name, label, ls, "fixed", h, NAN, o, ref);
          if (o.status == "skipped") break;  // the whole series is
        }
        // Adaptive: the largest step to start from, then the tolerance.
        for (double tol : tolerances) {
          const double h0 = steps.empty() ? 1e-3 : *std::max_element(steps.begin(), steps.end());
          Outcome o = RunVariant(
              scene_json,
              {ipatch, lpatch,
               SolverPatch(absl::StrCat(R"("step":)", Num(h0), R"(,"adaptive":true,"tolerance":)", Num(tol)))},
              repeats);
          Row(name, label, ls, "adaptive", h0, tol, o, ref);
          if (o.status == "skipped") break;
        }
      }
    }
  }

 private:
  // The reference patch's step, or the scene's.
  static double ReferenceStep(const Struct& patch, const std::string& scene_json) {
    if (const Value* s = Get(patch, "solver"); s && s->has_struct_value()) {
      const double h = Number(s->struct_value(), "step", NAN);
      if (std::isfinite(h)) return h;
    }
    absl::StatusOr<v1::Scene> proto = ParseSceneJson(scene_json);
    return proto.ok() && proto->solver().has_step() ? proto->solver().step() : 1e-3;
  }

  void Note(const std::string& scene, const std::string& note) {
    std::cerr << scene << ": " << note << "\n";
    *csv_ << Csv(scene) << ",,,,,,skipped,,,,,,,,,,,," << Csv(note) << ",\n";
  }

  void Row(const std::string& scene, const std::string& integrator, const std::string& ls,
           const std::string& mode, double h, double tol, const Outcome& o, const Reference& ref) {
    double error = NAN;
    std::string note = o.note;
    if (o.status == "ok") {
      absl::StatusOr<double> e = MaxProbePositionError(o.trajectory, ref.trajectory);
      if (e.ok()) {
        error = *e;
      } else {
        note = std::string(e.status().message());
      }
    }
    const auto [mn, mx] = o.walls.empty()
                              ? std::pair<double, double>(NAN, NAN)
                              : std::pair<double, double>(*std::min_element(o.walls.begin(), o.walls.end()),
                                                          *std::max_element(o.walls.begin(), o.walls.end()));
    const bool ran = o.status != "skipped";
    std::string line = absl::StrCat(
        Csv(scene), ",", Csv(integrator), ",", ls, ",", mode, ",", Num(h), ",",
        std::isfinite(tol) ? Num(tol) : "", ",", o.status, ",",
        o.walls.empty() ? "" : Num(Median(o.walls)), ",", o.walls.empty() ? "" : Num(mn), ",",
        o.walls.empty() ? "" : Num(mx), ",", o.walls.size(), ",", ran ? absl::StrCat(o.summary.steps) : "",
        ",", ran ? absl::StrCat(o.summary.rejected_steps) : "", ",",
        ran ? absl::StrCat(o.summary.newton_iterations) : "", ",",
        ran ? absl::StrCat(o.summary.linear_iterations) : "", ",",
        std::isfinite(error) ? Num(error) : "", ",", Csv(ref.label), ",",
        std::isfinite(ref.self_error) ? Num(ref.self_error) : "", ",", Csv(note), ",",
        o.cpus.empty() ? "" : Num(Median(o.cpus)));
    *csv_ << line << "\n";
    csv_->flush();
    std::cerr << absl::StrFormat("  %-16s %-28s %-7s %-8s h=%-8g tol=%-8g %-7s %9.4f s  err %.3g m %s\n",
                                 scene, integrator, ls, mode, h, tol, o.status,
                                 o.walls.empty() ? NAN : Median(o.walls), error,
                                 o.status == "ok" ? "" : note.substr(0, 90));
  }

  std::ostream* csv_;
  std::filesystem::path source_dir_;
};

// ---- scaling ---------------------------------------------------------------

constexpr char kScalingHeader[] =
    "linear_solver,elements,dofs,step_s,steps_short,steps_long,wall_short_s,wall_long_s,"
    "s_per_step,newton_per_step,linear_per_step,status,note";

void RunScaling(const Struct& config, const Struct& spec, std::ostream* csv) {
  const Value* scene_value = Get(spec, "scene");
  if (!scene_value || !scene_value->has_struct_value()) {
    std::cerr << "scaling: no inline scene\n";
    return;
  }
  const std::string scene_json = ToJson(scene_value->struct_value());
  const int repeats = static_cast<int>(Number(spec, "repeats", Number(config, "repeats", 3)));
  const double h = Number(spec, "step", 1e-4);
  const int n_short = static_cast<int>(Number(spec, "steps_short", 5));
  const int n_long = static_cast<int>(Number(spec, "steps_long", 25));
  std::vector<std::string> solvers;
  for (const Value* v : List(spec, "linear_solvers").empty() ? List(config, "linear_solvers")
                                                             : List(spec, "linear_solvers"))
    if (v->kind_case() == Value::kStringValue) solvers.push_back(v->string_value());
  for (const std::string& ls : solvers) {
    bool skip_rest = false;
    for (double elements : Numbers(spec, "elements")) {
      if (skip_rest) break;
      const int e = static_cast<int>(elements);
      auto run = [&](int steps) {
        const double duration = steps * h;
        return RunVariant(scene_json,
                          {absl::StrCat(R"({"cables":[{"elements":)", e, "}]}"),
                           SolverPatch(absl::StrCat(R"("linear_solver":")", ls, R"(","step":)", Num(h),
                                                    R"(,"duration":)", Num(duration),
                                                    R"(,"output_interval":)", Num(duration)))},
                          repeats);
      };
      Outcome a = run(n_short);
      Outcome b = a.status == "ok" ? run(n_long) : a;
      std::string status = b.status, note = b.note;
      double per_step = NAN, newton = NAN, linear = NAN;
      if (a.status == "ok" && b.status == "ok") {
        const double ds = static_cast<double>(b.summary.steps - a.summary.steps);
        per_step = (Median(b.walls) - Median(a.walls)) / ds;
        newton = (b.summary.newton_iterations - a.summary.newton_iterations) / ds;
        linear = (b.summary.linear_iterations - a.summary.linear_iterations) / ds;
      }
      *csv << ls << "," << e << "," << (status != "skipped" ? absl::StrCat(b.summary.info.dofs) : "")
           << "," << Num(h) << "," << n_short << "," << n_long << ","
           << (a.walls.empty() ? "" : Num(Median(a.walls))) << ","
           << (b.walls.empty() ? "" : Num(Median(b.walls))) << ","
           << (std::isfinite(per_step) ? Num(per_step) : "") << ","
           << (std::isfinite(newton) ? Num(newton) : "") << ","
           << (std::isfinite(linear) ? Num(linear) : "") << "," << status << "," << Csv(note) << "\n";
      csv->flush();
      std::cerr << absl::StrFormat("  scaling %-7s %6d elements: %s %.3g s/step %s\n", ls, e, status,
                                   per_step, note.substr(0, 90));
      if (status == "skipped") skip_rest = true;
    }
  }
}

int Main(int argc, char** argv) {
  std::string config_path = "bench/work_precision.json";
  std::string out_dir = "bench/results";
  std::string source_dir = ".";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "work_precision: " << arg << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--config") {
      config_path = value();
    } else if (arg == "--out") {
      out_dir = value();
    } else if (arg == "--source-dir") {
      source_dir = value();
    } else {
      std::cerr << "usage: work_precision [--config FILE] [--out DIR] [--source-dir DIR]\n";
      return 2;
    }
  }
  std::ifstream in(config_path);
  if (!in) {
    std::cerr << "work_precision: cannot read " << config_path << "\n";
    return 2;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  Struct config;
  if (auto st = google::protobuf::util::JsonStringToMessage(ss.str(), &config); !st.ok()) {
    std::cerr << "work_precision: " << config_path << ": " << st.message() << "\n";
    return 2;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  const std::filesystem::path csv_path = std::filesystem::path(out_dir) / "work_precision.csv";
  std::ofstream csv(csv_path);
  if (!csv) {
    std::cerr << "work_precision: cannot write " << csv_path << "\n";
    return 3;
  }
  g_max_run_seconds = Number(config, "max_run_seconds", g_max_run_seconds);
  csv << kHeader << "\n";
  Report report(&csv, source_dir);
  for (const Value* scene : List(config, "scenes"))
    if (scene->has_struct_value()) report.RunOneScene(config, scene->struct_value());
  if (const Value* scaling = Get(config, "scaling"); scaling && scaling->has_struct_value()) {
    const std::filesystem::path scaling_path = std::filesystem::path(out_dir) / "scaling.csv";
    std::ofstream scsv(scaling_path);
    if (!scsv) {
      std::cerr << "work_precision: cannot write " << scaling_path << "\n";
      return 3;
    }
    scsv << kScalingHeader << "\n";
    RunScaling(config, scaling->struct_value(), &scsv);
  }
  return 0;
}

}  // namespace
}  // namespace cablesim

int main(int argc, char** argv) { return cablesim::Main(argc, argv); }
