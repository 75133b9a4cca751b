#!/usr/bin/env python3
"""cablesim against MoorDyn-C at equal accuracy on OC4's three mooring lines (issue 34).

    bench/moordyn/compare_oc4.py --moordyn-src DIR --moordyn-lib DIR --reference-cache FILE
                                 [--build build] [--repeats 7] [--out FILE.md]

The same lines, seabed, fluid and fairlead motion as bench/scenes/oc4-three-lines.json, written
as a MoorDyn v2 deck (write_deck below: the scene's mesh-independent Kelvin-Voigt time becomes
MoorDyn's BA = EA axial_time, so that both codes converge to one answer as their meshes are
refined), run by MoorDyn-C through oc4_driver.c, and cablesim's settings of
bench/mooring_speed_oc4.json. Both are measured against the converged reference that
bench/mooring_speed.py bench/mooring_speed_oc4.json --reference-cache FILE stores (run it first;
the ladder takes about 40 minutes), with its error metric: max over the fairleads of
max_t |T - Tref| / max_t |Tref| at every 0.1 s frame.

MoorDyn is not a dependency of cablesim: build it yourself (its CMake, e.g. with
-DPYTHON_WRAPPER=OFF) and pass its source/ directory (MoorDyn2.h) and the directory holding
libmoordyn.so. Every setting runs once for its error, then the cheapest of each code in each
class and both codes' defaults run `repeats` times, interleaved, and the medians of the
processes' CPU seconds (user + system) are reported.
"""
import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import mooring_speed as ms  # noqa: E402

ROOT = ms.ROOT
EA, AXIAL_TIME = 7.536e8, 0.0161986  # N; s (bench/scenes/oc4-three-lines.json)

# MoorDyn settings: (segments per line, dtM [s] or None for MoorDyn's CFL default, time scheme,
# coupling step [s]). The coupling step is a multiple of dtM (MoorDyn otherwise ends each
# coupling interval with a shorter step). Found by a sweep of 60 runs (28 November 2026): the
# largest stable dtM near each class boundary, RK2 (MoorDyn's default) and its local-Euler
# scheme LEuler, the cheapest of the schemes tried (Euler, RK2, RK4, LEuler, BEuler5).
MOORDYN = [
    (20, None, "RK2", 0.01),  # the deck's 20 segments, MoorDyn's defaults
    (20, 0.01, "RK2", 0.02),
    (26, 0.005, "RK2", 0.02),
    (26, 0.005, "LEuler", 0.02),
    (40, 0.002, "RK2", 0.01),
    (42, 0.00125, "RK2", 0.01),
    (42, 0.00125, "LEuler", 0.01),
    (44, 0.00125, "LEuler", 0.01),
    (80, 0.0005, "RK2", 0.01),
    # The 0.2 % class (29 November 2026, one run each): 80 segments LEuler at 0.0005 s 0.398 %,
    # 112 at 0.00025 s 0.226 %, 120 at 0.0002 s 0.194 % (49 s of CPU); 120 at 0.00025 s and
    # 160 at 0.0002 s stop with NaN.
    (112, 0.00025, "LEuler", 0.01),
    (120, 0.0002, "LEuler", 0.01),
]
# cablesim settings (bench/mooring_speed_oc4.json's variants); {} = the scene as committed.
CABLESIM = [
    {},
    {"elements": 8, "gauss_points": 3, "solver": {"integrator": "HHT", "step": 0.75, "reuse_factorization": False}},
    {"elements": 10, "gauss_points": 3, "solver": {"integrator": "HHT", "step": 0.5, "reuse_factorization": False}},
    {"elements": 28, "gauss_points": 3, "solver": {"integrator": "HHT", "step": 0.2, "reuse_factorization": False}},
]
CLASSES = [0.02, 0.01, 0.002]


def write_deck(path, segments, dtm, scheme):
    dtm_line = f"{dtm}    dtM\n" if dtm else ""
    with open(path, "w") as f:
        f.write(f"""--------------------- MoorDyn Input File ------------------------------------
OC4 three lines, fairleads coupled (cablesim bench/moordyn/compare_oc4.py)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca    CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)     (N-m^2) (-)  (-)   (-)     (-)
main       0.0766  113.35   {EA:.4e}  {EA * AXIAL_TIME:.6e}    0     2.0   0.8   0.4    0.25
---------------------- POINTS --------------------------------
ID  Attachment  X       Y     Z      M     V      CdA   CA
(-) (-)         (m)     (m)   (m)    (kg)  (m^3)  (m^2) (-)
1   Fixed      418.8    725.383 -200.0  0  0  0  0
2   Fixed     -837.6    0.0     -200.0  0  0  0  0
3   Fixed      418.8   -725.383 -200.0  0  0  0  0
4   Coupled    20.434   35.393  -14.0   0  0  0  0
5   Coupled   -40.868   0.0     -14.0   0  0  0  0
6   Coupled    20.434  -35.393  -14.0   0  0  0  0
---------------------- LINES --------------------------------------
ID   LineType  AttachA  AttachB  UnstrLen  NumSegs  Outputs
(-)  (-)       (-)      (-)      (m)       (-)      (-)
1    main      1        4        835.35    {segments}       -
2    main      2        5        835.35    {segments}       -
3    main      3        6        835.35    {segments}       -
---------------------- OPTIONS -----------------------------------------
{dtm_line}{scheme}   tScheme
3.0e6    kbot
3.0e5    cbot
200      WtrDpth
1025     WtrDnsty
9.80665  g
1        disableOutput
---------------------- OUTPUTS -----------------------------------------
------------------------- need this line --------------------------------------
""")


