"""Looking at motion: stick-figure GIFs and filmstrips (matplotlib, Agg)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.animation import FuncAnimation, PillowWriter  # noqa: E402

from .io.atomic import atomic_path  # noqa: E402


def _bounds(positions_list):
    allp = np.concatenate([p.reshape(-1, 3) for p in positions_list])
    lo, hi = allp.min(0), allp.max(0)
    c = (lo + hi) / 2
    r = max(float(np.max(hi - lo)) / 2, 1e-6) * 1.05
    return c, r


def _segments(parents):
    return [(i, p) for i, p in enumerate(parents) if p >= 0]


def skeleton_gif(path, positions_list, parents, titles=None, fps: float = 30.0, step: int = 4,
                 follow_root: bool = True, max_frames: int = 150, source_fps: float | None = None) -> None:
    """Animated GIF of one or more stick figures side by side.

    Parameters
    ----------
    positions_list : list of arrays (frames, joints, 3), Y up
        E.g. ``[original, generated]``; shorter ones hold their last frame.
    parents : sequence of int, parent joint index (-1 for the root)
    titles : list of str
    fps : playback rate of the GIF
    step : take every ``step``-th frame
    follow_root : centre each figure on its root horizontally (long walks stay in view)
    max_frames : cap on GIF frames (the step is increased to respect it)
    source_fps : frame rate of the motions; when given, the GIF plays in real
        time: ``step`` is chosen so that the GIF runs at about ``fps`` frames
        per second (or slower, within ``max_frames``) and its playback rate is
        ``source_fps / step``
    """
    positions_list = [np.asarray(p, float) for p in positions_list]
    n = max(p.shape[0] for p in positions_list)
    if source_fps is not None:
        step = max(1, int(round(source_fps / fps)))
    step = max(step, int(np.ceil(n / max_frames)))
    if source_fps is not None:
        fps = source_fps / step
    frames = list(range(0, n, step))
    k = len(positions_list)
    titles = titles or [""] * k
    fig = plt.figure(figsize=(3.2 * k, 3.4), dpi=72)
    axes = [fig.add_subplot(1, k, i + 1, projection="3d") for i in range(k)]
    segs = _segments(parents)
    shown = []
    for p in positions_list:
        q = p.copy()
        if follow_root:
            q[:, :, [0, 2]] -= q[:, :1, [0, 2]]
        shown.append(q)
    c, r = _bounds(shown)
    lines = []
    for ax, t in zip(axes, titles):
        ax.set_title(t, fontsize=9)
        ax.set_xlim(c[0] - r, c[0] + r)
        ax.set_ylim(c[2] - r, c[2] + r)
        ax.set_zlim(c[1] - r, c[1] + r)
        ax.set_xticks([]), ax.set_yticks([]), ax.set_zticks([])
        ax.view_init(elev=10, azim=-60)
        lines.append([ax.plot([], [], [], "-", lw=2, color="tab:blue")[0] for _ in segs])

    def draw(fi):
        for q, ls in zip(shown, lines):
            f = min(fi, q.shape[0] - 1)
            for (a, b), ln in zip(segs, ls):
                ln.set_data([q[f, a, 0], q[f, b, 0]], [q[f, a, 2], q[f, b, 2]])
                ln.set_3d_properties([q[f, a, 1], q[f, b, 1]])
        return [ln for ls in lines for ln in ls]

    anim = FuncAnimation(fig, draw, frames=frames, blit=False)
    with atomic_path(path, suffix=".gif") as tmp:
        anim.save(tmp, writer=PillowWriter(fps=fps))
    plt.close(fig)


def filmstrip(path, positions, parents, n_panels: int = 8, title: str = "") -> None:
    """PNG filmstrip: ``n_panels`` evenly spaced poses of one motion, side view."""
    positions = np.asarray(positions, float)
    # side view: project onto the main horizontal direction of travel (or z)
    disp = positions[:, 0, [0, 2]] - positions[0, 0, [0, 2]]
    fwd = np.array([0.0, 1.0])
    if np.linalg.norm(disp[-1]) > 1e-6:
        fwd = np.linalg.svd(disp - disp.mean(0), full_matrices=False)[2][0]
    positions = positions.copy()
    positions[:, :, 2] = positions[:, :, 0] * fwd[0] + positions[:, :, 2] * fwd[1]
    idx = np.linspace(0, positions.shape[0] - 1, n_panels).round().astype(int)
    fig, ax = plt.subplots(figsize=(1.6 * n_panels, 2.6), dpi=100)
    segs = _segments(parents)
    span = 0.0
    for k, f in enumerate(idx):
        q = positions[f].copy()
        q[:, [0, 2]] -= q[:1, [0, 2]]
        off = k * 1.0 * max(np.ptp(positions[:, :, 1]), 1e-6)
        for a, b in segs:
            ax.plot([q[a, 2] + off, q[b, 2] + off], [q[a, 1], q[b, 1]], "-", color="tab:blue", lw=1.5)
        span = off
        ax.text(off, positions[:, :, 1].min() - 0.05 * np.ptp(positions[:, :, 1]), f"{f}", ha="center", fontsize=7)
    ax.set_aspect("equal")
    ax.set_xlim(-0.6 * np.ptp(positions[:, :, 1]), span + 0.6 * np.ptp(positions[:, :, 1]))
    ax.axis("off")
    if title:
        ax.set_title(title, fontsize=9)
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, bbox_inches="tight")
    plt.close(fig)


def motion_previews(motion, gif_path=None, bvh_path=None, png_path=None, original=None, titles=None,
                    fps: float = 30.0) -> None:
    """Write the standard previews of a generated motion: BVH, GIF (beside ``original`` if given), filmstrip.

    The GIF plays in real time at ``motion.fps``, showing about ``fps`` frames per second.
    """
    from .io.bvh import write_bvh
    from .kinematics import forward_kinematics

    sk = motion.skeleton
    pos = forward_kinematics(sk, motion.values) * sk.length_to_m
    if bvh_path:
        write_bvh(bvh_path, motion)
    if gif_path:
        plist = [pos]
        if original is not None:
            plist = [forward_kinematics(original.skeleton, original.values) * original.skeleton.length_to_m, pos]
        skeleton_gif(gif_path, plist, sk.parents(), titles or (["original", "generated"] if original is not None else ["generated"]), fps=fps,
                     source_fps=motion.fps)
    if png_path:
        filmstrip(png_path, pos, sk.parents(), title=motion.name)
