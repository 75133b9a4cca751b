#!/usr/bin/env python3
"""The scene reference page, generated from proto/cablesim/v1/scene.proto's
comments so that it never drifts from the contract.

As a MkDocs hook (mkdocs.yml `hooks:`) it adds the page reference/scene.md to
every build; run alone it prints the page:

    python3 docs/hooks/scene_reference.py [proto/cablesim/v1/scene.proto]

Reads only the subset of proto3 that scene.proto uses: messages (nested too),
enums, fields (`repeated`, scalar or message types) with `//` comments just
above them. Standard library only."""
import os
import re
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PROTO = os.path.join(HERE, "..", "..", "proto", "cablesim", "v1", "scene.proto")
PAGE = "reference/scene.md"
_DIRECTORY = None  # the generated page's directory, removed after the build


class Block:
    def __init__(self, kind, name, comment, parent):
        self.kind, self.name, self.comment, self.parent = kind, name, comment, parent
        self.items = []  # fields: (label, type, name, comment); enum values: (name, number, comment)

    @property
    def full_name(self):
        return f"{self.parent.full_name}.{self.name}" if self.parent else self.name


def parse(text):
    blocks, stack, comment, header = [], [], [], []
    seen_syntax = False
    for raw in text.split("\n"):
        line = raw.strip()
        if line.startswith("//"):
            comment.append(line[2:].strip())
            continue
        if not line:
            if not seen_syntax and comment:
                header, comment = comment, []
            comment = [] if stack or seen_syntax else comment
            continue
        if line.startswith("syntax"):
            seen_syntax = True
            header = header or comment
            comment = []
            continue
        m = re.match(r"^(message|enum)\s+(\w+)\s*\{$", line)
        if m:
            block = Block(m.group(1), m.group(2), comment, stack[-1] if stack else None)
            blocks.append(block)
            stack.append(block)
            comment = []
            continue
        if line == "}":
            stack.pop()
            comment = []
            continue
        if stack and stack[-1].kind == "message":
            m = re.match(r"^(repeated\s+)?([\w.]+)\s+(\w+)\s*=\s*\d+\s*;", line)
            if m:
                stack[-1].items.append((bool(m.group(1)), m.group(2), m.group(3), comment))
        elif stack and stack[-1].kind == "enum":
            m = re.match(r"^(\w+)\s*=\s*(\d+)\s*;", line)
            if m:
                stack[-1].items.append((m.group(1), m.group(2), comment))
        comment = []
    return header, blocks


def anchor(full_name):
    return full_name.lower().replace(".", "")


def cell(comment):
    text = " ".join(comment).strip()
    return text.replace("|", "\\|") or " "


def resolve(type_name, block, names):
    """The full name of a message or enum type as seen from block."""
    scope = block
    while scope is not None:
        candidate = f"{scope.full_name}.{type_name}"
        if candidate in names:
            return candidate
        scope = scope.parent
    return type_name if type_name in names else None


def render(proto_path):
    with open(proto_path, encoding="utf-8") as f:
        header, blocks = parse(f.read())
    names = {b.full_name for b in blocks}
    by_name = {b.full_name: b for b in blocks}
    out = ["# Scene reference", "",
           "Generated from `proto/cablesim/v1/scene.proto` while this site is built "
           "(`docs/hooks/scene_reference.py`): every message, field and enum value with its "
           "comment there, so this page is the contract itself. A scene file is a `Scene` in "
           "protobuf JSON or text format, with the field names as written below. "
           "[Scene format explained](scene-format.md) has the same fields with more physics; "
           "[Getting started](../getting-started.md) shows a whole scene.", ""]
    if header:
        out += [" ".join(header), ""]
    order = sorted(blocks, key=lambda b: (b.full_name != "Scene", 0))
    for b in order:
        out += [f"## {b.full_name} {{#{anchor(b.full_name)}}}", ""]
        if b.comment:
            out += [" ".join(b.comment), ""]
        if b.kind == "message":
            if not b.items:
                continue
            out += ["| field | type | meaning |", "| --- | --- | --- |"]
            for repeated, type_name, name, comment in b.items:
                target = resolve(type_name, b, names)
                if not comment and target and target.startswith(b.full_name + "."):
                    comment = by_name[target].comment  # a nested type's comment is the field's
                shown = f"[{type_name}](#{anchor(target)})" if target else f"`{type_name}`"
                if repeated:
                    shown = "list of " + shown
                out.append(f"| `{name}` | {shown} | {cell(comment)} |")
        else:
            out += ["| value | meaning |", "| --- | --- |"]
            for name, number, comment in b.items:
                out.append(f"| `{name}` | {cell(comment)} |")
        out.append("")
    return "\n".join(out) + "\n"


def on_files(files, config):
    """MkDocs hook: adds the generated page to the build."""
    from mkdocs.structure.files import File

    global _DIRECTORY
    directory = _DIRECTORY = tempfile.mkdtemp(prefix="cablesim-docs-")
    os.makedirs(os.path.join(directory, "reference"))
    with open(os.path.join(directory, PAGE), "w", encoding="utf-8") as f:
        f.write(render(DEFAULT_PROTO))
    stub = files.get_file_from_path(PAGE)  # the committed placeholder
    if stub is not None:
        files.remove(stub)
    files.append(File(PAGE, directory, config["site_dir"], config["use_directory_urls"]))
    return files


def on_post_build(config):
    """MkDocs hook: removes the generated page's directory once the site is written."""
    global _DIRECTORY
    if _DIRECTORY:
        shutil.rmtree(_DIRECTORY, ignore_errors=True)
        _DIRECTORY = None


if __name__ == "__main__":
    sys.stdout.write(render(sys.argv[1] if len(sys.argv) > 1 else DEFAULT_PROTO))
