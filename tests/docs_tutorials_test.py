#!/usr/bin/python3
"""Runs every command of docs/getting-started.md and docs/tutorials/*.md as
written (CTest docs_tutorials_slow_test; docs/development.md).

Each page's fenced blocks run in order, in a scratch directory of their own
where scenes/, sweeps/, docs/, client/, proto/ and deploy/ are the
repository's and build/ is the build tree, so that `build/bin/cablesim run
scenes/... --out x.csv` works as the page says and writes only there:

- ```sh blocks with `bash -e -o pipefail` (a failing command fails the page);
- ```python blocks with /usr/bin/python3, or with the interpreter an HTML
  comment `<!-- python: PATH -->` right above the block names;
- `<!-- expect exit N -->` right above a block: it must exit with N (a sh
  block then runs without -e: it is a script that sets its own status);
- `<!-- not run: why -->` right above a block: skipped (the README's own
  commands, which CI runs itself).

As root (CI) each page runs in a network namespace of its own (`ip netns`),
so a tutorial's server on 127.0.0.1:50051 meets no other; otherwise on the
machine's loopback. Processes a page leaves running are killed at its end.

Usage: docs_tutorials_test.py SOURCE_DIR BUILD_DIR [PAGE.md...]
"""
import glob
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

SOURCE, BUILD = (os.path.abspath(a) for a in sys.argv[1:3])
PAGES = sys.argv[3:] or ([os.path.join(SOURCE, "docs", "getting-started.md")]
                         + sorted(glob.glob(os.path.join(SOURCE, "docs", "tutorials", "*.md"))))
LINKED = ("scenes", "sweeps", "docs", "client", "proto", "deploy")
FENCE = re.compile(r"^```(\w*)\n(.*?)^```\n", re.S | re.M)
MARK = re.compile(r"<!--\s*(not run|expect exit|python)\s*:?\s*(.*?)\s*-->\s*$")


def blocks(text):
    """(language, code, marks) for each fenced block, marks from the HTML
    comments on the lines right above it."""
    out = []
    for m in FENCE.finditer(text):
        lang, code = m.group(1), m.group(2)
        marks = {}
        before = text[:m.start()].rstrip("\n").split("\n")
        while before and MARK.search(before[-1]):
            k = MARK.search(before[-1])
            marks[k.group(1)] = k.group(2)
            before.pop()
        out.append((lang, code, marks))
    return out


def run_page(page):
    rel = os.path.relpath(page, SOURCE)
    scratch = tempfile.mkdtemp(prefix="cablesim-docs-")
    for name in LINKED:
        os.symlink(os.path.join(SOURCE, name), os.path.join(scratch, name))
    os.symlink(BUILD, os.path.join(scratch, "build"))
    ns = None
    prefix = []
    if os.geteuid() == 0 and subprocess.run(["which", "ip"], capture_output=True).returncode == 0:
        ns = f"cablesim-docs-{os.getpid()}"
        subprocess.run(["ip", "netns", "delete", ns], capture_output=True)
        subprocess.run(["ip", "netns", "add", ns], check=True)
        subprocess.run(["ip", "netns", "exec", ns, "ip", "link", "set", "lo", "up"], check=True)
        prefix = ["ip", "netns", "exec", ns]
    env = dict(os.environ, MPLBACKEND="Agg", MPLCONFIGDIR=os.path.join(scratch, ".mpl"))
    env.pop("PYTHONPATH", None)
    failures = 0
    ran = 0
    started = time.monotonic()
    children = []
    try:
        for i, (lang, code, marks) in enumerate(blocks(open(page).read())):
            if lang not in ("sh", "python") or "not run" in marks:
                continue
            if lang == "sh" and "expect exit" in marks:
                argv = ["bash", "-c", code]  # a script that sets its own status
            elif lang == "sh":
                argv = ["bash", "-e", "-o", "pipefail", "-c", code]
            else:
                argv = [marks.get("python", "/usr/bin/python3"), "-c", code]
            expected = int(marks.get("expect exit", "0"))
            # A session of its own, so that what the block leaves running
            # (a server started with &) can be found and stopped at the end.
            # Output to a file, not a pipe: a server the block leaves running
            # keeps its standard output open.
            log = os.path.join(scratch, f".block-{i + 1}.log")
            with open(log, "w") as out_file:
                p = subprocess.Popen(prefix + argv, cwd=scratch, env=env, stdout=out_file,
                                     stderr=subprocess.STDOUT, start_new_session=True)
            children.append(p.pid)
            try:
                p.wait(timeout=300)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
            out = open(log, errors="replace").read()
            ran += 1
            first = code.strip().split("\n")[0][:90]
            if p.returncode != expected:
                failures += 1
                print(f"FAIL {rel} block {i + 1} ({lang}: {first}): exit {p.returncode}, "
                      f"expected {expected}\n{out}")
            else:
                print(f"ok   {rel} block {i + 1} ({lang}: {first})")
                if os.environ.get("CABLESIM_DOCS_VERBOSE"):
                    print(out)
    finally:
        for pid in children:
            try:
                os.killpg(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        if ns:
            pids = subprocess.run(["ip", "netns", "pids", ns], capture_output=True, text=True)
            for pid in pids.stdout.split():
                try:
                    os.kill(int(pid), signal.SIGKILL)
                except ProcessLookupError:
                    pass
            subprocess.run(["ip", "netns", "delete", ns], capture_output=True)
        subprocess.run(["rm", "-rf", scratch])
    print(f"     {rel}: {ran} blocks in {time.monotonic() - started:.1f} s")
    if ran == 0:
        print(f"FAIL {rel}: no block ran")
        failures += 1
    return failures


def main():
    failures = sum(run_page(p) for p in PAGES)
    print(f"{failures} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
