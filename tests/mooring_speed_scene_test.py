#!/usr/bin/env python3
"""bench/mooring_speed.py --write-scene writes the scene of one benchmark setting.

The figures quoted for a single setting (docs/mooring-speed.md) are reproduced by timing
`cablesim run` on that file, so it must be the scene the benchmark runs: the config's scene with
its scene_patch and each cable's cable_patch, the variant's elements and Gauss points on every
cable and its solver fields merged into the scene's solver (checked field by field against the
config, an independent reading of it); and a variant that is not a JSON object is refused with
exit 2, naming the argument.

    mooring_speed_scene_test.py SOURCE_DIR
"""
import json
import os
import subprocess
import sys
import tempfile


def main():
    root = sys.argv[1]
    script = os.path.join(root, "bench", "mooring_speed.py")
    config_path = os.path.join(root, "bench", "mooring_speed_buoy.json")
    config = json.load(open(config_path))
    scene = json.load(open(os.path.join(root, config["scene"])))
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "setting.json")
        variant = {"elements": 7, "gauss_points": 3, "solver": {"integrator": "HHT", "step": 0.2}}
        subprocess.run([sys.executable, script, config_path, "--write-scene", json.dumps(variant), out],
                       check=True, capture_output=True)
        written = json.load(open(out))
        if len(written["cables"]) != len(scene["cables"]):
            failures.append("cable count")
        for i, c in enumerate(written["cables"]):
            if c.get("elements") != 7 or c.get("gauss_points") != 3:
                failures.append(f"cables[{i}]: elements/gauss_points {c.get('elements')}/{c.get('gauss_points')}")
            for k, v in config["cable_patch"]["damping"].items():
                if c.get("damping", {}).get(k) != v:
                    failures.append(f"cables[{i}].damping.{k}: {c.get('damping', {}).get(k)} != {v}")
        if written["solver"].get("integrator") != "HHT" or written["solver"].get("step") != 0.2:
            failures.append(f"solver: {written['solver']}")
        if written["solver"].get("duration") != scene["solver"]["duration"]:
            failures.append("solver.duration not kept from the scene")
        for k, v in config["scene_patch"]["fluid"]["waves"].items():
            if written["fluid"]["waves"].get(k) != v:
                failures.append(f"fluid.waves.{k}: scene_patch not applied")
        for bad in ("not json", "[1]"):
            r = subprocess.run([sys.executable, script, config_path, "--write-scene", bad, out],
                               capture_output=True, text=True)
            if r.returncode != 2 or "--write-scene VARIANT" not in r.stderr:
                failures.append(f"variant {bad!r}: exit {r.returncode}, {r.stderr.strip()[-120:]}")
    for f in failures:
        print("FAIL:", f)
    print("ok" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
