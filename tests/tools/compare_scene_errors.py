#!/usr/bin/env python3
"""Feeds mutated sample scenes to two cablesim binaries' `validate` and
compares what they say: exit code, the JSON line and stderr, byte for byte.
For refactors of convert/ (the scene checks), which must keep every error
message and which field is reported first.

Usage:
  compare_scene_errors.py OLD_CABLESIM NEW_CABLESIM [--count N] [--seed S]
      [--pairs FRACTION] [SCENE ...]   (default scenes: scenes/*.json and
      scenes/paper/*.json)

Each case takes one sample scene and changes one leaf (or, for the
--pairs fraction, two leaves) to a value likely to be refused: negative,
zero, huge, tiny, "NaN", a wrong kind, an unknown name, or removes it.
Prints the count of cases, how many the old binary refused, and every case
whose outputs differ; exit 1 if any differ.
"""
import argparse
import copy
import glob
import json
import os
import random
import subprocess
import sys
import tempfile

NUMBER_VALUES = [-1, 0, 1e308, 1e-300, "NaN", -1e6, 2.5, 3]
STRING_VALUES = ["", "nosuch", "x" * 300, "EXACT", "PIN"]


def leaves(node, path=()):
    """Every (path, value) below `node`, containers included."""
    yield path, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from leaves(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from leaves(v, path + (i,))


def mutate(scene, rng):
    candidates = [(p, v) for p, v in leaves(scene) if p]
    path, value = rng.choice(candidates)
    parent = scene
    for key in path[:-1]:
        parent = parent[key]
    last = path[-1]
    if rng.random() < 0.15:
        if isinstance(parent, dict):
            del parent[last]
        else:
            parent.pop(last)
        return
    if isinstance(value, bool):
        parent[last] = not value
    elif isinstance(value, (int, float)):
        parent[last] = rng.choice(NUMBER_VALUES)
    elif isinstance(value, str):
        parent[last] = rng.choice(STRING_VALUES)
    elif isinstance(value, list) and value:
        parent[last] = value[:1] if rng.random() < 0.5 else value + value[-1:]
    elif isinstance(value, dict):
        parent[last] = {}


def validate(binary, path):
    p = subprocess.run([binary, "validate", path], capture_output=True, text=True)
    return p.returncode, p.stdout.replace(path, "SCENE"), p.stderr.replace(path, "SCENE")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--count", type=int, default=500)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--pairs", type=float, default=0.3)
    args = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    paths = args.scenes or sorted(glob.glob(os.path.join(root, "scenes", "*.json")) +
                                  glob.glob(os.path.join(root, "scenes", "paper", "*.json")))
    scenes = [(p, json.load(open(p))) for p in paths]
    rng = random.Random(args.seed)
    refused = differ = 0
    with tempfile.TemporaryDirectory() as tmp:
        case_path = os.path.join(tmp, "case.json")
        for n in range(args.count):
            name, base = rng.choice(scenes)
            scene = copy.deepcopy(base)
            for _ in range(2 if rng.random() < args.pairs else 1):
                mutate(scene, rng)
            with open(case_path, "w") as f:
                json.dump(scene, f)
            old = validate(args.old, case_path)
            new = validate(args.new, case_path)
            refused += old[0] != 0
            if old != new:
                differ += 1
                print(f"DIFFERENT case {n} ({os.path.basename(name)}):\n  old {old}\n  new {new}")
                with open(os.path.join(os.getcwd(), f"differ_case_{n}.json"), "w") as f:
                    json.dump(scene, f)
    print(f"{args.count} cases, {refused} refused by the old binary, {differ} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
