"""Client(target): the calls of the cablesim service
(proto/cablesim/v1/service.proto) as typed Python methods."""

import collections
import functools
import json
import os
from typing import Iterable, Mapping, Optional, Sequence, Tuple, Union

import grpc

from cablesim.errors import Error
from cablesim.progress import Progress, Reporter
from cablesim.results import Energy, Job, Record, Result, SweepResult, result_from_events, to_record
from cablesim.scenes import SceneLike, load_scene
from cablesim.v1 import service_pb2, service_pb2_grpc


def _raises_error(method):
    @functools.wraps(method)
    def wrapped(*args, **kwargs):
        try:
            return method(*args, **kwargs)
        except grpc.RpcError as e:
            raise Error(e.code().name, e.details() or "") from None
    return wrapped


class _CallDetails(collections.namedtuple(
        "_CallDetails", ("method", "timeout", "metadata", "credentials", "wait_for_ready",
                         "compression")), grpc.ClientCallDetails):
    pass


class _BearerToken(grpc.UnaryUnaryClientInterceptor, grpc.UnaryStreamClientInterceptor,
                   grpc.StreamStreamClientInterceptor):
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

    def intercept_stream_stream(self, continuation, details, request_iterator):
        return continuation(self._details(details), request_iterator)


def read_token(path: str) -> str:
    """The token in a token file: the first word of its first line that is
    not a # comment (as `cablesim --token-file`)."""
    with open(path) as f:
        for line in f:
            line = line.strip()
            if line and not line.startswith("#"):
                return line.split()[0]
    raise ValueError("%s: no token" % path)


# A call that fails UNAVAILABLE before any answer came back (a server that
# stopped while the channel still had its connection) is tried again, on the
# next server, up to twice: gRPC's retry policy, as the command line's
# channel does (client/service_client.cc). A SubmitJob whose server died
# between storing the job and answering can so leave one job more.
_RETRY_SERVICE_CONFIG = json.dumps({"methodConfig": [{
    "name": [{"service": "cablesim.v1.CablesimService"}],
    "retryPolicy": {"maxAttempts": 3, "initialBackoff": "0.1s", "maxBackoff": "1s",
                    "backoffMultiplier": 2, "retryableStatusCodes": ["UNAVAILABLE"]}}]})


def open_channel(target: str, tls_ca: Optional[str] = None, token: Optional[str] = None,
                 options: Sequence[Tuple[str, object]] = ()) -> grpc.Channel:
    """A channel to `target`: "host:port", or any gRPC target naming several
    servers ("ipv4:127.0.0.1:50051,127.0.0.1:50052", "dns:///cablesim:50051"),
    whose addresses are used in turn (gRPC's round_robin policy). `tls_ca`: a
    CA certificate file (PEM) the server's certificate is checked against.
    `token`: a bearer token sent with every call."""
    options = [("grpc.lb_policy_name", "round_robin"),
               ("grpc.service_config", _RETRY_SERVICE_CONFIG)] + list(options)
    if tls_ca:
        with open(tls_ca, "rb") as f:
            channel = grpc.secure_channel(target, grpc.ssl_channel_credentials(f.read()), options)
    else:
        channel = grpc.insecure_channel(target, options)
    if token:
        channel = grpc.intercept_channel(channel, _BearerToken(token))
    return channel


# Axes of a sweep: {path: values} or [(path, values), ...], e.g.
# {"cables[0].elements": [6, 12], "solver.step": [1e-4, 5e-5]}.
Axes = Union[Mapping[str, Iterable[float]], Iterable[Tuple[str, Iterable[float]]]]


