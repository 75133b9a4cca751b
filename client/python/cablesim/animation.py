"""Drawing a run's cables: an animation of the nodes that a scene with
`output.shape: true` writes (Result.cable_nodes), with the scene's bodies,
seabed and water line when the scene is given."""

import json

import numpy as np

_AXES = {"x": 0, "y": 1, "z": 2}


def _frame_indices(t, times):
    """The frame nearest each of `times` (all frames when None)."""
    if times is None:
        return list(range(len(t)))
    return [int(np.argmin(np.abs(t - time))) for time in times]


def scene_overlays(scene, plane):
    """What animate() draws from the scene besides the cables, in the plane
    `plane` (two axis names): {"seabed": height or None, "water": height or
    None, "bodies": [(body, probe), ...]}. The seabed (a flat `seabed.depth`
    below the water level) and the still water level (`fluid.still_water_level`,
    with a fluid of density > 0) are horizontal lines at their height on the
    plane's vertical axis, the one along gravity; they are drawn only when
    that axis is in the plane. Bodies are drawn at the probes on them.
    `scene`: a scene dict or a path to a JSON scene."""
    if isinstance(scene, str):
        with open(scene) as f:
            scene = json.load(f)
    elif hasattr(scene, "DESCRIPTOR"):  # a scene_pb2.Scene
        from google.protobuf import json_format
        scene = json_format.MessageToDict(scene, preserving_proto_field_name=True)
    gravity = scene.get("gravity", {})
    g = [abs(float(gravity.get(a, 0))) for a in "xyz"]
    up = "xyz"[int(np.argmax(g))] if max(g) > 0 else None
    out = {"seabed": None, "water": None, "bodies": [], "up": up}
    fluid = scene.get("fluid", {})
    water = float(fluid.get("still_water_level", 0))
    if up in plane:
        if float(fluid.get("density", 0)) > 0:
            out["water"] = water
        seabed = scene.get("seabed", {})
        if "depth" in seabed:
            out["seabed"] = water - float(seabed["depth"])
    for probe in scene.get("probes", []):
        if probe.get("body"):
            out["bodies"].append((probe["body"], probe["name"]))
    return out


def animate(result, path, times=None, fps=10, plane=("x", "y"), scene=None):
    """Draws every cable of `result` (a run of a scene with
    `output.shape: true`) at the frames nearest `times` (default: every
    frame) and writes the animation to `path`: a GIF (matplotlib's
    PillowWriter, Debian's python3-pil), or an MP4 when `path` ends in
    .mp4 (matplotlib's FFMpegWriter; RuntimeError when ffmpeg is not
    installed). `plane` names the two world axes drawn ("xz" or ("x",
    "z")). With `scene` (the run's scene, a dict or a JSON path) the bodies
    are drawn at the probes on them, with the seabed and the still water
    line (scene_overlays). Returns the number of frames written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation

    plane = tuple(plane)
    a, b = _AXES[plane[0]], _AXES[plane[1]]
    cables = [result.cable_nodes(i) for i in range(len(result.info.cable_names))]
    extra = scene_overlays(scene, plane) if scene is not None else None
    t = result.column("t")
    frames = _frame_indices(t, times)
    fig, ax = plt.subplots(figsize=(6, 5))
    points = [c.reshape(-1, 3) for c in cables]
    bodies = []
    if extra:
        for body, probe in extra["bodies"]:
            xyz = np.column_stack([result.column(probe + "." + c) for c in "xyz"])
            bodies.append((body, xyz))
            points.append(xyz)
    every = np.concatenate(points)
    lo, hi = every.min(axis=0), every.max(axis=0)
    if extra:
        vertical = _AXES[extra["up"]] if extra["up"] else None
        for level in (extra["seabed"], extra["water"]):
            if level is not None and vertical is not None:
                lo[vertical], hi[vertical] = min(lo[vertical], level), max(hi[vertical], level)
    pad = 0.05 * max(hi[a] - lo[a], hi[b] - lo[b], 1e-9)
    ax.set_xlim(lo[a] - pad, hi[a] + pad)
    ax.set_ylim(lo[b] - pad, hi[b] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel(plane[0] + " [m]")
    ax.set_ylabel(plane[1] + " [m]")
    lines = [ax.plot([], [], "o-", markersize=2, label=name)[0]
             for name in result.info.cable_names]
    if extra:
        # A level on the plane's vertical axis: a horizontal line when that
        # axis is drawn upwards (the plane's second), a vertical one if first.
        for level, style, label in ((extra["seabed"], "-", "seabed"),
                                    (extra["water"], "--", "water line")):
            if level is None:
                continue
            if extra["up"] == plane[1]:
                ax.axhline(level, color="tab:brown" if label == "seabed" else "tab:blue",
                           linestyle=style, label=label)
            else:
                ax.axvline(level, color="tab:brown" if label == "seabed" else "tab:blue",
                           linestyle=style, label=label)
    markers = [ax.plot([], [], "s", markersize=8, label=body)[0] for body, _ in bodies]
    if len(lines) + len(markers) > 1 or extra:
        ax.legend()
    title = ax.set_title("")

    def draw(k):
        for line, nodes in zip(lines, cables):
            line.set_data(nodes[k, :, a], nodes[k, :, b])
        for marker, (_, xyz) in zip(markers, bodies):
            marker.set_data([xyz[k, a]], [xyz[k, b]])
        title.set_text("t = %.4g s" % t[k])
        return lines + markers + [title]

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
