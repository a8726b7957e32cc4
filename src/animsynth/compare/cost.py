"""A cost estimate before a generator is built on a clip's database, and the guard the job applies with it.

Every generator of the family has a known growth with the database's frames ``n`` (at the rate it runs at:
fairmotion's native rate, ``compare.fairmotion.native_fps``; the others the working rate ``compare.fps``):

=======================================  ======================  ======================================================
generator                                growth                  why
=======================================  ======================  ======================================================
``fairmotion``, ``fairmotion_fixed``     ``c * n^2``             ``construct`` compares every pair of graph nodes
``motion_graph``                         ``c * n^2``             the frame-by-frame distance matrix
``isomap``, ``stisomap``                 ``c * n^2``             the neighbourhood graph's distances and shortest paths
``delaunay``, ``knn``                    ``c * n``               PCA and the training vectors of every frame
``motion_matching(_pose, _traj)``        ``c * n``               the feature database (one row per frame)
``genmm``                                ``c * n + g * n * L * S``  the features, then every generated frame's patch
                                                                 search over the database (``L`` frames, ``S`` seeds)
``replay``, ``concat``                   ``c * n``               a copy of the clips
=======================================  ======================  ======================================================

The constants (:data:`COST_MODELS`, CPU seconds; docs/compare.md, "What a build costs") were measured on the shared
2-core Intel Xeon machine of the project: fairmotion's from its construction on synthetic databases of 300, 600,
1200 and 2400 frames at 60 fps (the largest point: 53.2 s), the others as twice the median ratio of the paper run's
``metrics_timing.csv`` (19 clips, the clips of at least 150 database frames). A user generator has no known growth:
no estimate, no guard (its time limit is ``compare.user_timeout_s``).

The guard (``compare.cost_guard``): an estimate above ``warn_cpu_s`` is one warning line (generator, clip, frames,
estimate) before the build; one above ``max_cpu_s`` is not built: that clip's rows are kept with no values and
``note`` = "not run: ..." naming the key.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CostModel", "COST_MODELS", "model_frames", "estimate_cpu_s", "guard"]


@dataclass(frozen=True)
class CostModel:
    """``build * n^power + generate * n * length * seeds`` CPU seconds (``n``: database frames at the
    generator's rate)."""

    power: int
    build: float
    generate: float = 0.0
    growth: str = ""


#: each generator's growth and constants (CPU seconds; module docstring and docs/compare.md say how measured)
COST_MODELS = {
    "fairmotion": CostModel(2, 9.2e-6, growth="O(frames^2): every pair of nodes compared"),
    "fairmotion_fixed": CostModel(2, 9.2e-6, growth="O(frames^2): every pair of nodes compared"),
    "motion_graph": CostModel(2, 1.4e-6, growth="O(frames^2): the distance matrix"),
    "isomap": CostModel(2, 9e-7, growth="O(frames^2): the neighbourhood graph"),
    "stisomap": CostModel(2, 9e-7, growth="O(frames^2): the neighbourhood graph"),
    "delaunay": CostModel(1, 3e-5, growth="O(frames)"),
    "knn": CostModel(1, 3e-5, growth="O(frames)"),
    "motion_matching": CostModel(1, 6e-4, growth="O(frames): the feature database"),
    "motion_matching_pose": CostModel(1, 6e-4, growth="O(frames): the feature database"),
    "motion_matching_traj": CostModel(1, 6e-4, growth="O(frames): the feature database"),
    "genmm": CostModel(1, 2.4e-4, 4.4e-6, growth="O(frames x generated frames): patch search"),
    "replay": CostModel(1, 1.5e-6, growth="O(frames)"),
    "concat": CostModel(1, 1.5e-6, growth="O(frames)"),
}


def model_frames(generator: str, frames: int, cfg: dict) -> int:
    """The database's frames at the rate ``generator`` runs at (fairmotion: ``compare.fairmotion.native_fps``,
    an integer multiple of the working rate; the others: the working rate)."""
    if generator in ("fairmotion", "fairmotion_fixed"):
        native = (cfg.get("fairmotion") or {}).get("native_fps")
        if native:
            return int(frames) * max(1, int(round(float(native) / float(cfg["fps"]))))
    return int(frames)


def estimate_cpu_s(generator: str, frames: int, cfg: dict, length: int = 0, seeds: int = 0) -> float | None:
    """Estimated CPU seconds of building ``generator`` on a database of ``frames`` working-rate frames (with
    GenMM, the generation of ``seeds`` x ``length`` frames too); None for a generator without a model (a user's)."""
    m = COST_MODELS.get(generator)
    if m is None:
        return None
    n = float(model_frames(generator, frames, cfg))
    return m.build * n ** m.power + m.generate * n * float(length) * float(seeds)


def guard(generator: str, clip: str, frames: int, cfg: dict, length: int = 0, seeds: int = 0) -> tuple[str, str]:
    """``(level, line)`` of the cost guard for one clip: ``("", "")`` below ``compare.cost_guard.warn_cpu_s``,
    ``("warn", line)`` above it, ``("refuse", line)`` above ``compare.cost_guard.max_cpu_s`` (a missing key: no
    such level). The line names the generator, the clip, the frames, the estimate and the key."""
    est = estimate_cpu_s(generator, frames, cfg, length, seeds)
    g = cfg.get("cost_guard") or {}
    if est is None:
        return "", ""
    n = model_frames(generator, frames, cfg)
    rate = "" if n == int(frames) else f" ({n} at its native rate)"
    what = (f"{generator} on {clip}: database of {int(frames)} frames{rate}, estimated build "
            f"{est:.0f} s CPU ({COST_MODELS[generator].growth})")
    top, warn = g.get("max_cpu_s"), g.get("warn_cpu_s")
    if top is not None and est > float(top):
        return "refuse", (f"{what} above compare.cost_guard.max_cpu_s ({float(top):g} s): not run (raise the key, "
                          "or use a smaller database: compare.fps, compare.subsets, compare.resequencing)")
    if warn is not None and est > float(warn):
        return "warn", f"{what} above compare.cost_guard.warn_cpu_s ({float(warn):g} s)"
    return "", ""
