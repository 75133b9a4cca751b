"""What the service returns, as Python values: trajectories and sweep tables
as numpy arrays (and pandas DataFrames when pandas is installed), jobs and
summaries with enums as names. Units are SI: s, m, m/s, m/s^2, J.
"""

import dataclasses
import datetime
from typing import Any, Dict, List, Optional

import numpy as np
from google.protobuf import descriptor


class Record(dict):
    """A message as a dict whose keys are also attributes
    (`summary["status"]` or `summary.status`); enums are names, repeated
    fields lists, nested messages Records."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def to_record(message) -> Record:
    """Every field of `message` (defaults included) as a Record."""
    record = Record()
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.label == descriptor.FieldDescriptor.LABEL_REPEATED:
            record[field.name] = [_value(field, v) for v in value]
        else:
            record[field.name] = _value(field, value)
    return record


def _value(field, value):
    if field.type == descriptor.FieldDescriptor.TYPE_MESSAGE:
        return to_record(value)
    if field.type == descriptor.FieldDescriptor.TYPE_ENUM:
        number = field.enum_type.values_by_number.get(value)
        return number.name if number is not None else value
    return value


def _pandas():
    try:
        import pandas
    except ImportError:
        raise ImportError("to_pandas() needs pandas (Debian: python3-pandas; "
                          "pip: cablesim[pandas])") from None
    return pandas


@dataclasses.dataclass
class Result:
    """A run's trajectory: `data` has one row per output frame and one column
    per name in `columns` (the CSV columns of `cablesim run --out`: t, then
    per probe NAME.x ... NAME.az, then energy.* and constraint.violation).
    `info` is the model built (ModelInfo), `summary` the run's summary
    (RunSummary; `summary.status` is "ok", "failed" or "cancelled")."""

    columns: List[str]
    data: np.ndarray
    info: Record
    summary: Record
    scene_name: str = ""

    def column(self, name: str) -> np.ndarray:
        """The column `name` (e.g. "t", "tip.x", "energy.total")."""
        try:
            return self.data[:, self.columns.index(name)]
        except ValueError:
            raise KeyError("no column %r (columns: %s)" % (name, ", ".join(self.columns))) from None

    __getitem__ = column

    @property
    def t(self) -> np.ndarray:
        """Time [s] of each frame (the load factor for STATIC and MODAL)."""
        return self.column("t")

    def position(self, probe: str) -> np.ndarray:
        """The probe's position [m], frames x 3 (x, y, z)."""
        return np.column_stack([self.column(probe + "." + c) for c in "xyz"])

    def to_pandas(self):
        """The trajectory as a pandas DataFrame with the same columns."""
        return _pandas().DataFrame(self.data, columns=self.columns)

    def _joint(self, joint) -> int:
        if isinstance(joint, int):
            return joint
        names = list(self.info.get("joint_names", []))
        if joint not in names:
            raise KeyError("no joint named %r (joint names: %s)" % (joint, ", ".join(names)))
        return names.index(joint)

    def reaction(self, joint) -> np.ndarray:
        """The force [N] joint `joint` (its index in the scene, or its name)
        carries, frames x 3: the columns joints[i].fx, .fy, .fz that a scene
        with `output.reactions: true` adds (the force the joint exerts on
        the cable or body it holds)."""
        i = self._joint(joint)
        return np.column_stack([self.column("joints[%d].f%s" % (i, c)) for c in "xyz"])

    def reaction_moment(self, joint) -> np.ndarray:
        """The moment [N m] a FIXED joint carries about its point, frames x 3
        (joints[i].mx, .my, .mz)."""
        i = self._joint(joint)
        return np.column_stack([self.column("joints[%d].m%s" % (i, c)) for c in "xyz"])

    def tension(self, probe: str) -> np.ndarray:
        """The axial force [N] at a cable probe (NAME.tension, with
        `output.tension: true`; compression is negative)."""
        return self.column(probe + ".tension")

    def bending_moment(self, probe: str) -> np.ndarray:
        """The bending moment [N m] at a cable probe (NAME.bending_moment,
        with `output.bending_moment: true`; planar: about z, spatial: its
        size)."""
        return self.column(probe + ".bending_moment")

    def cable_nodes(self, cable: int) -> np.ndarray:
        """The positions [m] of cable `cable`'s nodes (its index in the scene)
        in every frame, frames x nodes x 3: the columns cables[i].nodes[k].x,
        .y, .z that a scene with `output.shape: true` adds (README, "The
        cable's shape"). Raises ValueError without them."""
        prefix = "cables[%d].nodes[" % cable
        first = [i for i, name in enumerate(self.columns)
                 if name.startswith(prefix) and name.endswith("].x")]
        if not first:
            raise ValueError("no node columns for cables[%d]: run the scene with "
                             "output.shape: true" % cable)
        index = np.array([[i, self.columns.index(self.columns[i][:-1] + "y"),
                           self.columns.index(self.columns[i][:-1] + "z")] for i in first])
        return self.data[:, index]

    def plot(self, png_path: str, probe: Optional[str] = None, view: str = "xy",
             tension=None) -> None:
        """Plots the path of `probe` (default: the first) in the plane
        `view` names ("xy", "xz", "yz": the horizontal axis first; a
        mooring whose gravity is along z reads best in "xz"), the energy
        components against time, and with `tension` (True: every
        NAME.tension column; or a list of probe names) the tensions against
        time, to `png_path` (matplotlib, Agg)."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if len(view) != 2 or any(c not in "xyz" for c in view) or view[0] == view[1]:
            raise ValueError('view: two different axes of "xyz", e.g. "xz" (got %r)' % (view,))
        if tension is True:
            tension = [c[:-len(".tension")] for c in self.columns
                       if c.endswith(".tension") and not c.startswith("cables[")]
        tension = list(tension or [])
        if probe is None:
            names = getattr(self.info, "probe_names", None) or [self.columns[1].rsplit(".", 1)[0]]
            probe = names[0]
        panels = 3 if tension else 2
        fig, axes = plt.subplots(1, panels, figsize=(5.5 * panels, 4.5))
        path_ax, energy_ax = axes[0], axes[1]
        path_ax.plot(self.column(probe + "." + view[0]), self.column(probe + "." + view[1]))
        path_ax.set_xlabel(view[0] + " [m]")
        path_ax.set_ylabel(view[1] + " [m]")
        path_ax.set_title("path of " + probe)
        path_ax.set_aspect("equal", adjustable="datalim")
        for name in ("kinetic", "potential", "axial", "bending", "total"):
            energy_ax.plot(self.t, self.column("energy." + name), label=name)
        energy_ax.set_xlabel("t [s]")
        energy_ax.set_ylabel("energy [J]")
        energy_ax.legend()
        energy_ax.set_title("energy")
        if tension:
            tension_ax = axes[2]
            for name in tension:
                tension_ax.plot(self.t, self.tension(name), label=name)
            tension_ax.set_xlabel("t [s]")
            tension_ax.set_ylabel("tension [N]")
            tension_ax.legend()
            tension_ax.set_title("tension")
        fig.tight_layout()
        fig.savefig(png_path, dpi=100)
        plt.close(fig)


def load_csv(path: str, shape: Optional[str] = None) -> Result:
    """Reads the CSV of `cablesim run SCENE --out FILE.csv` (or `watch
    --out`) into a Result with the same columns and numbers as the service
    streams them (17 significant digits read back exactly). With `shape`,
    the shape CSV of the same run (`--shape FILE`, or FILE.shape.csv beside
    the output; rows t, cable, node, s, x, y, z[, tension]) adds the nodes'
    columns cables[i].nodes[k].x, .y, .z (and .tension) as the service's
    rows carry them, so that cable_nodes() and animate() work on it.
    `info` holds the cables' names as cables[i] and the nodes' arc lengths
    then; `summary` is empty: the CSVs carry the frames only."""
    with open(path) as f:
        columns = f.readline().strip().split(",")
    if columns == [""]:
        raise ValueError("%s: empty file, not a cablesim CSV" % path)
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.size == 0:
        data = np.zeros((0, len(columns)))
    if data.shape[1] != len(columns):
        raise ValueError("%s: %d columns in the header, %d in the rows"
                         % (path, len(columns), data.shape[1]))
    info = Record()
    if shape is not None:
        columns, data, info = _with_shape(path, columns, data, shape)
    return Result(columns=columns, data=data, info=info, summary=Record())


def _with_shape(path, columns, data, shape):
    """The frames' columns and rows with the shape CSV's nodes appended."""
    with open(shape) as f:
        header = f.readline().strip().split(",")
    if header[:7] != ["t", "cable", "node", "s", "x", "y", "z"]:
        raise ValueError("%s: not a cablesim shape CSV (its header is %s)"
                         % (shape, ",".join(header)))
    rows = np.loadtxt(shape, delimiter=",", skiprows=1, ndmin=2)
    with_tension = len(header) > 7 and header[7] == "tension"
    nodes = sorted({(int(c), int(k)) for c, k in rows[:, 1:3]}) if rows.size else []
    index = {node: i for i, node in enumerate(nodes)}
    per_node = 4 if with_tension else 3
    times = np.unique(rows[:, 0]) if rows.size else np.zeros(0)
    if len(times) != data.shape[0] or (len(times) and not np.array_equal(times, data[:, 0])):
        raise ValueError("%s: its %d times are not the %d frames of %s"
                         % (shape, len(times), data.shape[0], path))
    extra = np.zeros((data.shape[0], per_node * len(nodes)))
    frame_of = {t: i for i, t in enumerate(data[:, 0])}
    s = {}
    for row in rows:
        i, n = frame_of[row[0]], index[(int(row[1]), int(row[2]))]
        extra[i, 3 * n:3 * n + 3] = row[4:7]
        if with_tension:
            extra[i, 3 * len(nodes) + n] = row[7]
        s[n] = row[3]
    names = ["cables[%d].nodes[%d].%s" % (c, k, a) for c, k in nodes for a in "xyz"]
    if with_tension:
        names += ["cables[%d].nodes[%d].tension" % (c, k) for c, k in nodes]
    cables = sorted({c for c, _ in nodes})
    info = Record(cable_names=["cables[%d]" % c for c in cables],
                  node_s=[s[n] for n in range(len(nodes))])
    return columns + names, np.hstack([data, extra]), info


def result_from_events(events, on_time=None) -> Result:
    """Collects a Run (or GetJobResult) stream: header, frame batches,
    summary. `on_time(t)`: called with the last frame's time of each batch."""
    header, summary, chunks = None, None, []
    for event in events:
        kind = event.WhichOneof("event")
        if kind == "header":
            header = event.header
        elif kind == "frames":
            chunks.append(np.asarray(event.frames.values, dtype=np.float64))
            if on_time is not None and header is not None and len(chunks[-1]):
                on_time(float(chunks[-1][-len(header.columns)]))
        elif kind == "summary":
            summary = event.summary
    if header is None or summary is None:
        raise RuntimeError("the stream ended without a %s" % ("header" if header is None else "summary"))
    flat = np.concatenate(chunks) if chunks else np.zeros(0)
    return Result(columns=list(header.columns), data=flat.reshape(-1, len(header.columns)),
                  info=to_record(header.info), summary=to_record(summary),
                  scene_name=header.scene_name)


