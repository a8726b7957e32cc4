"""Figures of the simplicial family (matplotlib, written atomically).

* :func:`plot_graphs` - G' edges for several folds (paper Figs 1-2)
* :func:`plot_field` - the vector field as a quiver plot over the training data (Figs 3-4)
* :func:`plot_paths` - held-out vs generated latent paths (Figs 5-6)
* :func:`walk_motion` - a generated walk reprojected to a full-body Motion (Fig 7)
* :func:`plot_derivative`, :func:`plot_beyond` - our extra figures
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection

from ..motion import Motion
from ..atomic import atomic_path

_CLIP_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink")


def _save(fig, path):
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight", metadata={"Software": None})
    plt.close(fig)


def _clips(ax, res, s=4, alpha=0.8):
    for c, clip in enumerate(res.train_latent):
        ax.plot(clip[:, 0], clip[:, 1], ".", ms=s * 0.6, color=_CLIP_COLOURS[c % len(_CLIP_COLOURS)], alpha=alpha)


def plot_graphs(results, path, title: str) -> None:
    """G' (2-D latent view) for each fold result: clip edges coloured, added edges grey."""
    n = len(results)
    fig, axes = plt.subplots(1, n, figsize=(4.6 * n, 4.4), squeeze=False)
    for ax, res in zip(axes[0], results):
        g = res.graph
        X = g.points_[:, :2]
        added = g.added_edges_
        ax.add_collection(LineCollection(np.stack([X[added[:, 0]], X[added[:, 1]]], axis=1),
                                         colors="0.45", linewidths=0.35, alpha=0.45))
        ce = g.clip_edge_array_
        ax.add_collection(LineCollection(np.stack([X[ce[:, 0]], X[ce[:, 1]]], axis=1),
                                         colors="k", linewidths=0.8))
        _clips(ax, res)
        # a few arrows to show the orientation of added edges
        if len(added):
            sel = added[:: max(1, len(added) // 150)]
            d = X[sel[:, 1]] - X[sel[:, 0]]
            ax.quiver(X[sel[:, 0], 0], X[sel[:, 0], 1], d[:, 0], d[:, 1], angles="xy", scale_units="xy", scale=1,
                      width=0.003, color="tab:red", alpha=0.6)
        r = res.row
        ax.set_title(f"held out {r['held_out']}: {r['n_edges']} edges\n"
                     f"SCC={r['components']}, undirected {'connected' if r['undirected_connected'] else 'split'}, "
                     f"H {'connected' if r['h_connected'] else 'split'}", fontsize=8)
        ax.set_xlabel("PC1")
        ax.set_ylabel("PC2")
        ax.autoscale()
        ax.set_aspect("equal", adjustable="datalim")
    fig.suptitle(title, fontsize=10)
    _save(fig, path)


def plot_field(res, path, title: str, grid: int = 28) -> None:
    """Quiver plot of the field on a grid over the training bounding box (first two latent axes)."""
    X = np.vstack(res.train_latent)
    lo, hi = X[:, :2].min(0), X[:, :2].max(0)
    pad = 0.08 * (hi - lo)
    gx, gy = np.meshgrid(np.linspace(lo[0] - pad[0], hi[0] + pad[0], grid), np.linspace(lo[1] - pad[1], hi[1] + pad[1], grid))
    Q = np.zeros((gx.size, X.shape[1]))
    Q[:, 0], Q[:, 1] = gx.ravel(), gy.ravel()
    if X.shape[1] > 2:  # other latent axes at the training mean
        Q[:, 2:] = X[:, 2:].mean(0)
    V, fb = res.field.evaluate(Q)
    fig, ax = plt.subplots(figsize=(6.2, 5.4))
    _clips(ax, res, s=3, alpha=0.5)
    ax.quiver(Q[~fb, 0], Q[~fb, 1], V[~fb, 0], V[~fb, 1], color="tab:red", angles="xy", width=0.003, label="inside hull")
    if fb.any():
        ax.quiver(Q[fb, 0], Q[fb, 1], V[fb, 0], V[fb, 1], color="0.5", angles="xy", width=0.003,
                  label="outside hull (k-NN fallback)")
    ax.legend(loc="best", fontsize=7)
    ax.set_xlabel("PC1")
    ax.set_ylabel("PC2")
    ax.set_title(title, fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    _save(fig, path)


def plot_paths(results, path, title: str) -> None:
    """Held-out (black) vs generated (red) latent paths, one panel per fold."""
    n = len(results)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 4.2), squeeze=False)
    for ax, res in zip(axes[0], results):
        _clips(ax, res, s=2, alpha=0.25)
        T, G = res.test_latent, res.path.points
        ax.plot(T[:, 0], T[:, 1], "-", color="k", lw=1.2, label="held out")
        ax.plot(G[:, 0], G[:, 1], "-", color="tab:red", lw=1.2, label="generated")
        ax.plot(*T[0, :2], "o", color="k", ms=5)
        ax.plot(*T[-1, :2], "s", color="k", ms=5)
        ax.plot(*G[-1, :2], "s", color="tab:red", ms=5)
        r = res.row
        ax.set_title(f"{r['held_out']}: A={r['error_a']:.3g} F={r['error_f']:.3g}\n"
                     f"(norm A={r['error_a_norm']:.3g}, F={r['error_f_norm']:.3g}; k-NN fallback "
                     f"{r['fallback_steps']}/{r['steps']} steps = {100 * r['fallback_share']:.0f} %)",
                     fontsize=8)
        ax.set_aspect("equal", adjustable="datalim")
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(title, fontsize=10)
    _save(fig, path)


def walk_motion(res, held_out: Motion, name: str = "generated") -> Motion:
    """Reproject a generated latent path to a full-body Motion.

    The 56 joint angles come from the inverse PCA of the path; the root (not
    modelled by the method) is fixed by :func:`in_place_root`, so the figure
    walks in place, facing the skeleton's rest direction (side view in the
    filmstrip).
    """
    angles = res.pca.inverse_transform(res.path.points)
    n_root = len(held_out.skeleton.joints[0].dofs)
    values = np.empty((angles.shape[0], n_root + angles.shape[1]))
    values[:, n_root:] = angles
    values[:, :n_root] = in_place_root(held_out)
    return Motion(values, held_out.skeleton, held_out.fps, name)


def in_place_root(motion: Motion) -> np.ndarray:
    """Root DOF values for an in-place figure: the first frame's translation, zero rotation."""
    sk = motion.skeleton
    root = sk.joints[0]
    vals = np.array(motion.values[0, :len(root.dofs)], float)
    for i, d in enumerate(root.dofs):
        if d.startswith("r"):
            vals[i] = 0.0
    return vals


def plot_derivative(folds, path, methods=("delaunay", "knn")) -> None:
    """Error A (normalised) and arc-length ratio per derivative variant and method."""
    ders = list(dict.fromkeys(folds["derivative"]))
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, met, lab in zip(axes, ("error_a_norm", "error_f_norm", "length_ratio"),
                            ("Error A / bbox diagonal", "Error F / bbox diagonal", "generated / held-out arc length")):
        data, labels = [], []
        for d in ders:
            for m in methods:
                s = folds[(folds["derivative"] == d) & (folds["method"] == m)][met]
                data.append(s.to_numpy())
                labels.append(f"{d}\n{m}")
        ax.boxplot(data, tick_labels=labels)
        ax.set_ylabel(lab)
        ax.tick_params(axis="x", labelsize=7)
        if met == "length_ratio":
            ax.axhline(1.0, color="0.5", ls="--", lw=0.8)
    fig.suptitle("Training-vector derivative variants (all folds)", fontsize=10)
    fig.tight_layout()
    _save(fig, path)


def plot_beyond(summary, folds, path, baseline: str, metric: str = "error_a_pose") -> None:
    """Left: median error per variant; middle: k sweep; right: latent dimension."""
    fig, axes = plt.subplots(1, 3, figsize=(16, 5))
    s = summary.sort_values(metric)
    colours = ["tab:red" if v == baseline else ("tab:green" if g == "target" else "tab:blue")
               for v, g in zip(s["variant"], s["generation"])]
    axes[0].barh(s["variant"], s[metric], color=colours)
    axes[0].invert_yaxis()
    axes[0].set_xlabel(f"median {metric} over folds (deg)" if metric.endswith("pose") else f"median {metric}")
    axes[0].tick_params(axis="y", labelsize=7)
    axes[0].set_title(f"variants (red: paper baseline {baseline}; green: target-directed)", fontsize=8)
    d0 = int(summary["latent_dim"].min())
    for m, mk in (("knn", "o-"), ("kdelaunay", "s-")):
        sub = summary[(summary["method"] == m) & (summary["latent_dim"] == d0) & (summary["generation"] == "field")]
        sub = sub.sort_values("k")
        if len(sub):
            axes[1].plot(sub["k"], sub["error_a_norm"], mk, label=m)
    base = summary[summary["variant"] == baseline]
    if len(base):
        axes[1].axhline(float(base["error_a_norm"].iloc[0]), color="tab:red", ls="--", lw=0.8, label=baseline)
    axes[1].set_xscale("log", base=2)
    axes[1].set_xlabel("k")
    axes[1].set_ylabel("median Error A / bbox diagonal")
    axes[1].legend(fontsize=7)
    axes[1].set_title(f"k sweep (latent dim {d0})", fontsize=9)
    for (m, w), sub in summary[summary["generation"] == "field"].groupby(["method", "weights"], sort=True):
        ks = sub["k"].mode().iloc[0]
        sub = sub[(sub["k"] == ks)].sort_values("latent_dim")
        if sub["latent_dim"].nunique() > 1:
            axes[2].plot(sub["latent_dim"], sub[metric], "o-", label=f"{m} ({w})")
    axes[2].set_xlabel("latent dimension")
    axes[2].set_xticks(sorted(int(d) for d in summary["latent_dim"].unique()))
    axes[2].set_ylabel(f"median {metric}")
    axes[2].legend(fontsize=7)
    axes[2].set_title("latent dimension (pose-space error compares dimensions)", fontsize=9)
    fig.tight_layout()
    _save(fig, path)
