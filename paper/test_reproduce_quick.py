#!/usr/bin/python3
"""CTest paper_reproduce_quick_slow_test: runs `paper/reproduce.py --quick` on
every scene of scenes/paper/ and checks that the figures and the report exist
and that a few numbers agree with closed forms or with each other.

Environment: CABLESIM_SOURCE_DIR, CABLESIM_BIN_DIR (set by CTest).
"""

import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

SRC = os.environ.get("CABLESIM_SOURCE_DIR", os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("CABLESIM_BIN_DIR", os.path.join(SRC, "build", "bin"))

failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def column(path, name):
    """(values of column `name`, values of column t) of a run's CSV."""
    with open(path) as f:
        rows = list(csv.reader(f))
    i = rows[0].index(name)
    return [float(r[i]) for r in rows[1:]], [float(r[0]) for r in rows[1:]]


def main():
    out = tempfile.mkdtemp(prefix="paper-quick-")
    p = subprocess.run([sys.executable, os.path.join(SRC, "paper", "reproduce.py"), "--quick",
                        "--cli", os.path.join(BIN, "cablesim"), "--out", out])
    check(p.returncode == 0, "reproduce.py --quick exits 0 (every run ok)")
    for fig in ("fig05", "fig06", "fig08", "fig10", "fig12", "fig13", "fig15"):
        path = os.path.join(out, fig + ".png")
        check(os.path.exists(path) and os.path.getsize(path) > 5000, fig + ".png written")
    report = open(os.path.join(out, "report.md")).read() if os.path.exists(
        os.path.join(out, "report.md")) else ""
    for heading in ("Figure 5", "Figure 6", "Figure 8", "Figure 10", "Figure 12", "Figure 13",
                    "Figure 15"):
        check("## " + heading in report, "report has a section on " + heading)
    numbers = json.load(open(os.path.join(out, "numbers.json")))
    runs = os.path.join(out, "runs")

    # Closed form: before the pin's influence reaches it, the tip of the
    # falling pendulum falls freely, y = -g t^2 / 2. At t = 0.03 s the
    # bending wave has not reached the tip of this soft beam; 1 % allows the
    # backward-Euler error of h = 1e-4 s (O(h/t) ~ 0.3 %).
    for case, g in (("fig8-12-g9.81", 9.81), ("fig8-12-g50", 50.0)):
        y, t = column(os.path.join(runs, case + ".csv"), "tip.y")
        i = min(range(len(t)), key=lambda k: abs(t[k] - 0.03))
        exact = -g * t[i] ** 2 / 2
        check(abs(y[i] - exact) <= 0.01 * abs(exact),
              "%s: tip y(%.3f) = %.6g m, free fall %.6g m" % (case, t[i], y[i], exact))

    # Backward Euler never adds energy to a conservative scene: its largest
    # rise must stay at the rounding and Newton-tolerance level (1e-9 of
    # the initial energy scale, 1e-6 J floor).
    for key, s in numbers.items():
        if s.get("integrator") == "IMPLICIT_EULER":
            scale = max(abs(s.get("energy_initial", 0)), 1e-3)
            check(s.get("energy_max_increase", 1) <= 1e-6 + 1e-9 * scale,
                  "%s: energy never rises (largest rise %.3g J)" % (key, s.get("energy_max_increase", 1)))

    # MINRES and GMRES with the block preconditioner solve to 1e-10: the
    # same motion to 1e-6 m/s^2 (Newton tolerance 1e-8 times accelerations
    # of order 10 m/s^2 would allow 1e-7; 1e-6 for margin).
    a1, _ = column(os.path.join(runs, "fig5-minres-block.csv"), "tip.ay")
    a2, _ = column(os.path.join(runs, "fig5-gmres-block.csv"), "tip.ay")
    d = max(abs(x - y) for x, y in zip(a1, a2))
    check(d <= 1e-6, "MINRES and GMRES (BLOCK) give the same acceleration (max diff %.3g)" % d)

    # Equal total mass: every cylinder model carries 0.2 m of cylinder of
    # diameter 0.04 m and density 1000: m = 1000 pi 0.02^2 0.2 = 0.2513 kg.
    for k in ("2", "3", "5"):
        scene = json.load(open(os.path.join(SRC, "scenes", "paper", "cylinders-%s.json" % k)))
        h = sum(b["cylinder"]["height"] for b in scene["bodies"])
        check(len(scene["bodies"]) == int(k) and abs(h - 0.2) < 1e-12,
              "cylinders-%s: %d cylinders, total height %.3f m" % (k, len(scene["bodies"]), h))
    if failures:
        print("%d checks failed; the outputs are in %s" % (len(failures), out))
        return 1
    shutil.rmtree(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
