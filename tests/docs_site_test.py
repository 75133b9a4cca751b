#!/usr/bin/python3
"""Builds the documentation site strictly and checks the generated scene
reference (CTest docs_site_test; docs/development.md).

- `mkdocs build --strict` must succeed: a link to a page or file that does
  not exist, a page missing from the files, any warning fails it;
- the scene reference it generated (site/reference/scene/index.html, from
  docs/hooks/scene_reference.py) must name every message, field and enum
  value of proto/cablesim/v1/scene.proto, so the page cannot drift from the
  contract (nor the generator silently skip a construct it does not read).

Usage: docs_site_test.py SOURCE_DIR SITE_DIR. Exit 77 (skipped) without
mkdocs (Debian: mkdocs, mkdocs-material).
"""
import html
import os
import re
import shutil
import subprocess
import sys

source, site = (os.path.abspath(a) for a in sys.argv[1:3])
mkdocs = shutil.which("mkdocs")
if mkdocs is None:
    print("SKIPPED: mkdocs is not installed (Debian: apt-get install mkdocs mkdocs-material)")
    sys.exit(77)
r = subprocess.run([mkdocs, "build", "--strict", "--site-dir", site], cwd=source,
                   capture_output=True, text=True)
print(r.stdout + r.stderr)
if r.returncode != 0:
    print("FAIL: mkdocs build --strict")
    sys.exit(1)
page = html.unescape(open(os.path.join(site, "reference", "scene", "index.html")).read())
proto = open(os.path.join(source, "proto", "cablesim", "v1", "scene.proto")).read()
# Messages and enums are headings (their anchors end in the lower-case
# name); fields and enum values are table cells in <code>.
types = set(re.findall(r"^\s*(?:message|enum)\s+(\w+)\s*\{", proto, re.M))
members = set(re.findall(r"^\s*(?:repeated\s+)?[\w.]+\s+(\w+)\s*=\s*\d+\s*;", proto, re.M))
members |= set(re.findall(r"^\s*([A-Z][A-Z0-9_]+)\s*=\s*\d+\s*;", proto, re.M))
names = types | members
missing = sorted([t for t in types if not re.search(r'id="\w*%s"' % t.lower(), page)]
                 + [m for m in members if "<code>%s</code>" % m not in page])
print(f"scene reference: {len(names)} names of scene.proto, {len(missing)} missing {missing}")
sys.exit(1 if missing else 0)
