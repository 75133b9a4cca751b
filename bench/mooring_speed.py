#!/usr/bin/env python3
"""Mooring speed at equal accuracy (issue 34): real-time factors of whole `cablesim run` processes
on a mooring scene against its own converged reference, on the fairlead tension series.

    bench/mooring_speed.py CONFIG.json [--quick] [--build DIR] [--out DIR] [--docs DIR]

CONFIG (bench/mooring_speed_oc4.json, bench/mooring_speed_buoy.json) names the scene (and a
`scene_patch` deep-merged into it, and a `cable_patch` deep-merged into each of its cables), the probes whose support force (`"tension": "support"`, a
moving support's NAME.fx/.fy/.fz) or tension column (`"tension": "column"`, NAME.tension with
output.tension) is the fairlead tension, the reference ladder (mesh and step refined together;
the last rung is the reference, the change between the last two rungs its own error), the
candidate settings and AUTO's tolerances. A variant is {"elements": N (every cable), "solver":
{...} merged into the scene's solver}; the defaults' variant is {} (the scene as committed).

Error of a run (the metric, stated in every table): for each fairlead i, the tension T_i(t) is
the size of the support force (columns NAME.fx, .fy, .fz) or the tension column at every
output frame; the error is
    max over i of  max_t |T_i(t) - Tref_i(t)| / max_t |Tref_i(t)|
over every frame of the run (0 to duration, the ramp included).

Timing: the whole process `cablesim run SCENE --out F.csv` (start-up, parsing, statics, the run,
writing the CSV), wall clock, one run at a time. Every candidate is run once to screen it; the
cheapest within each accuracy class (and its runners-up within 1.3x), every AUTO run and the
defaults are run `repeats` times and their medians reported. Real-time factor (RTF) = simulated
seconds / median wall seconds; RTF (CPU) the same with the process's CPU seconds (user + system),
which other load on a shared machine inflates less, so the class winners are chosen by it.

Output: OUT/mooring_speed_NAME.csv (every run) and OUT/mooring_speed_NAME.md (the tables), copied
to DOCS (docs/bench-results by default). --quick runs the config's "quick" subset (its own
reference ladder, candidates and repeats) into files named ..._quick.
"""
import argparse
import copy
import csv
import json
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def merge(into, patch):
    """Deep merge of JSON objects: objects merged key by key, anything else replaced."""
    for k, v in patch.items():
        if isinstance(v, dict) and isinstance(into.get(k), dict):
            merge(into[k], v)
        else:
            into[k] = copy.deepcopy(v)
    return into


def variant_scene(base, variant):
    scene = copy.deepcopy(base)
    if "elements" in variant:
        for c in scene["cables"]:
            c["elements"] = int(variant["elements"])
    if "gauss_points" in variant:
        for c in scene["cables"]:
            c["gauss_points"] = int(variant["gauss_points"])
    scene.setdefault("solver", {}).update(variant.get("solver", {}))
    return scene


def label(variant):
    if not variant:
        return "defaults (the scene as committed)"
    parts = []
    if "elements" in variant:
        parts.append(f"{variant['elements']} el/line")
    if "gauss_points" in variant:
        parts.append(f"{variant['gauss_points']} Gauss points")
    for k, v in variant.get("solver", {}).items():
        parts.append(f"{k}={v}")
    return ", ".join(parts)


class Runner:
    def __init__(self, binary, base, probes, duration, tmp):
        self.binary, self.base, self.probes, self.duration, self.tmp = binary, base, probes, duration, tmp
        self.count = 0
        self.timeout = None
        self.tension = "support"

    def run(self, variant):
        """One whole process; returns (wall_s, tensions {probe: [T]}, summary dict) or raises."""
        self.count += 1
        path = os.path.join(self.tmp, f"v{self.count}.json")
        out = os.path.join(self.tmp, f"v{self.count}.csv")
        with open(path, "w") as f:
            json.dump(variant_scene(self.base, variant), f)
        start = time.perf_counter()
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        try:
            p = subprocess.run([self.binary, "run", path, "--out", out], capture_output=True, text=True,
                               timeout=self.timeout)
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"stopped after max_run_seconds = {self.timeout:g} s")
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        if p.returncode != 0:
            raise RuntimeError((p.stderr or p.stdout).strip().splitlines()[-1][:200])
        summary = json.loads(p.stdout.strip().splitlines()[-1]) if p.stdout.strip() else {}
        with open(out) as f:
            rows = list(csv.DictReader(f))
        if self.tension == "column":  # the line's tension at the probe (output.tension)
            tensions = {n: [float(r[n + ".tension"]) for r in rows] for n in self.probes}
        else:  # the size of the support force at a moving support's probe
            tensions = {n: [math.sqrt(float(r[n + ".fx"]) ** 2 + float(r[n + ".fy"]) ** 2 +
                                      float(r[n + ".fz"]) ** 2) for r in rows] for n in self.probes}
        times = [float(r["t"]) for r in rows]
        os.remove(out)
        return wall, (times, tensions), summary


