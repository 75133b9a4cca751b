#!/usr/bin/env python3
"""AUTO given only a tolerance against the fastest hand-tuned setting at the
same error, per scene, from a work-precision CSV (bench/work_precision.cc;
bench/work_precision_auto.json).

  python3 bench/auto_ratios.py OUT_DIR/work_precision.csv [--targets 1e-2,1e-3,1e-4]

For each scene and target error: the fastest run of any named stepper (fixed
or adaptive) or of AUTO at a fixed step (a step is a hand-tuned setting)
whose largest probe error is at most the target; the fastest run of AUTO
with adaptive steps (only a tolerance) that reaches it; their median wall
times and the ratio (AUTO over fastest). Then every setting where AUTO
failed but a named stepper succeeded (issue 32: "never fails where a named
stepper succeeds"). Prints Markdown.
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


def main():
    p = argparse.ArgumentParser()
    p.add_argument("csv")
    p.add_argument("--targets", default="1e-2,1e-3,1e-4")
    a = p.parse_args()
    targets = [float(x) for x in a.targets.split(",")]
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
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
            best = min(tuned, key=lambda r: number(r["wall_s_median"])) if tuned else None
            mine = min(auto, key=lambda r: number(r["wall_s_median"])) if auto else None
            ratio = (number(mine["wall_s_median"]) / number(best["wall_s_median"])
                     if best and mine else math.nan)
            if math.isfinite(ratio):
                worst = max(worst, ratio)
            print(f"| {scene} | {target:g} | "
                  f"{describe(best) + ' (' + format(number(best['max_probe_error_m']), '.3g') + ' m)' if best else 'none'} | "
                  f"{number(best['wall_s_median']) if best else math.nan:.4g} | "
                  f"{setting(mine) + ' (' + format(number(mine['max_probe_error_m']), '.3g') + ' m)' if mine else 'no tolerance reaches it'} | "
                  f"{number(mine['wall_s_median']) if mine else math.nan:.4g} | "
                  f"{ratio:.2f} |")
    print(f"\nLargest ratio: {worst:.2f}\n")
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