def timed(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return p, wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--moordyn-src", required=True, help="MoorDyn's source/ directory (MoorDyn2.h)")
    ap.add_argument("--moordyn-lib", required=True, help="the directory holding libmoordyn.so")
    ap.add_argument("--reference-cache", required=True, help="bench/mooring_speed.py's cache for the OC4 config")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--out", default=None, help="write the tables here (markdown) as well")
    args = ap.parse_args()

    config = json.load(open(os.path.join(ROOT, "bench", "mooring_speed_oc4.json")))
    base = json.load(open(os.path.join(ROOT, config["scene"])))
    stored = json.load(open(args.reference_cache))
    if stored["key"] != {"scene": base, "ladder": config["reference_ladder"]}:
        sys.exit("compare_oc4: the cache is not the OC4 config's reference ladder (rerun mooring_speed.py)")
    ref = stored["ladder"][-1]["series"]

    tmp = tempfile.mkdtemp(prefix="compare_oc4_")
    driver = os.path.join(tmp, "oc4_driver")
    subprocess.run(["cc", "-O2", "-o", driver, os.path.join(HERE, "oc4_driver.c"), "-I", args.moordyn_src,
                    "-L", args.moordyn_lib, "-lmoordyn", "-lm", f"-Wl,-rpath,{args.moordyn_lib}"], check=True)
    runner = ms.Runner(os.path.join(args.build, "bin", "cablesim"), base, config["probes"],
                       float(base["solver"]["duration"]), tmp)

    rows = []  # {code, label, run: () -> cpu seconds, error}

    def moordyn_row(seg, dtm, scheme, coupling):
        deck = os.path.join(tmp, f"md_{seg}_{dtm}_{scheme}.dat")
        write_deck(deck, seg, dtm, scheme)
        out = deck + ".csv"
        lab = (f"{seg} segments, {scheme}, " + (f"dtM {dtm} s" if dtm else "dtM from MoorDyn's CFL 0.5") +
               f", coupled every {coupling} s" + (" (MoorDyn's defaults)" if not dtm else ""))

        def run():
            p, wall, cpu = timed([driver, deck, out, str(coupling)])
            if p.returncode != 0:
                raise RuntimeError(f"MoorDyn failed (exit {p.returncode})")
            return cpu
        return {"code": "MoorDyn-C", "label": lab, "run": run, "out": out, "defaults": not dtm}

    def moordyn_series(out):
        with open(out) as f:
            r = list(csv.DictReader(f))
        return ([float(x["time"]) for x in r], {n: [float(x[f"{n}.tension"]) for x in r] for n in config["probes"]})

    for spec in MOORDYN:
        rows.append(moordyn_row(*spec))
    for v in CABLESIM:
        row = {"code": "cablesim", "label": ms.label(v), "defaults": not v}

        def run(v=v, row=row):
            _, row["series"], _ = runner.run(v)
            return runner.cpu
        row["run"] = run
        rows.append(row)

    for r in rows:  # errors, one run each
        try:
            r["cpus"] = [r["run"]()]
            series = moordyn_series(r["out"]) if r["code"] == "MoorDyn-C" else r["series"]
            r["error"] = ms.error(series, ref)
        except RuntimeError as e:
            r["error"], r["note"] = float("nan"), str(e)
        print(f"{r['code']:<10} {r['label']:<70} cpu {r['cpus'][0] if 'cpus' in r else float('nan'):8.3f} s  "
              f"err {r['error']:.4g}", flush=True)

    chosen = [r for r in rows if r["defaults"] and r["error"] == r["error"]]
    for c in CLASSES:
        for code in ("MoorDyn-C", "cablesim"):
            ok = [r for r in rows if r["code"] == code and r["error"] <= c]
            if ok:
                best = min(ok, key=lambda r: r["cpus"][0])
                best.setdefault("classes", []).append(c)
                if best not in chosen:
                    chosen.append(best)
    for _ in range(args.repeats - 1):  # interleaved
        for r in chosen:
            r["cpus"].append(r["run"]())
    duration = float(base["solver"]["duration"])
    md = ["| class | code | setting | error | CPU s (median of %d) | real-time factor (CPU) |" % args.repeats,
          "| --- | --- | --- | --- | --- | --- |"]
    for r in chosen:
        med = statistics.median(r["cpus"])
        cls = "defaults" if r["defaults"] else ", ".join(f"{c:.3g}" for c in r.get("classes", []))
        md.append(f"| {cls} | {r['code']} | {r['label']} | {100 * r['error']:.3g} % | {med:.3f} | {duration / med:.0f} |")
    md += ["", "Every setting, one run each:", "", "| code | setting | error | CPU s |", "| --- | --- | --- | --- |"]
    for r in rows:
        md.append(f"| {r['code']} | {r['label']} | {100 * r['error']:.3g} % | "
                  f"{r['cpus'][0] if 'cpus' in r else float('nan'):.3f} |")
    text = "\n".join(md) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
