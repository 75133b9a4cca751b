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


def _bodies(bodies) -> List[service_pb2.CoupledBody]:
    """Each body as (position, orientation[, velocity[, angular_velocity]]):
    position (3,) [m], orientation (4,) a unit quaternion (w, x, y, z),
    velocity (3,) [m/s] and angular_velocity (3,) [rad/s, world axes],
    default 0 (or a dict with those keys)."""
    out = []
    for b in bodies or []:
        if isinstance(b, dict):
            b = (b["position"], b["orientation"], b.get("velocity"), b.get("angular_velocity"))
        b = tuple(b) + (None,) * (4 - len(b))
        x, q, v, w = (None if a is None else np.asarray(a, dtype=float).reshape(-1) for a in b)
        v = np.zeros(3) if v is None else v
        w = np.zeros(3) if w is None else w
        out.append(service_pb2.CoupledBody(
            position=scene_pb2.Vec3(x=x[0], y=x[1], z=x[2]),
            orientation=service_pb2.Quaternion(w=q[0], x=q[1], y=q[2], z=q[3]),
            velocity=scene_pb2.Vec3(x=v[0], y=v[1], z=v[2]),
            angular_velocity=scene_pb2.Vec3(x=w[0], y=w[1], z=w[2])))
    return out


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
      body_forces, body_moments   (m, 3): per coupled body, the force [N]
                  and the moment [N m] (about its centre, world axes) the
                  lines exert on it, their mean over the last step
      body_end_forces, body_end_moments   the same at `time`
      host_work   the work the host has done on the scene since open [J]
      energy, dissipated   the scene's mechanical energy now (without the
                  coupled bodies' own) and the work done against damping
                  since open [J] (docs/coupling.md, "Energy at the fairleads")
    Set once, at open: model (a Record), coupled_joints, scene_positions
    (n, 3), coupled_bodies, body_scene_positions (m, 3),
    body_scene_orientations (m, 4: w, x, y, z), max_jump_m, end_time_s (the
    scene's duration: the session ends there), warnings."""

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
        self.coupled_bodies = list(reply.coupled_bodies)
        self.body_scene_positions = _array(reply.body_scene_positions)
        self.body_scene_orientations = np.array(
            [[q.w, q.x, q.y, q.z] for q in reply.body_scene_orientations],
            dtype=float).reshape(-1, 4)
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
        self.body_forces = _array(reply.body_forces)
        self.body_moments = _array(reply.body_moments)
        self.body_end_forces = _array(reply.body_end_forces)
        self.body_end_moments = _array(reply.body_end_moments)
        self.host_work = reply.host_work_j
        self.energy = reply.energy_j
        self.dissipated = reply.dissipated_j
        self.lines: List[Tuple[str, np.ndarray, np.ndarray]] = [
            (line.name, _array(line.nodes), np.array(line.tensions, dtype=float))
            for line in reply.lines]

    def step(self, dt: float, positions=None, velocities=None, bodies=None) -> np.ndarray:
        """Advances the session by `dt` [s] with the coupled points at
        `positions` (n x 3 [m]; None when there are none) and `velocities`
        (n x 3 [m/s], default 0) and the coupled bodies at `bodies` (one
        (position, orientation[, velocity[, angular_velocity]]) per coupled
        body, as couple() takes them) at its end; returns the lines' forces
        on the points, their mean over the step (n x 3 [N]; the bodies'
        are in body_forces and body_moments). Bad input raises Error (code
        INVALID_ARGUMENT, `field` e.g. "points[2].position.x",
        "bodies[0].orientation") and leaves the session as it was: it stays
        usable. A step the lines cannot take raises Error ABORTED and ends
        the session."""
        positions = np.zeros((0, 3)) if positions is None else positions
        request = service_pb2.CoupleRequest(step=service_pb2.CoupleStep(
            dt_s=float(dt), points=_points(positions, velocities), bodies=_bodies(bodies)))
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


def couple(server: Union[str, "Client", grpc.Channel], scene: SceneLike, positions=None,
           velocities=None, *, bodies=None, lines: bool = False, strict: bool = False,
           timeout: Optional[float] = None, **channel_options) -> CoupleSession:
    """Opens a coupling session of `scene` (anything load_scene() reads; a
    DYNAMIC scene with coupled supports) on `server` (a "host:port" target,
    whose channel the session opens and closes (`channel_options`: those of
    open_channel(), e.g. token=...), a Client, or a grpc.Channel), with the
    coupled points at `positions` (n x 3 [m], one per coupled support in
    scene order of the joints; None when there are none) and `velocities`
    (default 0) at t = 0, and the coupled bodies (Body.coupled) at `bodies`:
    one (position (3,), orientation (4,) unit quaternion w, x, y, z[,
    velocity (3,)[, angular_velocity (3,)]]) per coupled body in scene order
    (or a dict with those keys), the orientation's matrix having the body's
    axes as columns (absolute; session.body_scene_orientations is the
    scene's).
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
        positions = np.zeros((0, 3)) if positions is None else positions
        request = service_pb2.CoupleOpen(scene=load_scene(scene), strict=strict, lines=lines,
                                         points=_points(positions, velocities),
                                         bodies=_bodies(bodies))
    except BaseException:
        if owned is not None:
            owned.close()
        raise
    return CoupleSession(stub, request, timeout, owned)