def _datetime(unix_ms: int) -> Optional[datetime.datetime]:
    """A time in milliseconds since the Unix epoch as an aware UTC datetime
    (None for 0: not yet)."""
    if not unix_ms:
        return None
    return datetime.datetime.fromtimestamp(unix_ms / 1000.0, tz=datetime.timezone.utc)


@dataclasses.dataclass
class Job:
    """A durable job. `state` is a name: "QUEUED", "RUNNING", "SUCCEEDED",
    "FAILED" or "CANCELLED"; `summary` is set once it finished. Times in
    milliseconds since the Unix epoch (0: not yet), and as datetimes in UTC
    (`created`, `started`, `finished_at`; None: not yet)."""

    id: str
    state: str
    name: str
    attempts: int
    progress_time_s: float
    end_time_s: float
    created_unix_ms: int
    started_unix_ms: int
    finished_unix_ms: int
    summary: Optional[Record]
    sweep_id: str
    sweep_index: int

    @property
    def finished(self) -> bool:
        return self.state in ("SUCCEEDED", "FAILED", "CANCELLED")

    @property
    def created(self) -> Optional[datetime.datetime]:
        return _datetime(self.created_unix_ms)

    @property
    def started(self) -> Optional[datetime.datetime]:
        return _datetime(self.started_unix_ms)

    @property
    def finished_at(self) -> Optional[datetime.datetime]:
        return _datetime(self.finished_unix_ms)

    @classmethod
    def from_message(cls, job) -> "Job":
        r = to_record(job)
        return cls(id=r.id, state=r.state, name=r.name, attempts=r.attempts,
                   progress_time_s=r.progress_time_s, end_time_s=r.end_time_s,
                   created_unix_ms=r.created_unix_ms, started_unix_ms=r.started_unix_ms,
                   finished_unix_ms=r.finished_unix_ms,
                   summary=r.summary if job.HasField("summary") else None,
                   sweep_id=r.sweep_id, sweep_index=r.sweep_index)


