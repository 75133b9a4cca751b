"""couple(): a coupling session (the Couple stream, docs/coupling.md).

The host program integrates its own bodies; cablesim advances the scene's
lines, whose coupled supports (joints with `coupled: true`) the host drives:

    with cablesim.couple("127.0.0.1:50051", "floater.json", x0) as session:
        f = session.forces                    # (n, 3) at t = 0 [N]
        for k in range(steps):
            ...                               # the host's step to x, v
            f = session.step(dt, x, v)        # mean forces over the step
"""

import queue
from typing import List, Optional, Tuple, Union

import grpc
import numpy as np

from cablesim.errors import Error
from cablesim.results import Record, to_record
from cablesim.scenes import SceneLike, load_scene
from cablesim.v1 import scene_pb2, service_pb2, service_pb2_grpc


def _points(positions, velocities, n=None) -> List[service_pb2.CoupledPoint]:
    x = np.asarray(positions, dtype=float).reshape(-1, 3)
    v = np.zeros_like(x) if velocities is None else np.asarray(velocities, float).reshape(-1, 3)
    if len(v) != len(x):
        raise ValueError("velocities: %d points, positions has %d" % (len(v), len(x)))
    return [service_pb2.CoupledPoint(position=scene_pb2.Vec3(x=p[0], y=p[1], z=p[2]),
                                      velocity=scene_pb2.Vec3(x=u[0], y=u[1], z=u[2]))
            for p, u in zip(x, v)]


def _array(vectors) -> np.ndarray:
    return np.array([[v.x, v.y, v.z] for v in vectors], dtype=float).reshape(-1, 3)


class CoupleSession:
    """A coupling session: made by couple() (or Client.couple()), closed by
    close() or at the end of a `with` block (the stream then ends).

    After open and after each step():
      time        the session's time [s]
      forces      (n, 3): per coupled point, the force [N] the lines exert on
                  it, their mean over the last step (the forces at t = 0
                  after open)
      end_forces  (n, 3): the forces at `time`
      steps, rejected_steps   the scene's own steps so far
      lines       with lines=True: [(name, nodes (k, 3), tensions (k,))]
    Set once, at open: model (a Record), coupled_joints, scene_positions
    (n, 3), max_jump_m, end_time_s (the scene's duration: the session ends
    there), warnings."""

    def __init__(self, stub, open_request: service_pb2.CoupleOpen, timeout: Optional[float],
                 channel_owned: Optional[grpc.Channel] = None):
        self._channel = channel_owned
        self._requests: "queue.Queue[Optional[service_pb2.CoupleRequest]]" = queue.Queue()
        self._closed = False

        def requests():
            while True:
                item = self._requests.get()
                if item is None:
                    return
                yield item

        self._call = stub.Couple(requests(), timeout=timeout)
        try:
            reply = self._exchange(service_pb2.CoupleRequest(open=open_request))
        except BaseException:
            self.close()
            raise
        self.model = to_record(reply.model)
        self.coupled_joints = list(reply.coupled_joints)
        self.scene_positions = _array(reply.scene_positions)
        self.max_jump_m = reply.max_jump_m
        self.end_time_s = reply.end_time_s
        self.warnings = list(reply.warnings)
        self._update(reply)

    @property
    def points(self) -> int:
        """The number of coupled points."""
        return len(self.coupled_joints)

    def _exchange(self, request) -> service_pb2.CoupleResponse:
        if self._closed:
            raise Error("FAILED_PRECONDITION", "the coupling session is closed")
        self._requests.put(request)
        try:
            return next(self._call)
        except grpc.RpcError as e:
            self._closed = True
            raise Error(e.code().name, e.details() or "") from None
        except StopIteration:
            self._closed = True
            raise Error("UNAVAILABLE", "the server ended the coupling session") from None

    def _update(self, reply) -> None:
        self.time = reply.time_s
        self.forces = _array(reply.forces)
        self.end_forces = _array(reply.end_forces)
        self.steps = reply.steps
        self.rejected_steps = reply.rejected_steps
        self.lines: List[Tuple[str, np.ndarray, np.ndarray]] = [
            (line.name, _array(line.nodes), np.array(line.tensions, dtype=float))
            for line in reply.lines]

    def step(self, dt: float, positions, velocities=None) -> np.ndarray:
        """Advances the session by `dt` [s] with the coupled points at
        `positions` (n x 3 [m]) and `velocities` (n x 3 [m/s], default 0)
        at its end; returns the lines' forces on them, their mean over the
        step (n x 3 [N]). Bad input raises Error (code INVALID_ARGUMENT,
        `field` e.g. "points[2].position.x") and leaves the session as it
        was: it stays usable. A step the lines cannot take raises Error
        ABORTED and ends the session."""
        request = service_pb2.CoupleRequest(step=service_pb2.CoupleStep(
            dt_s=float(dt), points=_points(positions, velocities)))
        reply = self._exchange(request)
        if reply.HasField("error"):
            e = reply.error
            details = "%s: %s" % (e.path, e.message) if e.path else e.message
            raise Error(e.code or "INVALID_ARGUMENT", details, e.path or None)
        self._update(reply)
        return self.forces

    def close(self) -> None:
        """Ends the session (the client's side of the stream closes; the
        server frees the session)."""
        if not self._closed:
            self._closed = True
            self._requests.put(None)
            try:
                for _ in self._call:
                    pass
            except grpc.RpcError:
                pass
        else:
            self._requests.put(None)
        if self._channel is not None:
            self._channel.close()
            self._channel = None

    def __enter__(self) -> "CoupleSession":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def couple(server: Union[str, "Client", grpc.Channel], scene: SceneLike, positions,
           velocities=None, *, lines: bool = False, strict: bool = False,
           timeout: Optional[float] = None, **channel_options) -> CoupleSession:
    """Opens a coupling session of `scene` (anything load_scene() reads; a
    DYNAMIC scene with coupled supports) on `server` (a "host:port" target,
    whose channel the session opens and closes (`channel_options`: those of
    open_channel(), e.g. token=...), a Client, or a grpc.Channel), with the
    coupled points at `positions` (n x 3 [m], one per coupled support in
    scene order of the joints) and `velocities` (default 0) at t = 0.
    `lines`: each step also returns every cable's nodes and tensions
    (session.lines). `timeout`: a deadline for the whole session [s].
    Raises Error when the server refuses the scene (INVALID_ARGUMENT naming
    the field, RESOURCE_EXHAUSTED naming the limit)."""
    from cablesim.client import Client, open_channel
    owned = None
    if isinstance(server, Client):
        stub = server.stub
    elif isinstance(server, grpc.Channel):
        stub = service_pb2_grpc.CablesimServiceStub(server)
    else:
        owned = open_channel(server, **channel_options)
        stub = service_pb2_grpc.CablesimServiceStub(owned)
    try:
        request = service_pb2.CoupleOpen(scene=load_scene(scene), strict=strict, lines=lines,
                                         points=_points(positions, velocities))
    except BaseException:
        if owned is not None:
            owned.close()
        raise
    return CoupleSession(stub, request, timeout, owned)
