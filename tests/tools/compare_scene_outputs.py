#!/usr/bin/env python3
"""Runs every sample scene with two cablesim binaries and compares what they
write: the CSV trajectory (every column, every row) and the summary's keys
(all but the wall times). A refactor must change no answer.

Usage:
  compare_scene_outputs.py OLD_CABLESIM NEW_CABLESIM [SCENE ...]
      (default scenes: scenes/*.json and scenes/paper/*.json)
  --rel 1e-12   relative tolerance for numbers whose printed digits differ
                (0: to the last printed digit)

Prints one line a scene: identical, within RTOL (the largest relative
difference), or DIFFERENT (the first column that differs); exit 1 if any
scene differs beyond the tolerance.
"""
import argparse
import csv
import glob
import json
import math
import os
import subprocess
import sys
import tempfile
import time

IGNORED_SUMMARY_KEYS = {"wall_seconds", "error_estimate_seconds", "cpu_seconds"}


def run(binary, scene, out):
    start = time.monotonic()
    p = subprocess.run([binary, "run", scene, "--out", out], capture_output=True, text=True)
    wall = time.monotonic() - start
    summary = None
    for line in p.stdout.splitlines():
        line = line.strip()
        if line.startswith("{"):
            try:
                summary = json.loads(line)
            except json.JSONDecodeError:
                pass
    return p.returncode, summary, p.stderr, wall


def rel_diff(a, b):
    try:
        x, y = float(a), float(b)
    except ValueError:
        return 0.0 if a == b else math.inf
    if x == y or (math.isnan(x) and math.isnan(y)):
        return 0.0
    return abs(x - y) / max(abs(x), abs(y), 1e-300)


def compare_values(a, b, where, worst, rtol):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in IGNORED_SUMMARY_KEYS:
                continue
            if k not in a or k not in b:
                return f"{where}{k}: only in {'new' if k in b else 'old'}"
            r = compare_values(a[k], b[k], f"{where}{k}.", worst, rtol)
            if r:
                return r
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return f"{where}: length {len(a)} vs {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            r = compare_values(x, y, f"{where}[{i}].", worst, rtol)
            if r:
                return r
        return None
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        d = rel_diff(a, b)
        worst[0] = max(worst[0], d)
        return None if d <= rtol else f"{where.rstrip('.')}: {a} vs {b}"
    return None if a == b else f"{where.rstrip('.')}: {a!r} vs {b!r}"


def compare_csv(old, new, worst, rtol):
    with open(old, newline="") as f:
        a = list(csv.reader(f))
    with open(new, newline="") as f:
        b = list(csv.reader(f))
    if not a or not b or a[0] != b[0]:
        return "CSV header differs"
    if len(a) != len(b):
        return f"CSV rows {len(a)} vs {len(b)}"
    for i, (ra, rb) in enumerate(zip(a[1:], b[1:]), start=1):
        for col, x, y in zip(a[0], ra, rb):
            if x == y:
                continue
            d = rel_diff(x, y)
            worst[0] = max(worst[0], d)
            if d > rtol:
                return f"CSV row {i} column {col}: {x} vs {y}"
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--rel", type=float, default=1e-12)
    ap.add_argument("--added", action="append", default=[], metavar="KEY",
                    help="a summary key the new binary adds (repeatable): compared only "
                         "for being absent from the old summary")
    args = ap.parse_args()
    scenes = args.scenes or sorted(glob.glob("scenes/*.json")) + sorted(
        glob.glob("scenes/paper/*.json"))
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            base = os.path.basename(scene)
            oa, ob = os.path.join(tmp, "old_" + base + ".csv"), os.path.join(tmp, "new_" + base + ".csv")
            rca, sa, ea, wa = run(args.old, scene, oa)
            rcb, sb, eb, wb = run(args.new, scene, ob)
            worst = [0.0]
            problem = None
            if rca != rcb:
                problem = f"exit {rca} vs {rcb}: {eb.strip()[:200]}"
            elif rca == 0:
                for key in args.added:
                    if key in sa:
                        problem = f"summary.{key}: not new (in the old summary too)"
                    sb.pop(key, None)
            if problem is None and rca == 0:
                problem = compare_values(sa, sb, "summary.", worst, args.rel) or compare_csv(
                    oa, ob, worst, args.rel)
            verdict = ("DIFFERENT: " + problem if problem else
                       "identical" if worst[0] == 0 else f"within {worst[0]:.1e}")
            if problem:
                failures += 1
            print(f"{scene}: {verdict} (wall {wa:.2f} s / {wb:.2f} s)", flush=True)
    print(f"{len(scenes)} scenes, {failures} different")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
