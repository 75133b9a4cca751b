"""Python client of the cablesim service (proto/cablesim/v1/service.proto).

The gRPC modules are generated at build time from the same .proto files
with Debian's protobuf compiler and its gRPC Python plugin (CMake target
cablesim_python, into build/python); put that directory on PYTHONPATH.

    PYTHONPATH=build/python:client/python /usr/bin/python3 \
        client/python/cablesim_client.py --server 127.0.0.1:50051 \
        scenes/falling-pendulum.json --png pendulum.png

streams a run into numpy arrays and plots the first probe's path and the
energy components to a PNG.
"""

import argparse
import collections
import json
import sys

import grpc
import numpy as np
from google.protobuf import json_format

from cablesim.v1 import scene_pb2, service_pb2, service_pb2_grpc


class RunResult:
    """A streamed run: `columns` (names), `data` (frames x columns array,
    SI units: s, m, m/s, m/s^2, J), `info` (ModelInfo) and `summary`
    (RunSummary)."""

    def __init__(self, header, data, summary):
        self.columns = list(header.columns)
        self.info = header.info
        self.data = data
        self.summary = summary

    def column(self, name):
        return self.data[:, self.columns.index(name)]


class _CallDetails(collections.namedtuple(
        "_CallDetails", ("method", "timeout", "metadata", "credentials", "wait_for_ready",
                         "compression")), grpc.ClientCallDetails):
    pass


class _BearerToken(grpc.UnaryUnaryClientInterceptor, grpc.UnaryStreamClientInterceptor):
    """Adds `authorization: Bearer TOKEN` to every call (an interceptor, not
    call credentials, so that it also works on a loopback channel without
    TLS)."""

    def __init__(self, token):
        self._entry = ("authorization", "Bearer " + token)

    def _details(self, details):
        return _CallDetails(details.method, details.timeout,
                            list(details.metadata or []) + [self._entry], details.credentials,
                            getattr(details, "wait_for_ready", None),
                            getattr(details, "compression", None))

    def intercept_unary_unary(self, continuation, details, request):
        return continuation(self._details(details), request)

    def intercept_unary_stream(self, continuation, details, request):
        return continuation(self._details(details), request)


def read_token(path):
    """The token in a token file: the first word of its first line that is
    not a # comment."""
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                return line.split()[0]
    raise ValueError("%s: no token" % path)


def connect(address, tls_ca=None, token=None):
    """A stub for the cablesim-server at `address` ("host:port", or a gRPC
    target naming several servers that share one job store:
    "ipv4:127.0.0.1:50051,127.0.0.1:50052" or "dns:///name:port"; calls are
    spread over them with gRPC's round_robin policy). `tls_ca`: a CA
    certificate file (PEM): TLS, the server's certificate checked against
    it. `token`: a bearer token sent with every call."""
    options = [("grpc.lb_policy_name", "round_robin")]
    if tls_ca:
        with open(tls_ca, "rb") as f:
            channel = grpc.secure_channel(
                address, grpc.ssl_channel_credentials(f.read()), options=options)
    else:
        channel = grpc.insecure_channel(address, options=options)
    if token:
        channel = grpc.intercept_channel(channel, _BearerToken(token))
    return service_pb2_grpc.CablesimServiceStub(channel)


def load_scene(path):
    """A cablesim.v1.Scene from a protobuf JSON scene file."""
    with open(path) as f:
        return json_format.Parse(f.read(), scene_pb2.Scene())


def run(stub, scene, frames_per_batch=256, timeout=None):
    """Runs `scene` on the server, streaming the frames into a numpy array.
    Raises grpc.RpcError (INVALID_ARGUMENT naming the field for a bad
    scene)."""
    request = service_pb2.RunRequest(scene=scene, frames_per_batch=frames_per_batch)
    return _read_stream(stub.Run(request, timeout=timeout))


def _read_stream(events):
    header, summary, chunks = None, None, []
    for event in events:
        kind = event.WhichOneof("event")
        if kind == "header":
            header = event.header
        elif kind == "frames":
            chunks.append(np.asarray(event.frames.values, dtype=np.float64))
        elif kind == "summary":
            summary = event.summary
    ncol = len(header.columns)
    flat = np.concatenate(chunks) if chunks else np.zeros(0)
    return RunResult(header, flat.reshape(-1, ncol), summary)


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
    return _read_stream(stub.GetJobResult(service_pb2.GetJobResultRequest(id=job_id)))


def plot(result, png_path, probe=None):
    """Plots the path of `probe` (default: the first) and the energy
    components against time to `png_path`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    probe = probe or result.info.probe_names[0]
    fig, (path_ax, energy_ax) = plt.subplots(1, 2, figsize=(11, 4.5))
    path_ax.plot(result.column(probe + ".x"), result.column(probe + ".y"))
    path_ax.set_xlabel("x [m]")
    path_ax.set_ylabel("y [m]")
    path_ax.set_title("path of " + probe)
    path_ax.set_aspect("equal", adjustable="datalim")
    t = result.column("t")
    for name in ("kinetic", "potential", "axial", "bending", "total"):
        energy_ax.plot(t, result.column("energy." + name), label=name)
    energy_ax.set_xlabel("t [s]")
    energy_ax.set_ylabel("energy [J]")
    energy_ax.legend()
    energy_ax.set_title("energy")
    fig.tight_layout()
    fig.savefig(png_path, dpi=100)
    plt.close(fig)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", help="scene file (protobuf JSON)")
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--png", help="plot the first probe's path and the energies here")
    parser.add_argument("--tls-ca", help="TLS: the CA certificate (PEM) the server's is checked against")
    parser.add_argument("--token-file", help="send the token in this file (its first word)")
    args = parser.parse_args(argv)
    stub = connect(args.server, tls_ca=args.tls_ca,
                   token=read_token(args.token_file) if args.token_file else None)
    try:
        result = run(stub, load_scene(args.scene))
    except grpc.RpcError as e:
        print("cablesim_client: %s: %s" % (e.code().name, e.details()), file=sys.stderr)
        return 2 if e.code() == grpc.StatusCode.INVALID_ARGUMENT else 1
    print(json.dumps({"frames": int(result.data.shape[0]),
                      "columns": len(result.columns),
                      "status": result.summary.status}))
    if args.png:
        plot(result, args.png)
    return 0 if result.summary.status == "ok" else 3


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
