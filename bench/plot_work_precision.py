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
import textwrap
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
    fig, ax = plt.subplots(figsize=(10, 5.5))
    # One colour per stepper, one marker per linear solver, solid lines for
    # fixed steps and dashed for adaptive ones.
    integrators = sorted({k[0] for k in series})
    solvers = sorted({k[1] for k in series})
    palette = plt.get_cmap("tab10").colors
    colour = {name: palette[i % len(palette)] for i, name in enumerate(integrators)}
    markers = dict(zip(solvers, "osD^vP*Xh<>p"))
    annotated_modes = set()
    for key, points in series.items():
        points.sort(key=lambda p: p[0])
        integrator, solver, mode = key
        style = "-" if mode == "fixed" else "--"
        ax.plot([p[0] for p in points], [p[1] for p in points], style, color=colour[integrator],
                marker=markers[solver], markersize=5, lw=1,
                label=f"{integrator} + {solver} ({mode})")
        if mode in annotated_modes:
            continue  # label the steps (tolerances) of one series per mode only
        annotated_modes.add(mode)
        for wall, err, r in points:
            tag = (f"h={number(r['step_s']):g}" if mode == "fixed"
                   else f"tol={number(r['tolerance']):g}")
            ax.annotate(tag, (wall, err), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ref_err = next((number(r["reference_self_error_m"]) for r in rows
                    if number(r["reference_self_error_m"]) > 0), math.nan)
    if ref_err > 0:
        ax.axhline(ref_err, color="grey", lw=0.8, ls=":",
                   label=f"reference's own error (vs twice its step): {ref_err:.2g} m")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median wall time of the run [s] (one thread)")
    ax.set_ylabel("max probe-position error vs reference [m]")
    ax.set_title(f"work precision: {scene}")
    skipped = sorted({f"{r['integrator']} + {r['linear_solver']} ({r['mode']})" for r in rows
                      if r["status"] == "skipped" and r["integrator"]})
    failed = [r for r in rows if r["status"] == "failed"]
    footnote = []
    if skipped:
        # Refused by the scene's validation (a setting that does not apply to
        # that stepper), wrapped so that it stays left of the legend.
        footnote += textwrap.wrap("refused (setting does not apply): " + ", ".join(skipped), 120)
    if failed:
        footnote.append(f"{len(failed)} runs failed (see work_precision.csv)")
    if footnote:
        fig.text(0.01, 0.005, "\n".join(footnote), fontsize=6, va="bottom", wrap=True)
    ax.grid(True, which="both", lw=0.3)
    # The legend outside the data, to the right.
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
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
    failed = [f"{r['linear_solver']} {r['elements']}: {r['status']}" for r in rows
              if r["status"] != "ok"]
    if failed:
        fig.text(0.01, 0.005, "not plotted: " + "; ".join(failed), fontsize=6, va="bottom",
                 wrap=True)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
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
        paper = [r for r in ok if r["integrator"].startswith("IMPLICIT_EULER")
                 and r["linear_solver"] == "MINRES" and r["mode"] == "fixed"
                 and abs(number(r["step_s"]) - 1e-4) < 1e-12]
        if paper:
            speedup = "no configuration reaches an error <= 1e-3 m"
            if 1e-3 in best:
                ratio = number(paper[0]["wall_s_median"]) / number(best[1e-3]["wall_s_median"])
                speedup = f"the fastest with error <= 1e-3 m is {ratio:.3g} x faster"
            lines.append(f"| {scene} | the paper's IMPLICIT_EULER + MINRES ({speedup}) | 0.0001 | "
                         f"{number(paper[0]['wall_s_median']):.4g} | "
                         f"{number(paper[0]['max_probe_error_m']):.3g} |")
        fastest = min(ok, key=lambda r: number(r["wall_s_median"]))
        most_accurate = min(ok, key=lambda r: number(r["max_probe_error_m"]))
        for what, r in (("fastest run", fastest), ("most accurate run", most_accurate)):
            setting = r["step_s"] if r["mode"] == "fixed" else r["tolerance"]
            lines.append(f"| {scene} | {what}: {r['integrator']} + {r['linear_solver']} "
                         f"({r['mode']}) | {number(setting):g} | "
                         f"{number(r['wall_s_median']):.4g} | {number(r['max_probe_error_m']):.3g} |")
        ref = next((number(r["reference_self_error_m"]) for r in ok
                    if number(r["reference_self_error_m"]) > 0), math.nan)
        lines.append(f"| {scene} | reference: {ok[0]['reference']} (its own error, against "
                     f"twice its step: {ref:.3g} m) | | | |")
        for limit, r in best.items():
            setting = r["step_s"] if r["mode"] == "fixed" else r["tolerance"]
            lines.append(f"| {scene} | fastest with error <= {limit:g} m: {r['integrator']} + "
                         f"{r['linear_solver']} ({r['mode']}) | {number(setting):g} | "
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
