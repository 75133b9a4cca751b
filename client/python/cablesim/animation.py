"""Drawing a run's cables: an animation of the nodes that a scene with
`output.shape: true` writes (Result.cable_nodes)."""

import numpy as np


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
