#!/usr/bin/env python3
"""Prints the ConfigMap and the Indexed Job that run a sweep without a server
(sweep-indexed-job.yaml), with the Job's completions derived from the sweep:
the product of its axes' value counts (service.proto, SweepFile), so no one
counts by hand. The ConfigMap holds the sweep file (as sweep.json) and its
base_file beside it.

    deploy/kubernetes/sweep-job.py sweeps/pendulum-resolution.json \\
        [--parallelism N] | kubectl apply -f -

Needs only Python 3's standard library."""
import argparse
import json
import math
import os
import re
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sweep", help="the sweep file (cablesim.v1.SweepFile JSON)")
    parser.add_argument("--parallelism", type=int, default=0,
                        help="pods at a time (default: every item at once, at most 100)")
    args = parser.parse_args()
    with open(args.sweep, encoding="utf-8") as f:
        text = f.read()
    sweep = json.loads(text)
    axes = sweep.get("axes", [])
    if not axes or any(not axis.get("values") for axis in axes):
        sys.exit(f"{args.sweep}: axes: need at least one axis, each with values")
    items = math.prod(len(axis["values"]) for axis in axes)
    files = {"sweep.json": text}
    if sweep.get("base_file"):
        base = os.path.join(os.path.dirname(args.sweep), sweep["base_file"])
        with open(base, encoding="utf-8") as f:
            files[os.path.basename(base)] = f.read()
        sweep["base_file"] = os.path.basename(base)
        files["sweep.json"] = json.dumps(sweep, indent=2) + "\n"
    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "sweep-indexed-job.yaml"), encoding="utf-8") as f:
        job = f.read()
    parallelism = args.parallelism or min(items, 100)
    job, n = re.subn(r"(?m)^  completions: \d+$", f"  completions: {items}", job)
    job, m = re.subn(r"(?m)^  parallelism: \d+$", f"  parallelism: {parallelism}", job)
    if n != 1 or m != 1:
        sys.exit("sweep-indexed-job.yaml: no single 'completions:' and 'parallelism:' line")
    out = sys.stdout
    out.write(f"# {items} items from {args.sweep}\n")
    out.write("apiVersion: v1\nkind: ConfigMap\nmetadata:\n  name: cablesim-sweep\n"
              "  labels:\n    app.kubernetes.io/name: cablesim\n"
              "    app.kubernetes.io/component: sweep\ndata:\n")
    for name, content in files.items():
        out.write(f"  {name}: |\n")
        for line in content.rstrip("\n").split("\n"):
            out.write(f"    {line}\n" if line else "\n")
    out.write("---\n")
    out.write(job)


if __name__ == "__main__":
    main()
