"""A cost estimate before a generator is built on a clip's database, and the guard the job applies with it.

Every generator of the family has a known growth with the database's frames ``n`` (at the rate it runs at:
fairmotion's native rate, ``compare.fairmotion.native_fps``; the others the working rate ``compare.fps``):

=======================================  ======================  ======================================================
generator                                growth                  why
=======================================  ======================  ======================================================
``fairmotion``, ``fairmotion_fixed``     ``a n + b N^2 K + g L``  loading every frame, ``construct`` comparing every
                                                                 pair of its ``N`` nodes ``K`` times, the walk
                                                                 (:func:`fairmotion_ops`: ``N``, ``K`` from the peer's
                                                                 ``base``, ``stride``, ``compare``, ``num_comparison``)
``motion_graph``                         ``c * n^2``             the frame-by-frame distance matrix
``isomap``, ``stisomap``                 ``c * n^2``             the neighbourhood graph's distances and shortest paths
``delaunay``, ``knn``                    ``c * n``               PCA and the training vectors of every frame
``motion_matching(_pose, _traj)``        ``c * n``               the feature database (one row per frame)
``genmm``                                ``c * n + g * n * L * S``  the features, then every generated frame's patch
                                                                 search over the database (``L`` frames, ``S`` seeds)
``replay``, ``concat``                   ``c * n``               a copy of the clips
=======================================  ======================  ======================================================

The constants (:data:`COST_MODELS`, :data:`FAIRMOTION_CPU_S`; CPU seconds; docs/compare/generators.md, "What a build costs")
were measured on the shared 2-core Intel Xeon machine of the project: fairmotion's per operation, from builds and
walks on synthetic databases with the operations counted (the comparisons fairmotion made, the frames loaded and
generated), the others as twice the median ratio of the paper run's ``metrics_timing.csv`` (19 clips, the clips of at
least 150 database frames). A user generator has no known growth: no estimate, no guard (its time limit is
``compare.user_timeout_s``).

The guard (``compare.cost_guard``): an estimate above ``warn_cpu_s`` is one warning line (generator, clip, frames,
estimate) before the build; one above ``max_cpu_s`` is not built: that clip's rows are kept with no values and
``note`` = "not run: ..." naming the key.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CostModel", "COST_MODELS", "FAIRMOTION_CPU_S", "model_frames", "fairmotion_ops", "estimate_cpu_s",
           "guard"]


@dataclass(frozen=True)
class CostModel:
    """``build * n^power + generate * n * length * seeds`` CPU seconds (``n``: database frames at the
    generator's rate)."""

    power: int
    build: float
    generate: float = 0.0
    growth: str = ""


#: each generator's growth and constants (CPU seconds; module docstring and docs/compare/generators.md say how measured)
COST_MODELS = {
    # fairmotion's constants are per operation (FAIRMOTION_CPU_S, fairmotion_ops): build is unused
    "fairmotion": CostModel(2, 0.0, growth="O(nodes^2 x comparisons): every pair of nodes compared"),
    "fairmotion_fixed": CostModel(2, 0.0, growth="O(nodes^2 x comparisons): every pair of nodes compared"),
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


#: fairmotion's CPU seconds per operation (:func:`fairmotion_ops`), measured on synthetic databases of the
#: CMU-like skeleton (31 joints) at its native 60 fps (docs/compare/generators.md, "What a build costs": every measured build
#: and walk is within 25 % of the estimate): loading a frame (its BVH round trip and velocities), one comparison of
#: two nodes at one of their compared frames (``construct``'s pose, root / end-effector and trajectory
#: similarity), and generating a frame (the walk and its blends)
FAIRMOTION_CPU_S = {"load_frame": 7.4e-3, "comparison": 3.3e-3, "generated_frame": 6.5e-3}


def fairmotion_ops(frames, cfg: dict, length: int = 0, seeds: int = 0) -> dict:
    """The operations fairmotion's build and walk make on a database, as fairmotion 0.0.4 counts them.

    Parameters
    ----------
    frames : int or list of int
        The database's frames at the working rate: one number (the clips taken as one: an upper bound of the
        nodes, by one node per clip at most) or every clip's.
    cfg : dict
        A generator job's config (``fps`` and the ``fairmotion`` block: ``base``, ``stride``, ``compare``,
        ``num_comparison``, ``native_fps``).
    length, seeds : frames generated per seed (working rate) and seeds

    Returns
    -------
    dict
        ``load_frames`` (native-rate frames loaded), ``nodes`` (``N``: per clip, a node every ``stride`` frames
        that leaves ``base + compare + 1`` frames after its start, as ``create_nodes`` cuts them),
        ``per_pair`` (``K``: the compared frames per pair of nodes, every ``(compare + 1) // num_comparison``
        frames of ``compare + 1``), ``comparisons`` (``N^2 K``: ``construct`` compares every ordered pair,
        a node with itself too), ``generated_frames`` (native-rate frames walked).
    """
    fm = cfg.get("fairmotion") or {}
    up = model_frames("fairmotion", 1, cfg)
    clips = [int(frames)] if isinstance(frames, (int, float)) else [int(f) for f in frames]
    base, compare = int(fm.get("base", 15)) * up, int(fm.get("compare", 10)) * up
    stride = int(fm.get("stride") or fm.get("base", 15)) * up
    while base % stride != 0 and stride > 1:  # fairmotion keeps a clip's own nodes connected
        stride -= 1
    nodes = sum(max(0, -(-(f * up - base - compare - 1) // stride)) for f in clips)
    step = (compare + 1) // max(1, int(fm.get("num_comparison", 3)))
    per_pair = len(range(0, compare + 1, step)) if step >= 1 else 0
    return {"load_frames": sum(clips) * up, "nodes": nodes, "per_pair": per_pair,
            "comparisons": nodes * nodes * per_pair, "generated_frames": int(length) * int(seeds) * up}


def estimate_cpu_s(generator: str, frames: int, cfg: dict, length: int = 0, seeds: int = 0) -> float | None:
    """Estimated CPU seconds of building ``generator`` on a database of ``frames`` working-rate frames (with
    GenMM and fairmotion, the generation of ``seeds`` x ``length`` frames too); None for a generator without a
    model (a user's)."""
    m = COST_MODELS.get(generator)
    if m is None:
        return None
    if generator in ("fairmotion", "fairmotion_fixed"):
        ops, c = fairmotion_ops(frames, cfg, length, seeds), FAIRMOTION_CPU_S
        return (c["load_frame"] * ops["load_frames"] + c["comparison"] * ops["comparisons"]
                + c["generated_frame"] * ops["generated_frames"])
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
    walks = COST_MODELS[generator].generate or generator in ("fairmotion", "fairmotion_fixed")
    what = (f"{generator} on {clip}: database of {int(frames)} frames{rate}, estimated build"
            f"{' and generation' if walks and seeds else ''} {est:.0f} s CPU ({COST_MODELS[generator].growth})")
    top, warn = g.get("max_cpu_s"), g.get("warn_cpu_s")
    if top is not None and est > float(top):
        return "refuse", (f"{what} above compare.cost_guard.max_cpu_s ({float(top):g} s): not run (raise the key, "
                          "or use a smaller database: compare.fps, compare.subsets, compare.resequencing)")
    if warn is not None and est > float(warn):
        return "warn", f"{what} above compare.cost_guard.warn_cpu_s ({float(warn):g} s)"
    return "", ""
