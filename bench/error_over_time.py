#!/usr/bin/env python3
"""When a run's error appears: the largest probe distance of each run's CSV
from a reference CSV (same frames), per time window, to tell an error that
builds up steadily from one that a phase of the motion grows
(docs/honest-runs.md, "Why the end cylinder's error is not local").

Usage:
  error_over_time.py REFERENCE.csv RUN.csv [RUN.csv ...] [--window 0.1]
      [--probe NAME]   (default: every probe with .x/.y/.z columns)

Prints per run its largest distance over the run, then one figure per
window (the largest distance within it).
"""

import argparse
import csv
import math


def load(path, probes):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no frames")
    names = probes or sorted(
        k[:-2] for k in rows[0] if k.endswith(".x") and not k.startswith(("energy", "cables", "bodies")))
    frames = []
    for r in rows:
        frames.append((float(r["t"]),
                       [tuple(float(r.get(f"{n}.{c}") or 0) for c in "xyz") for n in names]))
    return frames


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--window", type=float, default=0.1, help="window length [s]")
    ap.add_argument("--probe", action="append", default=[], help="probe name (repeatable)")
    args = ap.parse_args()
    ref = load(args.reference, args.probe)
    for path in args.runs:
        run = load(path, args.probe)
        if len(run) != len(ref) or any(abs(a[0] - b[0]) > 1e-9 for a, b in zip(run, ref)):
            raise SystemExit(f"{path}: frames differ from the reference's")
        windows = {}
        for (t, ps), (_, qs) in zip(run, ref):
            d = max(math.dist(p, q) for p, q in zip(ps, qs))
            k = int(t / args.window + 1e-9)
            windows[k] = max(windows.get(k, 0.0), d)
        print(f"{path}: largest {max(windows.values()):.3g} m")
        print("  " + " ".join(f"[{k * args.window:g}] {v:.2g}" for k, v in sorted(windows.items())))


if __name__ == "__main__":
    main()
