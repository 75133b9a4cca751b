#!/usr/bin/env python3
"""Fails when an include in engine/ goes up a layer, forms a cycle, or
leaves the engine (engine/ is pure C++ on Eigen and Abseil).

The layers, lowest first (docs/development.md explains each):
  scene < elements < linear < output < forces < constraints < model
        < steppers < analysis < run
A file may include files of its own folder or of a lower one. Within a
folder the includes must not form a cycle, counting a header and its .cc as
one unit (so a .cc that includes a header which includes the .cc's own
header is a cycle: two classes that need each other).

Usage: check_engine_layers.py ENGINE_DIR   (exit 0: clean; 1: violations)
       check_engine_layers.py --self-test  (the check catches what it must)
"""
import os
import re
import sys

LAYERS = ["scene", "elements", "linear", "output", "forces", "constraints", "model",
          "steppers", "analysis", "run"]
RANK = {name: i for i, name in enumerate(LAYERS)}
# Outside engine/: only the standard library, Eigen, Abseil and Spectra.
ALLOWED_ANGLE_OR_QUOTED_PREFIXES = ("absl/", "Eigen/", "Spectra/", "unsupported/Eigen/")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def main(engine_dir):
    engine_dir = os.path.abspath(engine_dir)
    problems = []
    graph = {}
    for root, _, files in os.walk(engine_dir):
        for name in sorted(files):
            if not name.endswith((".h", ".cc")):
                continue
            path = os.path.join(root, name)
            rel = os.path.relpath(path, os.path.dirname(engine_dir))  # engine/x/y.h
            parts = rel.split(os.sep)
            if len(parts) != 3:
                problems.append(f"{rel}: engine files live one folder deep (engine/LAYER/file)")
                continue
            folder = parts[1]
            if folder not in RANK:
                problems.append(f"{rel}: folder '{folder}' is not a layer ({', '.join(LAYERS)})")
                continue
            unit = os.path.splitext(rel)[0]
            graph.setdefault(unit, set())
            text = open(path, encoding="utf-8").read()
            for lineno, m in ((text.count("\n", 0, m.start()) + 1, m)
                              for m in INCLUDE.finditer(text)):
                kind, target = m.group(1), m.group(2)
                if target.startswith("engine/"):
                    tparts = target.split("/")
                    tfolder = tparts[1] if len(tparts) == 3 else None
                    if tfolder not in RANK:
                        problems.append(f"{rel}:{lineno}: includes {target}, not in a layer")
                        continue
                    if RANK[tfolder] > RANK[folder]:
                        problems.append(
                            f"{rel}:{lineno}: includes {target}: '{folder}' may not include "
                            f"the higher layer '{tfolder}'")
                    tunit = os.path.splitext(target)[0]
                    if tunit != unit:
                        graph[unit].add(tunit)
                elif kind == '"' or target.startswith(("google/", "grpc", "cablesim/")):
                    if not target.startswith(ALLOWED_ANGLE_OR_QUOTED_PREFIXES):
                        problems.append(f"{rel}:{lineno}: includes {target}: the engine "
                                        "uses only the standard library, Eigen and Abseil")
    # Cycles (within a folder; across folders the ranks already forbid them).
    state = {}
    stack = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                problems.append("include cycle: " + " -> ".join(cycle))
            elif nxt in graph and state.get(nxt) is None:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if state.get(node) is None:
            visit(node)
    for p in problems:
        print(p)
    print(f"{len(graph)} engine units, {sum(len(v) for v in graph.values())} engine includes, "
          f"{len(problems)} problems")
    return 1 if problems else 0


def self_test():
    import tempfile
    import contextlib
    import io
    with tempfile.TemporaryDirectory() as tmp:
        eng = os.path.join(tmp, "engine")
        files = {
            "scene/a.h": '#include "engine/model/b.h"\n',          # goes up
            "model/b.h": '#include "engine/scene/c.h"\n',
            "scene/c.h": "",
            "model/d.h": '#include "engine/model/e.h"\n',
            "model/e.h": "",
            "model/e.cc": '#include "engine/model/d.h"\n',          # unit cycle d <-> e
            "run/f.h": '#include "server/x.h"\n',                    # leaves the engine
            "misc/g.h": "",                                          # not a layer
        }
        for rel, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(eng, rel)), exist_ok=True)
            with open(os.path.join(eng, rel), "w") as f:
                f.write(text)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            rc = main(eng)
        text = out.getvalue()
        expected = ["may not include the higher layer 'model'", "include cycle: engine/model/d",
                    "includes server/x.h", "'misc' is not a layer"]
        missing = [e for e in expected if e not in text]
        if rc != 1 or missing:
            print(text)
            print("self-test FAILED: missing", missing)
            return 1
        print("self-test passed: the check reports an upward include, a cycle, a foreign "
              "include and a stray folder")
        return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--self-test":
        sys.exit(self_test())
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "engine"))
