#!/usr/bin/env python3
"""Times whole cablesim processes: start-up included, median of many runs.

  python3 bench/startup_bench.py [--runs N] BINARY [BINARY ...]

For each binary (side by side, interleaved so that a change in the
machine's load hits all of them alike) it times
  --version                       start-up and exit, nothing else
  run one-step.json               the falling pendulum (scenes/) cut to one
                                  step of 1e-4 s: start-up, scene parsing,
                                  the in-process service, one step, summary
and prints, per command and binary, the median wall time and the median CPU
time (user + system, from wait4's rusage) of the process. On a shared or
loaded machine the wall time includes waiting for a core; the CPU time is
the work the process did, and is the figure to compare there.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def one_step_scene(directory):
    scene = json.loads((ROOT / "scenes" / "falling-pendulum.json").read_text())
    step = scene["solver"]["step"]
    scene["solver"]["duration"] = step
    scene["solver"]["output_interval"] = step
    path = pathlib.Path(directory) / "one-step.json"
    path.write_text(json.dumps(scene))
    return path


def time_once(argv):
    """(wall seconds, cpu seconds) of one process; raises if it fails."""
    start = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, argv))} exited {proc.returncode}")
    return wall, usage.ru_utime + usage.ru_stime


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("binaries", nargs="+")
    parser.add_argument("--runs", type=int, default=100)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scene = one_step_scene(tmp)
        commands = {"--version": ["--version"], "run one-step": ["run", str(scene)]}
        results = {}
        for name, extra in commands.items():
            for b in args.binaries:
                time_once([b] + extra)  # warm the page cache
            samples = {b: [] for b in args.binaries}
            for _ in range(args.runs):
                for b in args.binaries:
                    samples[b].append(time_once([b] + extra))
            results[name] = samples
    width = max(len(b) for b in args.binaries)
    print(f"median of {args.runs} runs each (ms)")
    print(f"{'command':<14} {'binary':<{width}} {'wall':>8} {'cpu':>8}")
    for name, samples in results.items():
        for b, s in samples.items():
            wall = statistics.median(w for w, _ in s) * 1e3
            cpu = statistics.median(c for _, c in s) * 1e3
            print(f"{name:<14} {b:<{width}} {wall:8.2f} {cpu:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
