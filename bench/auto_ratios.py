#!/usr/bin/env python3
"""AUTO given only a tolerance against the fastest hand-tuned setting at the
same error, per scene, from a work-precision CSV (bench/work_precision.cc;
bench/work_precision_auto.json).

  python3 bench/auto_ratios.py OUT_DIR/work_precision.csv [--targets 1e-2,1e-3,1e-4]

For each scene and target error: the fastest run of any named stepper (fixed
or adaptive) or of AUTO at a fixed step (a step is a hand-tuned setting)
whose largest probe error is at most the target; the fastest run of AUTO
with adaptive steps (only a tolerance) that reaches it; their median times
and the ratio (AUTO over fastest). Times are the median process CPU time
(cpu_s_median) where the CSV has it, else wall time (--time wall chooses
wall time): on a shared machine other processes stretch wall time unevenly
across the rows of one run, CPU time much less. Then every setting where AUTO
failed but a named stepper succeeded (issue 32: "never fails where a named
stepper succeeds"). Prints Markdown.

A second table compares the curves at equal error: each setting's series
(a stepper's fixed steps, or its tolerances) is a work-precision curve; its
time at the target error is interpolated log-log between the two runs of
the series whose errors bracket the target (a run at or below the target
counts as itself; nothing is extrapolated). The fastest hand-tuned curve at
the target against AUTO's. The first table is what a user picking from the
grid gets; the second removes the grid's coarseness from the ratio, for
both sides alike.
"""
import argparse
import csv
import math
from collections import OrderedDict

AUTO = "AUTO_STEPPER"


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def setting(r):
    if r["mode"] == "fixed":
        return f"h = {number(r['step_s']):g}"
    return f"tol {number(r['tolerance']):g}"


def describe(r):
    return f"{r['integrator']} {r['mode']} {setting(r)}"


def time_at(series, target, key):
    """A series' time at `target` error [s], interpolated log-log between
    neighbours in the series' order whose errors bracket it; None if no
    run of the series reaches the target."""
    best = None
    pts = [(number(r["max_probe_error_m"]), number(r[key])) for r in series]
    pts = [(e, t) for e, t in pts if e > 0 and t > 0]
    for e, t in pts:
        if e <= target:
            best = t if best is None else min(best, t)
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if (e0 - target) * (e1 - target) < 0:
            w = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            t = math.exp(math.log(t0) + w * (math.log(t1) - math.log(t0)))
            best = t if best is None else min(best, t)
    return best


def series_of(rows, scene):
    """The runs of a scene grouped by setting (stepper and mode), each in
    the order of its step or tolerance, longest step / loosest first."""
    groups = OrderedDict()
    for r in rows:
        if r["scene"] != scene or r["status"] != "ok" or not number(r["max_probe_error_m"]) >= 0:
            continue
        groups.setdefault((r["integrator"], r["linear_solver"], r["mode"]), []).append(r)
    for k, g in groups.items():
        g.sort(key=lambda r: -number(r["step_s"] if r["mode"] == "fixed" else r["tolerance"]))
    return groups


def print_interpolated(rows, scenes, targets, key):
    print("At equal error, interpolated along each setting's series:\n")
    print("| Scene | Target [m] | Fastest hand-tuned curve | Its time [s] | AUTO's time [s] | Ratio |")
    print("| --- | --- | --- | --- | --- | --- |")
    worst = 0.0
    for scene in scenes:
        groups = series_of(rows, scene)
        for target in targets:
            tuned = []
            mine = None
            for (integ, ls, mode), g in groups.items():
                t = time_at(g, target, key)
                if t is None:
                    continue
                if integ == AUTO and mode == "adaptive":
                    mine = t
                else:
                    tuned.append((t, f"{integ} {mode}"))
            if not tuned and mine is None:
                continue
            best = min(tuned) if tuned else None
            ratio = mine / best[0] if best and mine else math.nan
            if math.isfinite(ratio):
                worst = max(worst, ratio)
            print(f"| {scene} | {target:g} | {best[1] if best else 'none'} | "
                  f"{best[0] if best else math.nan:.4g} | "
                  f"{mine if mine else math.nan:.4g} | {ratio:.2f} |")
    print(f"\nLargest interpolated ratio: {worst:.2f}\n")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("csv")
    p.add_argument("--targets", default="1e-2,1e-3,1e-4")
    p.add_argument("--time", choices=("cpu", "wall"), default="cpu")
    a = p.parse_args()
    targets = [float(x) for x in a.targets.split(",")]
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    key = "cpu_s_median" if a.time == "cpu" and rows and "cpu_s_median" in rows[0] else "wall_s_median"
    print(f"Times: {'median process CPU time' if key == 'cpu_s_median' else 'median wall time'} "
          f"({key}).\n")
    scenes = OrderedDict((r["scene"], None) for r in rows if r["integrator"])
    print("| Scene | Target [m] | Fastest hand-tuned | Its time [s] | AUTO (tolerance only) "
          "| AUTO's time [s] | Ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    worst = 0.0
    for scene in scenes:
        ok = [r for r in rows if r["scene"] == scene and r["status"] == "ok"
              and number(r["max_probe_error_m"]) >= 0]
        for target in targets:
            good = [r for r in ok if number(r["max_probe_error_m"]) <= target]
            tuned = [r for r in good if not (r["integrator"] == AUTO and r["mode"] == "adaptive")]
            auto = [r for r in good if r["integrator"] == AUTO and r["mode"] == "adaptive"]
            if not tuned and not auto:
                continue
            best = min(tuned, key=lambda r: number(r[key])) if tuned else None
            mine = min(auto, key=lambda r: number(r[key])) if auto else None
            ratio = (number(mine[key]) / number(best[key])
                     if best and mine else math.nan)
            if math.isfinite(ratio):
                worst = max(worst, ratio)
            print(f"| {scene} | {target:g} | "
                  f"{describe(best) + ' (' + format(number(best['max_probe_error_m']), '.3g') + ' m)' if best else 'none'} | "
                  f"{number(best[key]) if best else math.nan:.4g} | "
                  f"{setting(mine) + ' (' + format(number(mine['max_probe_error_m']), '.3g') + ' m)' if mine else 'no tolerance reaches it'} | "
                  f"{number(mine[key]) if mine else math.nan:.4g} | "
                  f"{ratio:.2f} |")
    print(f"\nLargest ratio: {worst:.2f}\n")
    print_interpolated(rows, scenes, targets, key)
    # AUTO's failures where a named stepper succeeded at the same setting.
    failures = []
    for scene in scenes:
        mine = [r for r in rows if r["scene"] == scene and r["integrator"] == AUTO
                and r["status"] not in ("ok", "skipped")]
        for r in mine:
            named_ok = [o["integrator"] for o in rows
                        if o["scene"] == scene and o["integrator"] != AUTO and o["status"] == "ok"
                        and o["mode"] == r["mode"] and o["step_s"] == r["step_s"]
                        and o["tolerance"] == r["tolerance"]]
            if named_ok:
                failures.append(f"- {scene}, AUTO {r['mode']} {setting(r)}: {r['status']} "
                                f"({r['note']}); succeeded: {', '.join(named_ok)}")
    print("AUTO failed where a named stepper succeeded:" if failures
          else "AUTO failed nowhere a named stepper succeeded.")
    for line in failures:
        print(line)


if __name__ == "__main__":
    main()
