"""Figures of the comparison: metrics per generator with their spread, one skeleton strip per generator."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..atomic import atomic_path
from .generators.names import REFERENCES
from .measures.metric_table import FIGURE_METRICS, SWEEP_PANELS, metric

__all__ = ["metrics_figure", "strips_figure", "sweep_figure"]


def _save(fig, path, title: str) -> None:
    """Title, layout, an atomic PNG write, and the figure closed."""
    import matplotlib.pyplot as plt

    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def metrics_figure(path, metrics: pd.DataFrame, order, title: str = "") -> None:
    """One panel per metric of :data:`~animsynth.compare.measures.metric_table.FIGURE_METRICS`, titled by its record's
    ``title``: every generator's values over clips x seeds as a box
    (median, IQR, whiskers at 5-95 %); the reference rows (replay, concat) in grey."""
    import matplotlib.pyplot as plt

    gens = [g for g in order if g in set(metrics["generator"])]
    n = len(FIGURE_METRICS)
    cols = 3
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.1 * rows), dpi=100, squeeze=False)
    for ax, m in zip(axes.ravel(), FIGURE_METRICS):
        label = metric(m).title
        data, names, colours = [], [], []
        for g in gens:
            x = pd.to_numeric(metrics.loc[metrics["generator"] == g, m], errors="coerce").to_numpy(float)
            x = x[np.isfinite(x)]
            if x.size:
                data.append(x)
                names.append(g)
                colours.append("0.75" if g in REFERENCES else "tab:blue")
        if data:
            bp = ax.boxplot(data, whis=(5, 95), showfliers=False, patch_artist=True, widths=0.6)
            for patch, c in zip(bp["boxes"], colours):
                patch.set_facecolor(c)
                patch.set_alpha(0.7)
            for med in bp["medians"]:
                med.set_color("black")
            ax.set_xticks(range(1, len(names) + 1), names, rotation=40, ha="right", fontsize=8)
        else:
            ax.text(0.5, 0.5, "no values", ha="center", va="center", transform=ax.transAxes)
        better = metric(m).better
        ax.set_title(label + (f" ({better} is better)" if better and "higher" not in label else ""), fontsize=8.5)
        ax.tick_params(axis="y", labelsize=8)
        ax.grid(axis="y", alpha=0.3)
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    _save(fig, path, title)


def strips_figure(path, shown: dict, n_panels: int = 8, title: str = "") -> None:
    """One row per generator: the last start frame (grey) and ``n_panels - 1`` evenly spaced generated
    frames (seam frames in red), side view along the start's direction of travel, every pose centred on
    its root.

    Parameters
    ----------
    shown : {generator: Motion}, the start and generated frames joined (``meta["context"]``: start frames,
        ``meta["seams"]``: seam frames of the joined motion; ``meta["note"]``: why a generator that failed shows its
        start alone)
    """
    import matplotlib.pyplot as plt

    from .measures import positions

    names = list(shown)
    fig, axes = plt.subplots(len(names), 1, figsize=(1.5 * n_panels, 1.9 * len(names)), dpi=100, squeeze=False)
    first = shown[names[0]]
    p0 = positions(first)
    c0 = int(first.meta["context"])
    d = p0[c0 - 1, 0, [0, 2]] - p0[0, 0, [0, 2]]
    fwd = d / np.linalg.norm(d) if np.linalg.norm(d) > 1e-6 else np.array([0.0, 1.0])
    height = float(np.ptp(p0[:, :, 1])) or 1.0
    for ax, g in zip(axes[:, 0], names):
        m = shown[g]
        pos = positions(m)
        c = int(m.meta["context"])
        seams = set(int(s) for s in np.asarray(m.meta.get("seams", [])))
        idx = np.unique(np.concatenate([[c - 1], np.linspace(c, pos.shape[0] - 1, n_panels - 1).round().astype(int)]))
        idx = idx[idx < pos.shape[0]]  # a generator that failed: its start alone
        parents = m.skeleton.parents()
        for k, f in enumerate(idx):
            q = pos[f] - pos[f, :1] * np.array([1.0, 0.0, 1.0])
            x = q[:, 0] * fwd[0] + q[:, 2] * fwd[1] + k * height * 0.9
            colour = "0.6" if f < c else ("tab:red" if any(abs(f - s) <= 1 for s in seams) else "tab:blue")
            for j, p in enumerate(parents):
                if p >= 0:
                    ax.plot([x[p], x[j]], [q[p, 1], q[j, 1]], "-", color=colour, lw=1.3)
            ax.text(k * height * 0.9, pos[:, :, 1].min() - 0.08 * height, str(f - c), ha="center", fontsize=6)
        ax.set_aspect("equal")
        ax.axis("off")
        note = str(m.meta.get("note") or "")
        if note:  # a generator that failed: its start frame at the left, the reason beside its name
            ax.set_xlim(-0.6 * height, (n_panels - 0.4) * height * 0.9)
            note = " -- no motion: " + (note if len(note) <= 110 else note[:107] + "...")
        ax.set_title(g + note, fontsize=8.5, loc="left")
    _save(fig, path, title)


def long_strips_figure(path, shown: dict, every_s: float = 2.0, title: str = "") -> None:
    """The long track's preview: one row per generator from the same start, its root path seen from above (start
    grey, generated blue, a dot every ``every_s`` seconds) beside its poses every ``every_s`` seconds (side view,
    each centred on its root; seam frames red), so a loop (a path over itself, poses that repeat) or a freeze (dots
    on one spot, one pose) can be seen.

    Parameters
    ----------
    shown : {generator: Motion}, the start and the long run's frames joined (``meta["context"]``: start frames,
        ``meta["seams"]``, ``meta["note"]``: why a generator with no long motion shows its start alone)
    """
    import matplotlib.pyplot as plt

    from .measures import positions

    names = list(shown)
    longest = max(m.n_frames - int(m.meta["context"]) for m in shown.values())
    step = max(1, int(round(every_s * next(iter(shown.values())).fps)))
    n_poses = longest // step + 2
    fig, axes = plt.subplots(len(names), 2, figsize=(2.2 + 0.9 * n_poses, 1.7 * len(names)), dpi=100,
                             squeeze=False, gridspec_kw={"width_ratios": [1.6, 0.9 * n_poses]})
    for (path_ax, ax), g in zip(axes, names):
        m = shown[g]
        pos, c = positions(m), int(m.meta["context"])
        height = float(np.ptp(pos[:, :, 1])) or 1.0
        idx = np.concatenate([[c - 1], np.arange(c + step - 1, pos.shape[0], step)])
        path_ax.plot(pos[:c, 0, 0], pos[:c, 0, 2], "-", color="0.6", lw=1.5)
        path_ax.plot(pos[c - 1:, 0, 0], pos[c - 1:, 0, 2], "-", color="tab:blue", lw=0.8)
        path_ax.plot(pos[idx[1:], 0, 0], pos[idx[1:], 0, 2], ".", color="tab:blue", ms=4)
        path_ax.set_aspect("equal", adjustable="datalim")
        path_ax.tick_params(labelsize=6)
        seams = {int(x) for x in np.asarray(m.meta.get("seams", []))}
        parents = m.skeleton.parents()
        for k, f in enumerate(idx):
            q = pos[f] - pos[f, :1] * np.array([1.0, 0.0, 1.0])
            x = q[:, 0] + k * height * 0.9
            colour = "0.6" if f < c else ("tab:red" if any(abs(f - s) <= 1 for s in seams) else "tab:blue")
            for j, p in enumerate(parents):
                if p >= 0:
                    ax.plot([x[p], x[j]], [q[p, 1], q[j, 1]], "-", color=colour, lw=1.1)
            ax.text(k * height * 0.9, pos[:, :, 1].min() - 0.1 * height, f"{(f - c + 1) / m.fps:.0f} s", ha="center",
                    fontsize=6)
        ax.set_xlim(-0.6 * height, (n_poses - 0.4) * height * 0.9)
        ax.set_aspect("equal")
        ax.axis("off")
        note = str(m.meta.get("note") or "")
        note = f" -- no long motion: {note if len(note) <= 110 else note[:107] + '...'}" if note else ""
        ax.set_title(g + note, fontsize=8.5, loc="left")
    _save(fig, path, title)


def sweep_figure(table: pd.DataFrame, path, default_budget: float) -> None:
    """The transition budget sweep (:func:`animsynth.compare.tables.sweep_table`): one panel per metric, one line
    per graph generator against the budget (transitions per second of database, log scale), one panel per metric of
    :data:`~animsynth.compare.measures.metric_table.SWEEP_PANELS` titled by its record's ``title``; the default
    budget, at which the claims are decided, dashed."""
    import matplotlib.pyplot as plt

    panels = [(f"{m}_median", metric(m).title) for m in SWEEP_PANELS]
    fig, axes = plt.subplots(2, 3, figsize=(13.5, 6.4), dpi=100, squeeze=False)
    for ax, (col, label) in zip(axes.ravel(), panels):
        for g, sub in table.groupby("generator", sort=False):
            sub = sub.sort_values("transitions_per_s")
            ax.plot(sub["transitions_per_s"], sub[col], marker="o", label=g)
        ax.axvline(default_budget, color="0.5", ls="--", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("transitions per second of database")
        ax.set_title(label, fontsize=9)
    axes[0, 0].legend(fontsize=8)
    _save(fig, path, "Graph generators at equal transition budgets (median over clips x seeds)")
