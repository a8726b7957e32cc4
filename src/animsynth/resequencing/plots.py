"""Figures of the re-sequencing study (matplotlib)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.collections import LineCollection

from ..atomic import atomic_path

__all__ = ["embedding_figure", "residual_variance_figure"]

_METHOD = {"isomap": "Isomap", "stisomap": "ST-Isomap"}
_METRIC = {"l2": "L2", "lee": "Lee"}


def embedding_figure(path, panels: list[dict], title: str) -> None:
    """Fig. 2: 2-D embeddings with their neighbourhood edges, one panel per configuration.

    ``panels``: dicts with ``xy`` (frames, 2), ``edges`` (E, 2) frame-index
    pairs and ``label``. Points are coloured by frame index (time).
    """
    k = max(len(panels), 1)
    cols = min(k, 2)
    rows = int(np.ceil(k / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4.4 * cols, 3.9 * rows), dpi=100, squeeze=False, layout="constrained")
    for ax in axes.ravel()[k:]:
        ax.axis("off")
    for ax, p in zip(axes.ravel(), panels):
        xy = np.asarray(p["xy"], float)
        e = np.asarray(p["edges"], int).reshape(-1, 2)
        if e.size:
            ax.add_collection(LineCollection(xy[e], colors="0.6", linewidths=0.3, alpha=0.5, zorder=1))
        sc = ax.scatter(xy[:, 0], xy[:, 1], c=np.arange(len(xy)), cmap="viridis", s=4, zorder=2)
        ax.set_title(p["label"], fontsize=9)
        ax.set_aspect("equal", adjustable="datalim")
        ax.tick_params(labelsize=7)
    fig.colorbar(sc, ax=axes.ravel().tolist(), shrink=0.6, label="frame")
    fig.suptitle(title, fontsize=10)
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)


def residual_variance_figure(path, rv: pd.DataFrame, title: str) -> None:
    """Fig. 3: residual variance against embedding dimension, one line per
    method x metric x global flag, at each configuration's minimum k (the
    paper's choice; rows of the fixed-k sweep, ``k_mode == "fixed"``, are left out)."""
    if "k_mode" in rv.columns:
        rv = rv[rv["k_mode"] == "min_k"]
    fig, ax = plt.subplots(figsize=(6.0, 4.0), dpi=100)
    styles = {("isomap", "l2"): ("tab:blue", "-"), ("isomap", "lee"): ("tab:blue", "--"),
              ("stisomap", "l2"): ("tab:red", "-"), ("stisomap", "lee"): ("tab:red", "--")}
    for (method, metric, g), grp in rv.groupby(["method", "metric", "global_dof"], sort=True):
        color, ls = styles.get((method, metric), ("k", "-"))
        grp = grp.sort_values("dim")
        ax.plot(grp["dim"], grp["residual_variance"], ls, color=color, marker="o" if g else "s", ms=3,
                alpha=1.0 if g else 0.6,
                label=f"{_METHOD.get(method, method)} {_METRIC.get(metric, metric)}, "
                      f"global DOF {'in' if g else 'out'} (k={int(grp['k'].iloc[0])})")
    ax.set_xlabel("embedding dimension d")
    ax.set_ylabel("residual variance 1 - R$^2$")
    ax.set_ylim(bottom=0)
    ax.set_xticks(sorted(rv["dim"].unique()))
    ax.legend(fontsize=6)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    plt.close(fig)
