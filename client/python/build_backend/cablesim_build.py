"""The cablesim package's build backend (PEP 517): builds the wheel with
Python's standard library alone, in a temporary directory.

Why not setuptools: `pip install --no-build-isolation` with setuptools
before 70.1 needs the separate `wheel` package for bdist_wheel, which a
Python that is not Debian's usually lacks ("invalid command 'bdist_wheel'"),
and offline nothing can fetch it; setuptools also writes build/ and
*.egg-info into the source directory, which fails in a read-only checkout.
This backend needs no package at all: any Python 3.9+ installs cablesim
offline from a read-only checkout.

What the wheel holds: the cablesim/ package, and cablesim/v1/scene_pb2.py,
service_pb2.py, service_pb2_grpc.py generated from proto/cablesim/v1/*.proto
(looked for in $CABLESIM_PROTO_DIR, then ../../proto: this directory in the
cablesim source tree, then proto/ in an sdist) by $PROTOC or `protoc` with $GRPC_PYTHON_PLUGIN or
`grpc_python_plugin` (Debian: protobuf-compiler, protobuf-compiler-grpc), or
else by the grpc_tools module. The metadata comes from pyproject.toml
([project]).
"""

import base64
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import zipfile

HERE = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
PROTOS = ("cablesim/v1/scene.proto", "cablesim/v1/service.proto")
PACKAGE = "cablesim"


# ---- pyproject.toml's [project] ------------------------------------------


def _project():
    """The [project] table of pyproject.toml (tomllib from 3.11; before it,
    a reader of the plain subset that file uses: strings, lists of strings,
    one-line tables)."""
    path = os.path.join(HERE, "pyproject.toml")
    try:
        import tomllib
        with open(path, "rb") as f:
            return tomllib.load(f)["project"]
    except ImportError:
        pass
    data, table, pending = {}, None, None
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for raw in lines:
        line = raw.split(" #")[0].strip() if not raw.strip().startswith("#") else ""
        if pending is not None:
            key, acc = pending
            acc += " " + line
            if acc.count("[") == acc.count("]"):
                table[key] = _value(acc)
                pending = None
            else:
                pending = (key, acc)
            continue
        if not line:
            continue
        m = re.match(r"^\[([\w.\-]+)\]$", line)
        if m:
            table = data.setdefault(m.group(1), {})
            continue
        key, _, value = (s.strip() for s in line.partition("="))
        if table is None:
            continue
        if value.startswith("[") and value.count("[") != value.count("]"):
            pending = (key, value)
        else:
            table[key] = _value(value)
    return data["project"]


def _value(text):
    text = text.strip()
    if text.startswith("["):
        return re.findall(r'"((?:[^"\\]|\\.)*)"', text)
    if text.startswith('"'):
        return text[1:-1]
    return text


def _metadata(project):
    lines = ["Metadata-Version: 2.1", "Name: %s" % project["name"],
             "Version: %s" % project["version"]]
    if project.get("description"):
        lines.append("Summary: %s" % project["description"])
    if project.get("requires-python"):
        lines.append("Requires-Python: %s" % project["requires-python"])
    for dep in project.get("dependencies", []):
        lines.append("Requires-Dist: %s" % dep)
    for extra, deps in project.get("optional-dependencies", {}).items():
        lines.append("Provides-Extra: %s" % extra)
        for dep in deps:
            lines.append('Requires-Dist: %s ; extra == "%s"' % (dep, extra))
    body = ""
    readme = project.get("readme")
    if readme and os.path.exists(os.path.join(HERE, readme)):
        lines.append("Description-Content-Type: text/markdown")
        with open(os.path.join(HERE, readme), encoding="utf-8") as f:
            body = "\n" + f.read()
    return "\n".join(lines) + "\n" + body


# ---- the generated gRPC modules ---------------------------------------------


def _proto_dir():
    candidates = [os.environ.get("CABLESIM_PROTO_DIR"), os.path.join(HERE, "..", "..", "proto"),
                  os.path.join(HERE, "proto")]  # the last: in an sdist
    for candidate in candidates:
        if candidate and all(os.path.isfile(os.path.join(candidate, p)) for p in PROTOS):
            return os.path.abspath(candidate)
    raise SystemExit("cablesim: cannot find proto/cablesim/v1/service.proto (tried %s); "
                     "set CABLESIM_PROTO_DIR to the source tree's proto directory"
                     % ", ".join(c for c in candidates if c))