@dataclasses.dataclass
class Energy:
    """Energy diagnostics [J]: one entry per frame in each array, the
    `report` (EnergyReport: initial, final, min, max, relative_drift, scale,
    energy_dissipated, max_constraint_violation) and the run's `summary`."""

    t: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    axial: np.ndarray
    bending: np.ndarray
    total: np.ndarray
    constraint_violation: np.ndarray
    report: Record
    summary: Record

    @classmethod
    def from_message(cls, response) -> "Energy":
        arrays = {name: np.asarray(getattr(response, name), dtype=np.float64)
                  for name in ("t", "kinetic", "potential", "axial", "bending", "total",
                               "constraint_violation")}
        return cls(report=to_record(response.report), summary=to_record(response.summary), **arrays)

    def to_pandas(self):
        names = ("t", "kinetic", "potential", "axial", "bending", "total", "constraint_violation")
        return _pandas().DataFrame({n: getattr(self, n) for n in names})


# The per-item numbers of a sweep table, the columns of `cablesim sweep`'s
# CSV between the axes and the final values.
SWEEP_SUMMARY_COLUMNS = ("wall_seconds", "frames", "steps", "rejected_steps", "newton_iterations",
                         "end_time_s", "energy_initial", "energy_final", "energy_dissipated")


@dataclasses.dataclass
class SweepResult:
    """A sweep's table, one row per item in item order (the last axis
    varying fastest). `axis_values` is items x axes (columns `axis_paths`),
    `final` items x frame columns (`final_columns`: each item's last frame;
    NaN until the item finished), `states` the job states by name,
    `summaries` and `energy` the items' RunSummary and EnergyReport."""

    id: str
    name: str
    axis_paths: List[str]
    axis_values: np.ndarray
    job_ids: List[str]
    states: List[str]
    summaries: List[Record]
    energy: List[Record]
    final_columns: List[str]
    final: np.ndarray

    @property
    def items(self) -> int:
        return len(self.job_ids)

    def summary_column(self, name: str) -> np.ndarray:
        """One summary number per item, e.g. "wall_seconds", "steps"."""
        return np.array([float(s[name]) for s in self.summaries])

    @property
    def relative_drift(self) -> np.ndarray:
        return np.array([e.relative_drift for e in self.energy])

    def table(self) -> Dict[str, Any]:
        """The columns of `cablesim sweep --out` (index, job_id, state, the
        axis paths, status, error, the summary numbers,
        energy_relative_drift, max_constraint_violation, final.*), each a
        list or a numpy array."""
        columns: Dict[str, Any] = {"index": np.arange(self.items), "job_id": self.job_ids,
                                   "state": self.states}
        for k, path in enumerate(self.axis_paths):
            columns[path] = self.axis_values[:, k]
        columns["status"] = [s.status for s in self.summaries]
        columns["error"] = [s.error for s in self.summaries]
        for name in SWEEP_SUMMARY_COLUMNS:
            columns[name] = self.summary_column(name)
        columns["energy_relative_drift"] = self.relative_drift
        columns["max_constraint_violation"] = self.summary_column("max_constraint_violation")
        for k, name in enumerate(self.final_columns):
            columns["final." + name] = self.final[:, k]
        return columns

    def to_pandas(self):
        return _pandas().DataFrame(self.table())

    @classmethod
    def from_message(cls, results) -> "SweepResult":
        sweep = results.sweep
        ncol = len(results.final_columns)
        final = np.full((len(results.items), ncol), np.nan)
        for i, item in enumerate(results.items):
            if len(item.final_values) == ncol:
                final[i] = item.final_values
        return cls(
            id=sweep.id, name=sweep.name, axis_paths=[a.path for a in sweep.axes],
            axis_values=np.array([list(item.axis_values) for item in results.items],
                                 dtype=np.float64).reshape(len(results.items), len(sweep.axes)),
            job_ids=[item.job_id for item in results.items],
            states=[to_record(item).state for item in results.items],
            summaries=[to_record(item.summary) for item in results.items],
            energy=[to_record(item.energy) for item in results.items],
            final_columns=list(results.final_columns), final=final)