def error(series, ref):
    (t, T), (tr, Tr) = series, ref
    if len(t) != len(tr) or any(abs(a - b) > 1e-9 for a, b in zip(t, tr)):
        return float("nan")
    worst = 0.0
    for name, ref_values in Tr.items():
        scale = max(abs(v) for v in ref_values)
        worst = max(worst, max(abs(a - b) for a, b in zip(T[name], ref_values)) / scale)
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("config")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results"))
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs", "bench-results"))
    ap.add_argument("--reference-cache", help="JSON file: the reference ladder's runs are read from it "
                    "when it exists and holds the same scene and ladder, else run and written to it")
    ap.add_argument("--reference-only", action="store_true", help="run the ladder (and cache it), stop")
    ap.add_argument("--write-scene", nargs=2, metavar=("VARIANT", "FILE"),
                    help="write the scene of one setting (a variant as JSON, e.g. "
                    "'{\"elements\": 50, \"solver\": {\"step\": 0.2}}'; '{}' for the defaults) to FILE "
                    "and stop: `cablesim run FILE` then times that setting alone")
    args = ap.parse_args()
    config = json.load(open(args.config))
    if args.quick:
        config = {**config, **config.get("quick", {})}
    name = config["name"] + ("_quick" if args.quick else "")
    base = merge(json.load(open(os.path.join(ROOT, config["scene"]))), config.get("scene_patch", {}))
    for cable in base["cables"]:  # lists are replaced by scene_patch, so cables get their own
        merge(cable, config.get("cable_patch", {}))
    if args.write_scene:
        try:
            variant = json.loads(args.write_scene[0])
        except json.JSONDecodeError as e:
            ap.error(f"--write-scene VARIANT: not JSON ({e})")
        if not isinstance(variant, dict):
            ap.error("--write-scene VARIANT: must be a JSON object, e.g. '{\"elements\": 50}'")
        with open(args.write_scene[1], "w") as f:
            json.dump(variant_scene(base, variant), f, indent=1)
        print(f"{args.write_scene[1]}: {label(variant)}", file=sys.stderr)
        return
    duration = float(base["solver"]["duration"])
    binary = os.path.join(args.build, "bin", "cablesim")
    repeats = int(config.get("repeats", 3))
    classes = config.get("classes", [0.02, 0.01, 0.002])
    tmp = tempfile.mkdtemp(prefix="mooring_speed_")
    load_start = os.getloadavg()
    runner = Runner(binary, base, config["probes"], duration, tmp)
    runner.timeout = config.get("max_run_seconds")
    runner.tension = config.get("tension", "support")
    log = lambda *a: print(*a, file=sys.stderr, flush=True)
    rows = []  # dicts: kind, label, variant, walls, error, summary, status

    def record(kind, variant, reps):
        r = {"kind": kind, "label": label(variant), "variant": variant, "walls": [], "error": float("nan"),
             "summary": {}, "status": "ok", "series": None}
        try:
            for _ in range(reps):
                wall, series, summary = runner.run(variant)
                r["walls"].append(wall)
                r.setdefault("cpus", []).append(runner.cpu)
                r["series"], r["summary"] = series, summary
                if summary.get("status", "ok") != "ok":
                    r["status"] = summary.get("status")
                    break
        except RuntimeError as e:
            r["status"], r["note"] = "failed", str(e)
        rows.append(r)
        return r

    # 1. The reference ladder.
    ladder = []
    key = {"scene": base, "ladder": config["reference_ladder"]}
    cache = args.reference_cache
    if cache and os.path.exists(cache):
        stored = json.load(open(cache))
        if stored["key"] == key:
            ladder = stored["ladder"]
            rows.extend(ladder)
            log(f"reference ladder read from {cache}")
    if not ladder:
        timeout, runner.timeout = runner.timeout, None  # the reference takes what it takes
        for v in config["reference_ladder"]:
            r = record("reference", v, 1)
            log(f"reference rung {r['label']}: {r['status']} {r['walls'][0] if r['walls'] else float('nan'):.1f} s")
            if r["status"] != "ok":
                sys.exit(f"mooring_speed: the reference rung {r['label']} failed: {r.get('note', r['status'])}")
            ladder.append(r)
        runner.timeout = timeout
        if cache:
            with open(cache, "w") as f:
                json.dump({"key": key, "ladder": ladder}, f)
    if args.reference_only:
        return
    ref = ladder[-1]["series"]
    for a, b in zip(ladder, ladder[1:]):
        a["change_to_next"] = error(a["series"], b["series"])
    for r in ladder:
        r["error"] = error(r["series"], ref)
    ref_self = ladder[-2]["change_to_next"] if len(ladder) > 1 else float("nan")
    log(f"reference: {ladder[-1]['label']}, last refinement changed the series by {ref_self:.3g}")

    def finish(r):
        if r["status"] == "ok":
            r["error"] = error(r["series"], ref)
        r["series"] = None
        w = statistics.median(r["walls"]) if r["walls"] else float("nan")
        log(f"  {r['kind']:<10} {r['label']:<70} {r['status']:<7} wall {w:8.3f} s  "
            f"cpu {statistics.median(r['cpus']) if r.get('cpus') else float('nan'):8.3f} s  "
            f"x{duration / w if w == w else float('nan'):8.1f}  err {r['error']:.4g}")
        return r

    # 2. Candidates, screened once.
    for v in config.get("candidates", []):
        finish(record("candidate", v, 1))
    # AUTO with a tolerance only, and the defaults.
    for v in config.get("auto", []):
        finish(record("auto", v, repeats))
    if int(config.get("defaults_repeats", repeats)) > 0:
        finish(record("defaults", {}, int(config["defaults_repeats"]) if "defaults_repeats" in config else repeats))

    # 3. The cheapest candidate in each class, rerun to `repeats` runs (and its runners-up within
    # 1.3x of its screening time, so a lucky screening run does not pick the winner).
    for c in classes:
        ok = [r for r in rows if r["kind"] == "candidate" and r["status"] == "ok" and r["error"] <= c]
        ok.sort(key=lambda r: r["cpus"][0])
        for r in ok[:4]:
            if r["cpus"][0] <= 1.3 * ok[0]["cpus"][0] and len(r["walls"]) < repeats:
                more = record("candidate", r["variant"], repeats - len(r["walls"]))
                r["walls"] += more["walls"]
                r["cpus"] += more.get("cpus", [])
                rows.remove(more)
                log(f"  rerun {r['label']}: median {statistics.median(r['walls']):.3f} s")

    # 4. Tables.
    def cpu_med(r):
        return statistics.median(r["cpus"]) if r.get("cpus") else float("nan")

    def rtf(r, key="walls"):
        return duration / statistics.median(r[key]) if r.get(key) else float("nan")

    load_end = os.getloadavg()
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, f"mooring_speed_{name}.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["kind", "setting", "variant", "status", "runs", "wall_s_median", "realtime_factor",
                    "cpu_s_median", "realtime_factor_cpu", "error", "steps", "newton_iterations", "integrator", "note"])
        for r in rows:
            med = statistics.median(r["walls"]) if r["walls"] else float("nan")
            s = r["summary"]
            w.writerow([r["kind"], r["label"], json.dumps(r["variant"]), r["status"], len(r["walls"]),
                        f"{med:.4g}", f"{duration / med:.4g}", f"{cpu_med(r):.4g}",
                        f"{duration / cpu_med(r):.4g}", f"{r['error']:.4g}", s.get("steps", ""),
                        s.get("newton_iterations", ""), s.get("integrator", ""),
                        r.get("note", f"change to the next rung {r['change_to_next']:.3g}"
                              if "change_to_next" in r else "")])

    md = [f"# Mooring speed: {config['name']}{' (quick)' if args.quick else ''}", "",
          config.get("_about", ""), "",
          f"Command: `bench/mooring_speed.py {os.path.relpath(args.config, ROOT)}"
          f"{' --quick' if args.quick else ''}`; {duration:g} s simulated; real-time factor = "
          f"simulated s / median wall s of {repeats} whole `cablesim run SCENE --out F.csv` processes "
          f"(screening runs: 1), one at a time; RTF (CPU) the same with the process's CPU seconds "
          f"(user + system), which other load on the machine inflates less: the class winners are "
          f"chosen by it. Load average (1 min) at the start {load_start[0]:.1f}, at the end "
          f"{load_end[0]:.1f}, on {os.cpu_count()} cores. Error: max over fairleads i of max_t |T_i - Tref_i| / "
          f"max_t |Tref_i|, T the fairlead tension ({'the size of the support force' if runner.tension == 'support' else 'column NAME.tension'}) at every output frame.", "",
          "## Reference ladder", "", "| setting | wall [s] | error against the reference | change to the next rung |",
          "| --- | --- | --- | --- |"]
    for r in ladder:
        md.append(f"| {r['label']} | {r['walls'][0]:.1f} | {r['error']:.3g} | "
                  f"{r.get('change_to_next', float('nan')):.3g} |")
    md += ["", "## Cheapest setting per accuracy class", "",
           "| class | cheapest setting | runs | RTF (wall) | RTF (CPU) | error | AUTO (tolerance only), best in class | its RTF (wall) | its RTF (CPU) | best / AUTO (CPU) |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for c in classes:
        ok = [r for r in rows if r["kind"] == "candidate" and r["status"] == "ok" and r["error"] <= c]
        au = [r for r in rows if r["kind"] == "auto" and r["status"] == "ok" and r["error"] <= c]
        best = max(ok, key=lambda r: rtf(r, "cpus")) if ok else None
        ab = max(au, key=lambda r: rtf(r, "cpus")) if au else None
        nan = float("nan")
        md.append(f"| {c:.3g} | {best['label'] if best else 'none'} | {len(best['walls']) if best else ''} | "
                  f"{rtf(best) if best else nan:.1f} | {rtf(best, 'cpus') if best else nan:.1f} | "
                  f"{best['error'] if best else nan:.3g} | {ab['label'] if ab else 'none'} | "
                  f"{rtf(ab) if ab else nan:.1f} | {rtf(ab, 'cpus') if ab else nan:.1f} | "
                  f"{rtf(best, 'cpus') / rtf(ab, 'cpus') if best and ab else nan:.2f} |")
    md += ["", "## AUTO with a tolerance only, and the defaults", "",
           "| setting | status | runs | RTF (wall) | RTF (CPU) | error | steps | Newton iterations |",
           "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        if r["kind"] in ("auto", "defaults"):
            ok = r["status"] == "ok"
            md.append(f"| {r['label']} | {r['status']} | {len(r['walls'])} | {rtf(r) if ok else float('nan'):.1f} | "
                      f"{rtf(r, 'cpus') if ok else float('nan'):.1f} | "
                      f"{r['error']:.3g} | {r['summary'].get('steps', '')} | {r['summary'].get('newton_iterations', '')} |")
    md += ["", "## Every candidate", "", "| setting | status | runs | RTF (wall) | RTF (CPU) | error | Newton iterations |",
           "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in sorted((r for r in rows if r["kind"] == "candidate"), key=lambda r: r["label"]):
        ok = r["status"] == "ok"
        md.append(f"| {r['label']} | {r['status']} | {len(r['walls'])} | {rtf(r) if ok else float('nan'):.1f} | "
                  f"{rtf(r, 'cpus') if ok else float('nan'):.1f} | "
                  f"{r['error']:.3g} | {r['summary'].get('newton_iterations', '')} |")
    md_path = os.path.join(args.out, f"mooring_speed_{name}.md")
    with open(md_path, "w") as f:
        f.write("\n".join(md) + "\n")
    if args.docs:
        os.makedirs(args.docs, exist_ok=True)
        for p in (csv_path, md_path):
            target = os.path.join(args.docs, os.path.basename(p))
            if not (os.path.exists(target) and os.path.samefile(p, target)):
                shutil.copy(p, target)
    shutil.rmtree(tmp, ignore_errors=True)
    log(f"wrote {csv_path} and {md_path}")


if __name__ == "__main__":
    main()