def _compiler():
    protoc = os.environ.get("PROTOC") or shutil.which("protoc")
    plugin = os.environ.get("GRPC_PYTHON_PLUGIN") or shutil.which("grpc_python_plugin")
    if protoc and plugin:
        return [protoc, "--plugin=protoc-gen-grpc_python=" + plugin]
    try:
        import grpc_tools
    except ImportError:
        raise SystemExit("cablesim: generating the gRPC modules needs protoc and grpc_python_plugin "
                         "(Debian: apt-get install protobuf-compiler protobuf-compiler-grpc) or "
                         "the grpc_tools module") from None
    well_known = os.path.join(os.path.dirname(grpc_tools.__file__), "_proto")
    return [sys.executable, "-m", "grpc_tools.protoc", "--proto_path=" + well_known]


def _stage(root):
    """The package's files, sources and generated modules, under root."""
    shutil.copytree(os.path.join(HERE, PACKAGE), os.path.join(root, PACKAGE),
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "v1"))
    source = _proto_dir()
    subprocess.run(_compiler() + ["--proto_path=" + source, "--python_out=" + root,
                                  "--grpc_python_out=" + root]
                   + [os.path.join(source, p) for p in PROTOS], check=True)
    with open(os.path.join(root, PACKAGE, "v1", "__init__.py"), "w") as f:
        f.write('"""Modules generated from proto/cablesim/v1 when the package was built."""\n')


# ---- PEP 517 -----------------------------------------------------------------


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def _dist_info(project):
    return "%s-%s.dist-info" % (project["name"], project["version"])


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    project = _project()
    info = os.path.join(metadata_directory, _dist_info(project))
    os.makedirs(info, exist_ok=True)
    with open(os.path.join(info, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata(project))
    return os.path.basename(info)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    project = _project()
    name = "%s-%s-py3-none-any.whl" % (project["name"], project["version"])
    info = _dist_info(project)
    records = []
    with tempfile.TemporaryDirectory(prefix="cablesim-wheel-") as root:
        _stage(root)
        path = os.path.join(wheel_directory, name)
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as wheel:
            def add(arcname, data):
                digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=")
                records.append("%s,sha256=%s,%d" % (arcname, digest.decode(), len(data)))
                wheel.writestr(arcname, data)

            for directory, dirs, files in sorted(os.walk(os.path.join(root, PACKAGE))):
                dirs.sort()
                for file in sorted(files):
                    full = os.path.join(directory, file)
                    with open(full, "rb") as f:
                        add(os.path.relpath(full, root).replace(os.sep, "/"), f.read())
            add(info + "/METADATA", _metadata(project).encode("utf-8"))
            add(info + "/WHEEL", ("Wheel-Version: 1.0\nGenerator: cablesim_build\n"
                                  "Root-Is-Purelib: true\nTag: py3-none-any\n").encode())
            add(info + "/top_level.txt", (PACKAGE + "\n").encode())
            records.append(info + "/RECORD,,")
            wheel.writestr(info + "/RECORD", "\n".join(records) + "\n")
    return name


def build_sdist(sdist_directory, config_settings=None):
    """The package's sources with the .proto files beside them (proto/), so
    that the sdist builds on its own."""
    project = _project()
    base = "%s-%s" % (project["name"], project["version"])
    name = base + ".tar.gz"
    with tarfile.open(os.path.join(sdist_directory, name), "w:gz") as tar:
        for entry in ("pyproject.toml", "README.md", "build_backend", PACKAGE):
            tar.add(os.path.join(HERE, entry), arcname=base + "/" + entry,
                    filter=lambda t: None if "__pycache__" in t.name else t)
        source = _proto_dir()
        for proto in PROTOS:
            tar.add(os.path.join(source, proto), arcname=base + "/proto/" + proto)
        info = tarfile.TarInfo(base + "/PKG-INFO")
        data = _metadata(project).encode("utf-8")
        info.size = len(data)
        import io
        tar.addfile(info, io.BytesIO(data))
    return name
