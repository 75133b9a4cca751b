"""Builds the cablesim package with its generated gRPC modules.

pyproject.toml holds the metadata; this file only adds a build step: the
modules cablesim/v1/scene_pb2.py, service_pb2.py and service_pb2_grpc.py are
generated from proto/cablesim/v1/*.proto into the build directory, so that
the wheel (and `pip install ./client/python`) carries them. The .proto files
are looked for in $CABLESIM_PROTO_DIR, then ../../proto (this directory in
the cablesim source tree). The compiler is $PROTOC or `protoc` with
$GRPC_PYTHON_PLUGIN or `grpc_python_plugin` (Debian: protobuf-compiler,
protobuf-compiler-grpc), else the grpc_tools module.
"""

import os
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
PROTOS = ("cablesim/v1/scene.proto", "cablesim/v1/service.proto")


def proto_dir():
    candidates = [os.environ.get("CABLESIM_PROTO_DIR"), os.path.join(HERE, "..", "..", "proto")]
    for candidate in candidates:
        if candidate and all(os.path.isfile(os.path.join(candidate, p)) for p in PROTOS):
            return os.path.abspath(candidate)
    raise SystemExit("cablesim: cannot find proto/cablesim/v1/service.proto (tried %s); "
                     "set CABLESIM_PROTO_DIR to the source tree's proto directory"
                     % ", ".join(c for c in candidates if c))


def compiler_command(source, out):
    protoc = os.environ.get("PROTOC") or shutil.which("protoc")
    plugin = os.environ.get("GRPC_PYTHON_PLUGIN") or shutil.which("grpc_python_plugin")
    if protoc and plugin:
        return [protoc, "--plugin=protoc-gen-grpc_python=" + plugin]
    try:
        import grpc_tools  # noqa: F401
    except ImportError:
        raise SystemExit("cablesim: generating the gRPC modules needs protoc and grpc_python_plugin "
                         "(Debian: apt-get install protobuf-compiler protobuf-compiler-grpc) or "
                         "the grpc_tools module")
    import grpc_tools
    well_known = os.path.join(os.path.dirname(grpc_tools.__file__), "_proto")
    return [sys.executable, "-m", "grpc_tools.protoc", "--proto_path=" + well_known]


def generate(out):
    source = proto_dir()
    command = compiler_command(source, out) + [
        "--proto_path=" + source, "--python_out=" + out, "--grpc_python_out=" + out
    ] + [os.path.join(source, p) for p in PROTOS]
    subprocess.run(command, check=True)
    with open(os.path.join(out, "cablesim", "v1", "__init__.py"), "w") as f:
        f.write('"""Modules generated from proto/cablesim/v1 when the package was built."""\n')


class BuildPyWithProtos(build_py):
    def run(self):
        super().run()
        if not self.dry_run:
            generate(self.build_lib)


setup(cmdclass={"build_py": BuildPyWithProtos})
