"""Looking at motion: stick-figure GIFs (Pillow) and filmstrips (matplotlib, imported when drawn)."""

from __future__ import annotations

import numpy as np

from .atomic import atomic_path


def _bounds(positions_list):
    allp = np.concatenate([p.reshape(-1, 3) for p in positions_list])
    lo, hi = allp.min(0), allp.max(0)
    c = (lo + hi) / 2
    r = max(float(np.max(hi - lo)) / 2, 1e-6) * 1.05
    return c, r


def _segments(parents):
    return [(i, p) for i, p in enumerate(parents) if p >= 0]


def _camera(elev_deg: float = 10.0, azim_deg: float = -60.0) -> np.ndarray:
    """Orthographic camera (2, 3): rows are the screen's right and up axes in (x, z, y)-as-plotted order.

    The same view as matplotlib's ``view_init(elev, azim)`` on axes (x, z, up=y).
    """
    e, a = np.radians(elev_deg), np.radians(azim_deg)
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    up = np.array([-np.sin(e) * np.cos(a), -np.sin(e) * np.sin(a), np.cos(e)])
    return np.vstack([right, up])


def gif_timing(n: int, fps: float, step: int, max_frames: int, source_fps: float | None) -> tuple[int, float, float]:
    """The frame step, playback rate and speed-up of a GIF of ``n`` motion frames (see :func:`skeleton_gif`).

    Returns
    -------
    step : int
        Every ``step``-th motion frame is drawn (at most ``max_frames`` of them).
    fps : float
        GIF frames per second.
    speedup : float
        Playback speed over real time: 1 when the clip fits in real time (or ``source_fps`` is None); a clip
        too long for real time within ``max_frames`` is evenly subsampled and still played at about ``fps``
        frames per second, so ``speedup`` times faster (not as a slideshow).
    """
    if source_fps is None:
        return max(step, int(np.ceil(n / max_frames))), fps, 1.0
    real = max(1, int(round(source_fps / fps)))
    step = max(real, int(np.ceil(n / max_frames)))
    return step, source_fps / real, step / real


def skeleton_gif(path, positions_list, parents, titles=None, fps: float = 30.0, step: int = 4,
                 follow_root: bool = True, max_frames: int = 150, source_fps: float | None = None,
                 panel_px: int = 230) -> None:
    """Animated GIF of one or more stick figures side by side.

    Drawn with Pillow (orthographic projection, one line per bone), not with
    matplotlib's 3-D axes: a stick figure needs no axes, and Pillow draws a
    frame in well under a millisecond where a 3-D matplotlib redraw takes tens
    of milliseconds, which made GIFs the dominant cost of the re-sequencing jobs.

    Parameters
    ----------
    positions_list : list of arrays (frames, joints, 3), Y up
        E.g. ``[original, generated]``; shorter ones hold their last frame.
    parents : sequence of int, parent joint index (-1 for the root)
    titles : list of str
    fps : playback rate of the GIF (frames per second of the file, after ``step``)
    step : take every ``step``-th frame
    follow_root : centre each figure on its root horizontally (long walks stay in view)
    max_frames : cap on GIF frames (the step is increased to respect it)
    source_fps : frame rate of the motions; when given, the GIF plays in real
        time: ``step`` is chosen so that the GIF runs at about ``fps`` frames
        per second and its playback rate is ``source_fps / step``. A clip too
        long for that within ``max_frames`` is evenly subsampled (a larger
        ``step``) and still plays at about ``fps`` frames per second, so
        faster than real time, not as a slideshow: the titles then state the
        speed-up (``x4 speed``)
    panel_px : width and height of one figure's panel in pixels
    """
    from PIL import Image, ImageDraw

    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"GIF frame rate must be a positive number, got {fps!r}")
    positions_list = [np.asarray(p, float) for p in positions_list]
    n = max(p.shape[0] for p in positions_list)
    step, fps, speedup = gif_timing(n, fps, step, max_frames, source_fps)
    k = len(positions_list)
    titles = list(titles or [""] * k)
    if speedup > 1:
        titles = [f"{t} (x{speedup:.3g} speed)".strip() for t in titles]
    frames = list(range(0, n, step))
    segs = _segments(parents)
    shown = []
    for p in positions_list:
        q = p.copy()
        if follow_root:
            q[:, :, [0, 2]] -= q[:, :1, [0, 2]]
        shown.append(q)
    c, r = _bounds(shown)
    cam = _camera()
    top = 18  # title band
    scale = (panel_px - 10) / (2.0 * r * 1.2)
    # screen coordinates of every figure: (frames, joints, 2), y down
    screen = []
    for i, q in enumerate(shown):
        xzy = (q - c)[:, :, [0, 2, 1]]
        uv = xzy @ cam.T
        x = i * panel_px + panel_px / 2 + scale * uv[..., 0]
        y = top + (panel_px - top) / 2 - scale * uv[..., 1]
        screen.append(np.stack([x, y], axis=-1))
    # palette: 0 background, 1 bones, 2 titles, 3 panel separators
    palette = [255, 255, 255, 31, 119, 180, 0, 0, 0, 200, 200, 200] + [0] * (256 * 3 - 12)
    images = []
    for fi in frames:
        im = Image.new("P", (panel_px * k, panel_px), 0)
        im.putpalette(palette)
        draw = ImageDraw.Draw(im)
        for i, (s, t) in enumerate(zip(screen, titles)):
            if i:
                draw.line([(i * panel_px, 0), (i * panel_px, panel_px)], fill=3)
            draw.text((i * panel_px + 6, 3), str(t), fill=2)
            f = min(fi, s.shape[0] - 1)
            for a, b in segs:
                draw.line([tuple(s[f, a]), tuple(s[f, b])], fill=1, width=2)
        images.append(im)
    with atomic_path(path, suffix=".gif") as tmp:
        images[0].save(tmp, save_all=True, append_images=images[1:], duration=int(round(1000.0 / fps)), loop=0,
                       optimize=False)


def filmstrip(path, positions, parents, n_panels: int = 8, title: str = "") -> None:
    """PNG filmstrip: ``n_panels`` evenly spaced poses of one motion, side view."""
    import matplotlib.pyplot as plt

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
                    fps: float = 30.0, max_frames: int = 150) -> None:
    """Write the standard previews of a generated motion: BVH, GIF (beside ``original`` if given), filmstrip.

    The GIF plays in real time at ``motion.fps``, showing about ``fps`` frames per second; a clip longer than
    ``max_frames`` GIF frames is evenly subsampled and plays faster, its speed-up in the titles
    (:func:`skeleton_gif`). ``titles``: one per figure (default ``original``/``generated``).
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
        default_titles = ["original", "generated"] if original is not None else ["generated"]
        skeleton_gif(gif_path, plist, sk.parents(), titles or default_titles, fps=fps,
                     source_fps=motion.fps, max_frames=max_frames)
    if png_path:
        filmstrip(png_path, pos, sk.parents(), title=motion.name)
