#!/usr/bin/env python3
"""Plots the work-precision report written by build/bin/work_precision.

    plot_work_precision.py RESULTS_DIR

Reads RESULTS_DIR/work_precision.csv and RESULTS_DIR/scaling.csv and writes
  RESULTS_DIR/work_precision_<scene>.png  error [m] against median wall time [s]
                                          per scene, one line per integrator x
                                          linear solver x fixed/adaptive
  RESULTS_DIR/scaling.png                 time per step [s] against elements,
                                          per linear solver, with a line of
                                          slope 1 (linear growth) for reference
  RESULTS_DIR/summary.md                  the figures the README quotes
Needs Debian's python3-matplotlib (deploy/install-deps.sh); no network.
"""

import csv
import math
import os
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return math.nan
    return value


def plot_scene(scene, rows, out_dir):
    series = OrderedDict()
    for r in rows:
        if r["status"] != "ok":
            continue
        err, wall = number(r["max_probe_error_m"]), number(r["wall_s_median"])
        if not (err > 0 and wall > 0):
            continue
        key = (r["integrator"], r["linear_solver"], r["mode"])
        series.setdefault(key, []).append((wall, err, r))
    if not series:
        return None
    fig, ax = plt.subplots(figsize=(8, 5.5))
    markers = "os^vD<>pP*Xh"
    for i, (key, points) in enumerate(series.items()):
        points.sort(key=lambda p: p[0])
        integrator, solver, mode = key
        style = "-" if mode == "fixed" else "--"
        ax.plot([p[0] for p in points], [p[1] for p in points], style,
                marker=markers[i % len(markers)], label=f"{integrator} + {solver} ({mode})")
        for wall, err, r in points:
            tag = r["step_s"] if mode == "fixed" else "tol " + r["tolerance"]
            ax.annotate(f"{float(tag.split()[-1]):g}" if mode == "fixed" else tag,
                        (wall, err), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ref_err = next((number(r["reference_self_error_m"]) for r in rows
                    if number(r["reference_self_error_m"]) > 0), math.nan)
    if ref_err > 0:
        ax.axhline(ref_err, color="grey", lw=0.8, ls=":",
                   label=f"reference's own error (vs twice its step): {ref_err:.2g} m")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median wall time of the run [s] (one thread)")
    ax.set_ylabel("max probe-position error vs reference [m]")
    ax.set_title(f"work precision: {scene} (labels: step [s] or tolerance)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = os.path.join(out_dir, f"work_precision_{scene}.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_scaling(rows, out_dir):
    series = OrderedDict()
    for r in rows:
        t = number(r["s_per_step"])
        if r["status"] == "ok" and t > 0:
            series.setdefault(r["linear_solver"], []).append((int(r["elements"]), t))
    if not series:
        return None
    fig, ax = plt.subplots(figsize=(7, 5))
    for solver, points in series.items():
        points.sort()
        ax.plot([p[0] for p in points], [p[1] for p in points], "-o", label=solver)
    first = next(iter(series.values()))
    e0, t0 = first[0]
    xs = [p[0] for p in first]
    ax.plot(xs, [t0 * x / e0 for x in xs], ":", color="grey", label="slope 1 (linear)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("elements")
    ax.set_ylabel("wall time per step [s]")
    ax.set_title("scaling: hanging cable, time per step (setup excluded)")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(out_dir, "scaling.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def summary(rows, scaling):
    """The figures the README quotes, as Markdown."""
    lines = ["| scene | configuration | step / tolerance | median wall [s] | error [m] |",
             "| --- | --- | --- | --- | --- |"]
    scenes = OrderedDict((r["scene"], None) for r in rows)
    for scene in scenes:
        ok = [r for r in rows if r["scene"] == scene and r["status"] == "ok"
              and number(r["max_probe_error_m"]) >= 0]
        if not ok:
            note = next((r["note"] for r in rows if r["scene"] == scene), "")
            lines.append(f"| {scene} | skipped: {note} | | | |")
            continue
        best = {}
        for limit in (1e-2, 1e-3, 1e-4):
            good = [r for r in ok if number(r["max_probe_error_m"]) <= limit]
            if good:
                best[limit] = min(good, key=lambda r: number(r["wall_s_median"]))
        for limit, r in best.items():
            setting = r["step_s"] if r["mode"] == "fixed" else "tol " + r["tolerance"]
            lines.append(f"| {scene} | fastest with error <= {limit:g} m: {r['integrator']} + "
                         f"{r['linear_solver']} ({r['mode']}) | {number(setting.split()[-1]):g} | "
                         f"{number(r['wall_s_median']):.4g} | {number(r['max_probe_error_m']):.3g} |")
    lines.append("")
    if scaling:
        lines.append("| linear solver | elements | dofs | time per step [s] | Newton / step |")
        lines.append("| --- | --- | --- | --- | --- |")
        for r in scaling:
            if r["status"] == "ok":
                lines.append(f"| {r['linear_solver']} | {r['elements']} | {r['dofs']} | "
                             f"{number(r['s_per_step']):.3g} | {number(r['newton_per_step']):.3g} |")
    return "\n".join(lines) + "\n"


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else "bench/results"
    rows = read_rows(os.path.join(out_dir, "work_precision.csv"))
    scaling = read_rows(os.path.join(out_dir, "scaling.csv"))
    written = []
    for scene in OrderedDict((r["scene"], None) for r in rows):
        path = plot_scene(scene, [r for r in rows if r["scene"] == scene], out_dir)
        if path:
            written.append(path)
    path = plot_scaling(scaling, out_dir)
    if path:
        written.append(path)
    with open(os.path.join(out_dir, "summary.md"), "w") as f:
        f.write(summary(rows, scaling))
    written.append(os.path.join(out_dir, "summary.md"))
    for p in written:
        print(p)


if __name__ == "__main__":
    main()
