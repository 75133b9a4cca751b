#!/usr/bin/env python3
"""cablesim's viscoelastic law against MoorDyn-C's on one polyester segment (issue 34).

    bench/moordyn/compare_visco.py --moordyn-src DIR --moordyn-lib DIR [--build build]

A 1 m segment of MoorDyn's test rope (tests/Mooring/polyester/visco.txt: static EA 1.424e8 N,
mean-load law alphaMBL 1.586e8 N and beta 0.4, BA 4e9 N s, BA_D 1.1e7 N s; and the same rope
with a constant dynamic EA_D of 1.586e8 N), fixed at one end and pulled at the other by
x(t) = 1 + a (1 - cos(2 pi t / 20 s)), a = 5 mm (0 to 1 % strain), for 60 s, no gravity, no
fluid: both ends move as given, so the tension is the law's alone. The deck is written here,
read by `cablesim import` (the reader under test too), given the motion, and run with HHT at
several steps; MoorDyn-C runs the deck through visco_driver.c at dtM = 1e-4 s (its explicit
scheme). Printed: the largest difference of the fairlead tension over the 0.5 s frames, and
cablesim's energy balance (energy_max_increase against energy_damped).

MoorDyn is not a dependency of cablesim: build it yourself (its CMake, e.g. with
-DPYTHON_WRAPPER=OFF) and pass its source/ directory (MoorDyn2.h) and the directory holding
libmoordyn.so.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
AMPLITUDE, PERIOD, DURATION = 0.005, 20.0, 60.0

DECK = """one viscoelastic segment (bench/moordyn/compare_visco.py)
---------------------- LINE TYPES ----------------------
TypeName  Diam    Mass/m  EA      BA/-zeta    EI   Cd  Ca  CdAx  CaAx
(name)    (m)     (kg/m)  (N)     (N-s/-)     (-)  (-) (-) (-)   (-)
rope      0.1438  22.42   {ea}    4e9|11e6    0    0   0   0     0
---------------------- POINTS ----------------------
ID  Attachment  X  Y  Z  Mass  Volume  CdA  Ca
(#) (-)         (m) (m) (m) (kg) (m^3) (m^2) (-)
1   Fixed       0  0  0  0     0       0    0
2   Coupled     1  0  0  0     0       0    0
---------------------- LINES ----------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#) (name)    (#)      (#)      (m)       (-)      (-)
1   rope      1        2        1.0       1        -
---------------------- OPTIONS ----------------------
0       writeLog
0.0001  dtM
0       TmaxIC
0       g
200     WtrDpth
0       WtrDnsty
--------------------- need this line ----------------------
"""
LAWS = {"mean-load": "1.424e8|1.586e8|0.4", "constant": "1.424e8|1.586e8"}


def series(path, column):
    with open(path) as f:
        return {round(float(r["t"]), 6): float(r[column]) for r in csv.DictReader(f)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--moordyn-src", required=True, help="MoorDyn's source/ directory (MoorDyn2.h)")
    ap.add_argument("--moordyn-lib", required=True, help="the directory holding libmoordyn.so")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--steps", default="0.01,0.05,0.2", help="cablesim's steps [s], comma-separated")
    args = ap.parse_args()
    cablesim = os.path.join(args.build, "bin", "cablesim")
    with tempfile.TemporaryDirectory() as tmp:
        driver = os.path.join(tmp, "visco_driver")
        subprocess.run(["cc", "-O2", "-o", driver, os.path.join(HERE, "visco_driver.c"), "-I",
                        args.moordyn_src, "-L", args.moordyn_lib, "-lmoordyn", "-lm"], check=True)
        env = dict(os.environ, LD_LIBRARY_PATH=args.moordyn_lib)
        print("| law | cablesim step [s] | largest difference [N] | of the peak tension | "
              "energy_max_increase / energy_damped |")
        print("|---|---|---|---|---|")
        for law, ea in LAWS.items():
            deck = os.path.join(tmp, f"{law}.txt")
            with open(deck, "w") as f:
                f.write(DECK.format(ea=ea))
            md_csv = os.path.join(tmp, f"{law}-moordyn.csv")
            dt = 1e-4
            subprocess.run([driver, deck, md_csv, str(AMPLITUDE), str(PERIOD), str(dt),
                            str(round(DURATION / dt)), str(round(0.5 / dt))],
                           check=True, env=env, stdout=subprocess.DEVNULL)
            md = series(md_csv, "tension")
            peak = max(abs(v) for v in md.values())
            scene_path = os.path.join(tmp, f"{law}.json")
            subprocess.run([cablesim, "import", deck, "--out", scene_path], check=True,
                           stdout=subprocess.DEVNULL)
            scene = json.load(open(scene_path))
            fairlead = scene["joints"][1]
            fairlead.pop("coupled", None)
            fairlead["motion"] = {"x": {"constant": AMPLITUDE,
                                        "harmonic": {"amplitude": -AMPLITUDE, "frequency": 1 / PERIOD,
                                                     "phase": math.pi / 2}}}
            scene["probes"] = [{"name": "fairlead", "cable": "line1", "s": 1}]
            scene["output"] = {"tension": True}
            for h in [float(x) for x in args.steps.split(",")]:
                scene["solver"] = {"analysis": "DYNAMIC", "integrator": "HHT", "step": h,
                                   "duration": DURATION, "output_interval": 0.5}
                run_path, out = os.path.join(tmp, "run.json"), os.path.join(tmp, "run.csv")
                json.dump(scene, open(run_path, "w"))
                p = subprocess.run([cablesim, "run", run_path, "--out", out], capture_output=True,
                                   text=True)
                summary = json.loads(p.stdout)
                if p.returncode != 0:
                    print(f"{law} h = {h}: cablesim exited {p.returncode}: {summary.get('error')}")
                    return 1
                ours = series(out, "fairlead.tension")
                diff = max(abs(ours[t] - v) for t, v in md.items() if t in ours)
                balance = summary["energy_max_increase"] / summary["energy_damped"]
                print(f"| {law} | {h:g} | {diff:.4g} | {100 * diff / peak:.3g} % of {peak:.4g} N | "
                      f"{balance:.2g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
