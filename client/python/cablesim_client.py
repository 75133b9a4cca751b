"""Python client of the cablesim service (proto/cablesim/v1/service.proto).

The gRPC modules are generated at build time from the same .proto files
with Debian's protobuf compiler and its gRPC Python plugin (CMake target
cablesim_python, into build/python); put that directory on PYTHONPATH.

    PYTHONPATH=build/python:client/python /usr/bin/python3 \
        client/python/cablesim_client.py --server 127.0.0.1:50051 \
        scenes/falling-pendulum.json --png pendulum.png

streams a run into numpy arrays and plots the first probe's path and the
energy components to a PNG; `--animate cable.gif` also asks for the
cable's shape (Scene.output.shape) and draws the cables moving.
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

    def cable_nodes(self, cable):
        """The positions of cable `cable`'s nodes (its index in the scene)
        in every frame, as a frames x nodes x 3 array [m]: the columns
        cables[i].nodes[k].x, .y, .z that a scene with `output.shape: true`
        adds (README, "The cable's shape"). Raises ValueError without them."""
        prefix = "cables[%d].nodes[" % cable
        first = [i for i, name in enumerate(self.columns)
                 if name.startswith(prefix) and name.endswith("].x")]
        if not first:
            raise ValueError("no node columns for cables[%d]: run the scene with "
                             "output.shape: true" % cable)
        index = np.array([[i, self.columns.index(self.columns[i][:-1] + "y"),
                           self.columns.index(self.columns[i][:-1] + "z")] for i in first])
        return self.data[:, index]


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
    """A stub for the cablesim-server at `address` ("host:port"). `tls_ca`:
    a CA certificate file (PEM): TLS, the server's certificate checked
    against it. `token`: a bearer token sent with every call."""
    if tls_ca:
        with open(tls_ca, "rb") as f:
            channel = grpc.secure_channel(address, grpc.ssl_channel_credentials(f.read()))
    else:
        channel = grpc.insecure_channel(address)
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


def _frame_indices(t, times):
    """The frame nearest each of `times` (all frames when None)."""
    if times is None:
        return list(range(len(t)))
    return [int(np.argmin(np.abs(t - time))) for time in times]


def animate(result, path, times=None, fps=10, plane=("x", "y")):
    """Draws every cable of `result` (a run of a scene with
    `output.shape: true`) at the frames nearest `times` (default: every
    frame) and writes the animation to `path`: a GIF (matplotlib's
    PillowWriter, Debian's python3-pil), or an MP4 when `path` ends in
    .mp4 (matplotlib's FFMpegWriter; RuntimeError when ffmpeg is not
    installed). `plane` names the two world axes drawn. Returns the number
    of frames written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation

    axes = {"x": 0, "y": 1, "z": 2}
    a, b = axes[plane[0]], axes[plane[1]]
    cables = [result.cable_nodes(i) for i in range(len(result.info.cable_names))]
    t = result.column("t")
    frames = _frame_indices(t, times)
    fig, ax = plt.subplots(figsize=(6, 5))
    every = np.concatenate([c.reshape(-1, 3) for c in cables])
    lo, hi = every.min(axis=0), every.max(axis=0)
    pad = 0.05 * max(hi[a] - lo[a], hi[b] - lo[b], 1e-9)
    ax.set_xlim(lo[a] - pad, hi[a] + pad)
    ax.set_ylim(lo[b] - pad, hi[b] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(plane[0] + " [m]")
    ax.set_ylabel(plane[1] + " [m]")
    lines = [ax.plot([], [], "o-", markersize=2, label=name)[0]
             for name in result.info.cable_names]
    if len(lines) > 1:
        ax.legend()
    title = ax.set_title("")

    def draw(k):
        for line, nodes in zip(lines, cables):
            line.set_data(nodes[k, :, a], nodes[k, :, b])
        title.set_text("t = %.4g s" % t[k])
        return lines + [title]

    if path.endswith(".mp4"):
        if not animation.FFMpegWriter.isAvailable():
            plt.close(fig)
            raise RuntimeError("writing %s needs ffmpeg (apt-get install ffmpeg)" % path)
        writer = animation.FFMpegWriter(fps=fps)
    else:
        writer = animation.PillowWriter(fps=fps)
    movie = animation.FuncAnimation(fig, draw, frames=frames, blit=False)
    movie.save(path, writer=writer)
    plt.close(fig)
    return len(frames)


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
