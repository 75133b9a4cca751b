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


def run(tag, integrator, solver, step, reps=3):
    scene = json.loads(json.dumps(BASE))
    scene["solver"].update({"step": step, "output_interval": 1e-3, "integrator": integrator,
                            "linear_solver": solver})
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
for tag, integrator, solver, step in [("be", "IMPLICIT_EULER", "MINRES", 1e-4),
                                      ("em1", "ENERGY_MOMENTUM", "DIRECT", 1e-3),
                                      ("em05", "ENERGY_MOMENTUM", "DIRECT", 5e-4),
                                      ("ga", "GENERALIZED_ALPHA", "DIRECT", 6.25e-4)]:
    wall, rows = run(tag, integrator, solver, step)
    err = max(sum((float(a[c]) - float(b[c])) ** 2 for c in cols) ** 0.5 for a, b in zip(rows, ref))
    print(f"{integrator:18s} {solver:7s} h = {step:<8g} median {wall * 1e3:7.1f} ms  "
          f"largest frame tip error {err:.3g} m")
