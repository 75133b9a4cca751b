#!/usr/bin/env python3
"""bench/moordyn/compare_oc4.py's MoorDyn deck describes the benchmark's scene.

The comparison with MoorDyn-C is only fair if MoorDyn is given the same lines, seabed, water and
gravity as bench/scenes/oc4-three-lines.json. cablesim's own MoorDyn reader (tested on its own
in moordyn_deck_test) reads the deck the script writes back into a scene; every cable property
must equal the bench scene's to 1e-6 relative (the bench scene's numbers are written to 7 to 11
significant digits, the deck's BA to 7), the supports and fairleads must sit on the same points,
and the seabed, water density and gravity must be the same.

    moordyn_compare_deck_test.py SOURCE_DIR BIN_DIR
"""
import json
import os
import subprocess
import sys
import tempfile


def close(a, b, rel=1e-6):
    return abs(a - b) <= rel * max(abs(a), abs(b), 1e-300)


def main():
    root, bin_dir = sys.argv[1], sys.argv[2]
    sys.path.insert(0, os.path.join(root, "bench", "moordyn"))
    import compare_oc4

    bench = json.load(open(os.path.join(root, "bench", "scenes", "oc4-three-lines.json")))
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        deck = os.path.join(tmp, "oc4.dat")
        compare_oc4.write_deck(deck, 20, None, "RK2")
        out = os.path.join(tmp, "oc4.json")
        p = subprocess.run([os.path.join(bin_dir, "cablesim"), "import", deck, "--out", out],
                           capture_output=True, text=True)
        if p.returncode != 0:
            print(p.stdout, p.stderr)
            return 1
        scene = json.load(open(out))

    def same(path, a, b):
        if isinstance(b, dict):
            for k in b:
                same(f"{path}.{k}", (a or {}).get(k), b[k])
        elif isinstance(b, (int, float)) and not isinstance(b, bool):
            if not isinstance(a, (int, float)) or not close(a, b):
                failures.append(f"{path}: deck {a}, bench scene {b}")
        elif a != b:
            failures.append(f"{path}: deck {a!r}, bench scene {b!r}")

    if len(scene["cables"]) != len(bench["cables"]):
        failures.append(f"{len(scene['cables'])} cables, the bench scene has {len(bench['cables'])}")
    for i, (c, b) in enumerate(zip(scene["cables"], bench["cables"])):
        for k in b:
            if k in ("points", "name"):
                continue
            same(f"cables[{i}].{k}", c.get(k), b[k])
        # The line's ends: anchor (s = 0) and fairlead (s = length).
        for end in (0, -1):
            for axis in "xyz":
                same(f"cables[{i}].points[{end}].{axis}", c["points"][end].get(axis, 0.0),
                     b["points"][end].get(axis, 0.0))
    for k in ("seabed", "gravity"):
        same(k, scene.get(k), bench[k])
    same("fluid.density", scene["fluid"].get("density"), bench["fluid"]["density"])
    for f in failures:
        print("FAIL", f)
    print(f"{len(failures)} differences between the comparison deck and the bench scene")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
