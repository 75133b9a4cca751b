#!/usr/bin/env python3
"""Falling pendulum (scenes/falling-pendulum.json, 12 elements, 1 s), frames every 1 ms: the
largest tip error over every frame against ENERGY_MOMENTUM at h = 3.125e-5 (the same mesh), and the
median wall time of 3 runs, for a few settings. Usage: bench/frame_error_speed.py [BUILD_DIR]."""
import csv
import json
import statistics
import subprocess
import sys

ROOT = sys.path[0] + "/.."
BIN = (sys.argv[1] if len(sys.argv) > 1 else ROOT + "/build") + "/bin/cablesim"
BASE = json.load(open(ROOT + "/scenes/falling-pendulum.json"))


REPS = 5


def run(tag, integrator, solver, step, reps=REPS, extra=None):
    scene = json.loads(json.dumps(BASE))
    scene["solver"].update({"output_interval": 1e-3, "integrator": integrator,
                            "linear_solver": solver})
    if step is None:
        del scene["solver"]["step"]  # adaptive: the user gives a tolerance only
    else:
        scene["solver"]["step"] = step
    scene["solver"].update(extra or {})
    path = f"/tmp/frame_error_speed_{tag}"
    json.dump(scene, open(path + ".json", "w"))
    walls = []
    for _ in range(reps):
        out = subprocess.run([BIN, "run", path + ".json", "--out", path + ".csv"],
                             capture_output=True, text=True, check=True).stdout
        walls.append(json.loads(out[out.index("{"):])["wall_seconds"])
    return statistics.median(walls), list(csv.DictReader(open(path + ".csv")))


_, ref = run("ref", "ENERGY_MOMENTUM", "DIRECT", 3.125e-5, 1)
cols = ["tip.x", "tip.y"]
# The last rows loosen Newton's tolerance (default 1e-8): at 1e-3 m the error is the step's.
GA = {"rho_infinity": 0.8}
for tag, integrator, solver, step, extra in [
        ("be", "IMPLICIT_EULER", "MINRES", 1e-4, {}),
        ("em1", "ENERGY_MOMENTUM", "DIRECT", 1e-3, {}),
        ("em05", "ENERGY_MOMENTUM", "DIRECT", 5e-4, {}),
        ("ga", "GENERALIZED_ALPHA", "DIRECT", 6.25e-4, {}),
        ("ga5", "GENERALIZED_ALPHA", "DIRECT", 5e-4, GA),
        ("ga5n6", "GENERALIZED_ALPHA", "DIRECT", 5e-4, dict(GA, newton_tolerance=1e-6)),
        ("ga5n5", "GENERALIZED_ALPHA", "DIRECT", 5e-4, dict(GA, newton_tolerance=1e-5)),
        ("ga4n5", "GENERALIZED_ALPHA", "DIRECT", 4e-4, dict(GA, newton_tolerance=1e-5)),
        # Explicit steppers (no Newton; undamped modes stable while h omega_max < 2 and <= 1).
        ("cd8", "CENTRAL_DIFFERENCE", "AUTO", 8e-4, {}),
        ("cd7", "CENTRAL_DIFFERENCE", "AUTO", 7e-4, {}),
        ("cd5", "CENTRAL_DIFFERENCE", "AUTO", 5e-4, {}),
        ("dp15", "DORMAND_PRINCE", "AUTO", 1.5e-3, {}),
        ("dp1", "DORMAND_PRINCE", "AUTO", 1e-3, {}),
        # A user who asks only for accuracy: adaptive, a tolerance, no step.
        ("hhtad", "HHT", "AUTO", None, {"adaptive": True, "tolerance": 3e-5}),
        ("cdad", "CENTRAL_DIFFERENCE", "AUTO", None, {"adaptive": True, "tolerance": 1e-4}),
        ("cdad3", "CENTRAL_DIFFERENCE", "AUTO", None, {"adaptive": True, "tolerance": 3e-4}),
        ("dpad", "DORMAND_PRINCE", "AUTO", None, {"adaptive": True, "tolerance": 1e-4}),
        ("dpad5", "DORMAND_PRINCE", "AUTO", None, {"adaptive": True, "tolerance": 1e-5})]:
    wall, rows = run(tag, integrator, solver, step, extra=extra)
    err = max(sum((float(a[c]) - float(b[c])) ** 2 for c in cols) ** 0.5 for a, b in zip(rows, ref))
    hs = "adaptive" if step is None else f"{step:g}"
    print(f"{integrator:18s} {solver:7s} h = {hs:<8s} {json.dumps(extra):45s} median "
          f"{wall * 1e3:7.1f} ms  largest frame tip error {err:.3g} m")