class Client:
    """The cablesim service at `target` (see open_channel()). Methods raise
    Error for a refused call (INVALID_ARGUMENT naming the scene's field,
    NOT_FOUND, ...). Scenes are anything load_scene() reads: a dict, a JSON
    or text-format file name, JSON text or a Scene.

        with cablesim.Client("127.0.0.1:50051") as client:
            result = client.run("scenes/falling-pendulum.json")
            result["tip.y"]          # numpy array, one value per frame
    """

    def __init__(self, target: str = "127.0.0.1:50051", *, tls_ca: Optional[str] = None,
                 token: Optional[str] = None, token_file: Optional[str] = None,
                 options: Sequence[Tuple[str, object]] = ()):
        if token_file:
            token = read_token(token_file)
        self.target = target
        self.channel = open_channel(target, tls_ca=tls_ca, token=token, options=options)
        self.stub = service_pb2_grpc.CablesimServiceStub(self.channel)

    def close(self) -> None:
        self.channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @_raises_error
    def info(self, timeout: Optional[float] = None) -> Record:
        """The server's version, build and limits (ServerInfo)."""
        return to_record(self.stub.GetServerInfo(service_pb2.GetServerInfoRequest(),
                                                 timeout=timeout))

    @_raises_error
    def validate(self, scene: SceneLike) -> Record:
        """The verdict on a scene without running it: `valid`, the `model`
        the engine would build, or the first invalid field in `errors`."""
        return to_record(self.stub.Validate(service_pb2.ValidateRequest(scene=load_scene(scene))))

    @_raises_error
    def run(self, scene: SceneLike, *, frames_per_batch: int = 256,
            timeout: Optional[float] = None, progress: Progress = None) -> Result:
        """Runs `scene` and returns its trajectory. A numerical failure is not
        an error: `result.summary.status` is "failed" with the reason.
        `progress`: True for a bar (tqdm when installed), or a function
        called with (simulated seconds done, end time) as frames arrive (for
        STATIC, the load factor out of 1)."""
        message = load_scene(scene)
        request = service_pb2.RunRequest(scene=message, frames_per_batch=frames_per_batch)
        if not progress:
            return result_from_events(self.stub.Run(request, timeout=timeout))
        static = message.solver.analysis == message.solver.STATIC
        total = 1.0 if static else (message.solver.duration or None)
        reporter = Reporter(progress, "s", total, message.name)
        try:
            return result_from_events(self.stub.Run(request, timeout=timeout), reporter.update)
        finally:
            reporter.close()

    @_raises_error
    def submit(self, scene: SceneLike) -> str:
        """Queues `scene` as a durable job; returns its id at once."""
        return self.stub.SubmitJob(service_pb2.SubmitJobRequest(scene=load_scene(scene))).id

    @_raises_error
    def job(self, job_id: str) -> Job:
        """The job now."""
        return Job.from_message(self.stub.GetJob(service_pb2.GetJobRequest(id=job_id)))

    @_raises_error
    def wait(self, job_id: str, timeout: Optional[float] = None,
             progress: Progress = None) -> Job:
        """Follows the job until it finished; returns it (state SUCCEEDED,
        FAILED or CANCELLED). `progress` as for run(): simulated seconds."""
        job = None
        reporter = Reporter(progress, "s", None, job_id) if progress else None
        try:
            for job in self.stub.WatchJob(service_pb2.WatchJobRequest(id=job_id), timeout=timeout):
                if reporter is not None and job.end_time_s > 0:
                    reporter.update(job.progress_time_s, job.end_time_s)
        finally:
            if reporter is not None:
                reporter.close()
        return Job.from_message(job)

    @_raises_error
    def result(self, job_id: str, timeout: Optional[float] = None) -> Result:
        """A finished job's trajectory and summary, as run() returns them."""
        return result_from_events(self.stub.GetJobResult(
            service_pb2.GetJobResultRequest(id=job_id, frames_per_batch=256), timeout=timeout))

    @_raises_error
    def cancel(self, job_id: str) -> Job:
        """Cancels a queued or running job."""
        return Job.from_message(self.stub.CancelJob(service_pb2.CancelJobRequest(id=job_id)))

    @_raises_error
    def energy(self, source: Union[SceneLike, Job], timeout: Optional[float] = None) -> Energy:
        """Energy diagnostics of a finished job (a Job, or an id `j-...`) or of
        a scene, run for the purpose."""
        if isinstance(source, Job):
            request = service_pb2.EnergyRequest(job_id=source.id)
        elif isinstance(source, str) and source.startswith("j-") and not os.path.exists(source):
            request = service_pb2.EnergyRequest(job_id=source)
        else:
            request = service_pb2.EnergyRequest(scene=load_scene(source))
        return Energy.from_message(self.stub.GetEnergy(request, timeout=timeout))

    @_raises_error
    def submit_sweep(self, base: SceneLike, axes: Axes, name: str = "") -> str:
        """Queues the cartesian product of `axes` over the `base` scene, one
        job per item (the last axis varying fastest); returns the sweep id."""
        pairs = axes.items() if isinstance(axes, Mapping) else axes
        request = service_pb2.SubmitSweepRequest(
            name=name, base=load_scene(base),
            axes=[service_pb2.SweepAxis(path=path, values=[float(v) for v in values])
                  for path, values in pairs])
        return self.stub.SubmitSweep(request).id

    @_raises_error
    def sweep_results(self, sweep_id: str) -> SweepResult:
        """The sweep's table so far."""
        return SweepResult.from_message(
            self.stub.GetSweepResults(service_pb2.GetSweepResultsRequest(id=sweep_id)))

    @_raises_error
    def wait_sweep(self, sweep_id: str, timeout: Optional[float] = None,
                   progress: Progress = None) -> SweepResult:
        """Follows the sweep until every item finished; returns its table.
        `progress`: True for a bar (tqdm when installed), or a function
        called with (items finished, items)."""
        reporter = Reporter(progress, "item", None, sweep_id) if progress else None
        try:
            for event in self.stub.WatchSweep(service_pb2.WatchSweepRequest(id=sweep_id),
                                              timeout=timeout):
                if reporter is not None:
                    reporter.update(event.progress.finished, event.progress.items)
        finally:
            if reporter is not None:
                reporter.close()
        return self.sweep_results(sweep_id)

    def couple(self, scene: SceneLike, positions, velocities=None, *, lines: bool = False,
               strict: bool = False, timeout: Optional[float] = None):
        """A coupling session of `scene` (cablesim.couple(), on this
        client's channel): step(dt, positions, velocities) -> forces."""
        from cablesim.coupling import couple
        return couple(self, scene, positions, velocities, lines=lines, strict=strict,
                      timeout=timeout)

    def sweep(self, base: SceneLike, axes: Axes, name: str = "",
              timeout: Optional[float] = None, progress: Progress = None) -> SweepResult:
        """Queues a sweep (see submit_sweep()) and waits for its table."""
        return self.wait_sweep(self.submit_sweep(base, axes, name), timeout=timeout,
                               progress=progress)
