"""Python client of the cablesim service (proto/cablesim/v1/service.proto).

A script and the functional API of the first client, kept for scripts that
use it: the client itself is the `cablesim` package beside this file
(client/python/cablesim, `pip install ./client/python`), whose
cablesim.Client is the typed interface. Without installing the package, the
gRPC modules generated at build time from the same .proto files with
Debian's protobuf compiler and its gRPC Python plugin (CMake target
cablesim_python, into build/python) serve: put that directory on
PYTHONPATH.

    PYTHONPATH=build/python:client/python /usr/bin/python3 \
        client/python/cablesim_client.py --server 127.0.0.1:50051 \
        scenes/falling-pendulum.json --png pendulum.png

streams a run into numpy arrays and plots the first probe's path and the
energy components to a PNG; `--animate cable.gif` also asks for the
cable's shape (Scene.output.shape) and draws the cables moving.
"""

import argparse
import json
import sys

import grpc

from cablesim.client import read_token  # noqa: F401 (part of this module's API)
from cablesim.client import open_channel
from cablesim.results import Result as RunResult  # noqa: F401
from cablesim.animation import animate  # noqa: F401 (part of this module's API)
from cablesim.results import result_from_events
from cablesim.v1 import scene_pb2, service_pb2, service_pb2_grpc  # noqa: F401


def connect(address, tls_ca=None, token=None):
    """A stub for the cablesim-server at `address` ("host:port", or a target
    naming several servers, see cablesim.open_channel). `tls_ca`: a CA
    certificate file (PEM): TLS, the server's certificate checked against
    it. `token`: a bearer token sent with every call."""
    return service_pb2_grpc.CablesimServiceStub(open_channel(address, tls_ca=tls_ca, token=token))


def load_scene(path):
    """A cablesim.v1.Scene from a protobuf JSON scene file."""
    from cablesim.scenes import load_scene as load
    return load(path)


def run(stub, scene, frames_per_batch=256, timeout=None):
    """Runs `scene` on the server, streaming the frames into a numpy array
    (a cablesim.Result). Raises grpc.RpcError (INVALID_ARGUMENT naming the
    field for a bad scene)."""
    request = service_pb2.RunRequest(scene=scene, frames_per_batch=frames_per_batch)
    return result_from_events(stub.Run(request, timeout=timeout))


def submit(stub, scene):
    """Queues `scene` as a durable job; returns its id at once."""
    return stub.SubmitJob(service_pb2.SubmitJobRequest(scene=scene)).id


def wait(stub, job_id, timeout=None):
    """Follows the job until it is finished; returns the last Job message
    (state SUCCEEDED, FAILED or CANCELLED)."""
    job = None
    for job in stub.WatchJob(service_pb2.WatchJobRequest(id=job_id), timeout=timeout):
        pass
    return job


def job_result(stub, job_id):
    """A finished job's trajectory and summary, as run() returns them."""
    return result_from_events(stub.GetJobResult(service_pb2.GetJobResultRequest(id=job_id)))


def plot(result, png_path, probe=None, view="xy", tension=None):
    """Plots the path of `probe` (default: the first) in the plane `view`,
    the energy components and, with `tension`, the tensions against time to
    `png_path` (Result.plot)."""
    result.plot(png_path, probe, view=view, tension=tension)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="scene file (protobuf JSON)")
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--png", help="plot the first probe's path and the energies here")
    parser.add_argument("--animate", help="draw the cables (GIF, or MP4 with ffmpeg) here; "
                        "asks the server for the cable's shape")
    parser.add_argument("--tls-ca", help="TLS: the CA certificate (PEM) the server's is checked against")
    parser.add_argument("--token-file", help="send the token in this file (its first word)")
    args = parser.parse_args(argv)
    stub = connect(args.server, tls_ca=args.tls_ca,
                   token=read_token(args.token_file) if args.token_file else None)
    try:
        scene = load_scene(args.scene)
        if args.animate:
            scene.output.shape = True
        result = run(stub, scene)
    except grpc.RpcError as e:
        print("cablesim_client: %s: %s" % (e.code().name, e.details()), file=sys.stderr)
        return 2 if e.code() == grpc.StatusCode.INVALID_ARGUMENT else 1
    print(json.dumps({"frames": int(result.data.shape[0]),
                      "columns": len(result.columns),
                      "status": result.summary.status}))
    if args.png:
        plot(result, args.png)
    if args.animate:
        animate(result, args.animate)
    return 0 if result.summary.status == "ok" else 3


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
