"""Figures of the facegraph family (matplotlib): region graphs, trajectories, animated GIF."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.collections import LineCollection

from ..atomic import atomic_path
from ..io.ckplus import EMOTIONS

#: Polylines of the 68-point face (closed ones repeat their first point).
FACE_LINES = [
    list(range(0, 17)), list(range(17, 22)), list(range(22, 27)), list(range(27, 31)), list(range(31, 36)),
    list(range(36, 42)) + [36], list(range(42, 48)) + [42], list(range(48, 60)) + [48], list(range(60, 68)) + [60],
]
_COLORS = plt.get_cmap("tab10")


def _emotion_color(e: int):
    return _COLORS(e % 10)


def draw_region_graphs(path, graphs: dict, title: str = "") -> None:
    """One panel per region graph: nodes placed by the first two principal
    components of their mean displacements (reduced landmarks), coloured by the
    label of the samples peaking there (grey: not a peak node), area ~ poses."""
    fig, axes = plt.subplots(1, len(graphs), figsize=(3.6 * len(graphs), 3.8), dpi=90)
    axes = np.atleast_1d(axes)
    for ax, (r, g) in zip(axes, graphs.items()):
        X = g.disp[:, g.red].reshape(g.n_nodes, -1)
        Xc = X - X.mean(0)
        if g.n_nodes >= 2 and np.any(Xc):
            _, _, vt = np.linalg.svd(Xc, full_matrices=False)
            P = Xc @ vt[:2].T
            if P.shape[1] < 2:
                P = np.c_[P, np.zeros(len(P))]
        else:
            P = np.zeros((g.n_nodes, 2))
        segs = P[g.edges] if g.n_edges else np.zeros((0, 2, 2))
        ax.add_collection(LineCollection(segs, colors="0.6", linewidths=0.4, alpha=0.6, zorder=1))
        size = 6 + 40 * np.sqrt(g.pose_count / g.pose_count.max())
        col = np.array(["0.75"] * g.n_nodes, dtype=object)
        for i in range(g.n_nodes):
            m = int(g.peak_mask[i])
            if m:
                col[i] = _emotion_color(int(np.log2(m & -m)))
        ax.scatter(P[:, 0], P[:, 1], s=size, c=list(col), edgecolors="k", linewidths=0.2, zorder=2)
        ax.set_title(f"{r}: {g.n_nodes} nodes, {g.n_edges} edges", fontsize=9)
        ax.set_xticks([]), ax.set_yticks([])
        ax.autoscale_view()
    handles = [plt.Line2D([], [], ls="", marker="o", color=_emotion_color(e), label=EMOTIONS[e]) for e in range(1, 8)]
    handles.append(plt.Line2D([], [], ls="", marker="o", color="0.75", label="not a peak"))
    fig.legend(handles=handles, loc="lower center", ncol=8, fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.07, 1, 0.95))
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def draw_trajectories(path, items: list, landmarks: list[int], title: str = "") -> None:
    """Original vs synthesised landmark trajectories.

    ``items``: list of (name, original (F, 68, 2), synthesised (T, 68, 2)).
    Solid: y displacement, dashed: x displacement (pixels) against frames.
    """
    fig, axes = plt.subplots(len(items), len(landmarks), figsize=(3.0 * len(landmarks), 2.4 * len(items)),
                             dpi=90, squeeze=False)
    for i, (name, orig, syn) in enumerate(items):
        for j, lm in enumerate(landmarks):
            ax = axes[i, j]
            for c, ls in ((1, "-"), (0, "--")):
                ax.plot(np.arange(len(orig)), orig[:, lm, c], ls, color="tab:blue", lw=1.4,
                        label="original" if c == 1 else None)
                ax.plot(np.arange(len(syn)), syn[:, lm, c], ls, color="tab:red", lw=1.4,
                        label="synthesised" if c == 1 else None)
            ax.set_title(f"{name}, landmark {lm}", fontsize=8)
            ax.tick_params(labelsize=7)
            if j == 0:
                ax.set_ylabel("displacement (px)", fontsize=8)
            if i == len(items) - 1:
                ax.set_xlabel("frame", fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def face_gif(path, positions: np.ndarray, segments: list, fps: float = 12.0, title: str = "") -> None:
    """Animated GIF of a 68-landmark face (frames, 68, 2; image coordinates, y down)."""
    positions = np.asarray(positions, float)
    lo, hi = positions.reshape(-1, 2).min(0), positions.reshape(-1, 2).max(0)
    pad = 0.08 * (hi - lo).max()
    fig, ax = plt.subplots(figsize=(3.6, 4.0), dpi=72)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(hi[1] + pad, lo[1] - pad)
    ax.set_aspect("equal")
    ax.set_xticks([]), ax.set_yticks([])
    lines = [ax.plot([], [], "-", color="tab:blue", lw=1.6)[0] for _ in FACE_LINES]
    dots = ax.plot([], [], ".", color="k", ms=2.5)[0]
    label = ax.set_title(title, fontsize=9)

    def seg_label(f):
        for a, b, name in segments:
            if a <= f < b:
                return name
        return ""

    def draw(f):
        p = positions[f]
        for ln, idx in zip(lines, FACE_LINES):
            ln.set_data(p[idx, 0], p[idx, 1])
        dots.set_data(p[:, 0], p[:, 1])
        label.set_text(f"{title} {seg_label(f)} (frame {f + 1}/{len(positions)})".strip())
        return lines + [dots, label]

    anim = FuncAnimation(fig, draw, frames=len(positions), blit=False)
    with atomic_path(path, suffix=".gif") as tmp:
        anim.save(tmp, writer=PillowWriter(fps=fps))
    plt.close(fig)
