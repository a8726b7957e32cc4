"""One generator over every clip of the protocol: fitted on each clip's database, every seed generated from the
clip's start and scored (:func:`run_generator`), its cost measured; a generator that fails is kept as empty rows.

Files of one generator job: per generator ``compare/runs/<generator>.csv`` (metrics, one row per clip x seed),
``<generator>_timing.csv`` (build and generation cost, one row per clip, :data:`TIMING_COLUMNS`) and
``<generator>_showcase.npz`` (the showcase clip's start and generated frames: :func:`save_shown` / :func:`load_shown`).
"""

from __future__ import annotations

import logging
import os
import sys
import time

import numpy as np
import pandas as pd

from ..atomic import atomic_path
from ..motion import Motion
from ..skeleton import Skeleton
from .generators.registry import make_generator
from .measures.metric_table import KEY_COLUMNS, METRIC_NAMES
from .protocol import Clip, clip_seeds
from .scoring import DatabaseKinematics, joint_count, reference, run_stats_by_skeleton, run_values, score

__all__ = ["TIMING_COLUMNS", "cpu_seconds", "peak_rss_mb", "run_generator", "run_isolated", "failed_run",
           "generation_query", "native_inputs", "save_shown", "load_shown"]

log = logging.getLogger("animsynth.compare.runner")

#: the columns of ``<generator>_timing.csv``
TIMING_COLUMNS = ["generator", "clip", "database_frames", "build_cpu_s", "build_wall_s", "generate_cpu_s",
                  "generate_wall_s", "frames_generated", "peak_rss_mb"]


def cpu_seconds() -> float:
    """CPU seconds (user + system) of this process and of its finished child processes (fairmotion builds
    its graph in a multiprocessing pool)."""
    import resource

    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + c.ru_utime + c.ru_stime


def peak_rss_mb() -> float:
    """The largest resident memory (MB) so far of this process and of its largest finished child process
    (``getrusage``): a generator job's peak, a pool it starts included."""
    import resource

    return max(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
               resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss) / 1024.0



def run_generator(clips: list[Clip], generator: str, cfg: dict, master_seed: int, roles: dict | None = None,
                  showcase: tuple[str, int] | None = None):
    """Fit ``generator`` on every clip's database, generate every seed from the clip's start, score.

    Parameters
    ----------
    clips : list of Clip
    generator : a name of :data:`animsynth.compare.generators.names.GENERATORS`
    cfg : the ``compare`` block (with the re-sequencing study's ``stisomap`` block added)
    master_seed : the config's ``seed``
    roles : joint-role overrides (config ``joint_roles``)
    showcase : (clip id, seed index) whose motion is returned

    Returns
    -------
    metrics : DataFrame, one row per clip x seed (:data:`KEY_COLUMNS` + :data:`METRIC_NAMES` + ``note``):
        a clip whose database the generator cannot be built on (its ``fit`` raises ValueError, e.g. a
        motion graph without transitions) keeps its rows with no values and ``note`` = "not built: <why>"
    timing : DataFrame, one row per clip (:data:`TIMING_COLUMNS`): CPU (:func:`cpu_seconds`, child
        processes included) and wall seconds of the build and of the generation, the job's peak resident
        memory so far (:func:`peak_rss_mb`)
    shown : Motion or None, the showcase clip's start and generated frames joined
        (``meta["context"]``: start frames)

    A user generator (``compare.user_generators``) that fails in any way (:class:`UserGeneratorError`) stops at
    its first failure: one error line, and every row of it empty (:func:`failed_run`).
    """
    from .generators.user import UserGeneratorError, close_processes

    try:
        return _run_generator(clips, generator, cfg, master_seed, roles, showcase)
    except UserGeneratorError as exc:
        return failed_run(clips, generator, cfg, str(exc), showcase)
    finally:
        close_processes()  # a user generator's child process ends with its job


def failed_run(clips: list[Clip], generator: str, cfg: dict, why: str, showcase: tuple[str, int] | None = None):
    """The files of a generator that could not run at all: ``why`` logged as one error line (and printed to
    stderr, the run's console), every clip x seed row with no values and ``note`` = "failed: <why>", every timing
    row empty, and as the showcase the showcase clip's start alone (no generated frame; ``meta["note"]``)."""
    line = " ".join(why.split())
    log.error("%s", line)
    print(f"animsynth: ERROR: {line}", file=sys.stderr)
    rows, trows, shown = [], [], None
    for clip in clips:
        r, t = _empty_rows(clip, generator, int(cfg["seeds"]), f"failed: {line}")
        rows += r
        trows.append(t)
        if showcase is not None and clip.clip == showcase[0]:
            shown = _start_only(clip, generator, f"failed: {line}")
    return (pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"]), pd.DataFrame(trows, columns=TIMING_COLUMNS),
            shown)


def _start_only(clip: Clip, generator: str, note: str) -> Motion:
    """The showcase of a generator with no motion for the clip: the start alone, ``meta["note"]`` saying why."""
    start = clip.start
    return Motion(np.asarray(start.values, float), start.skeleton, start.fps, f"{generator} {clip.clip}",
                  {"context": clip.context, "seams": np.zeros(0, np.int64), "note": note})


def _empty_rows(clip: Clip, generator: str, n_seeds: int, note: str) -> tuple[list, dict]:
    """The metric rows (one per seed, no values, ``note``) and the timing row (no times) of a clip a generator
    has no motion for."""
    key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
    rows = [{**key, "seed": i, **{m: np.nan for m in METRIC_NAMES}, "note": note} for i in range(n_seeds)]
    timing = {"generator": generator, "clip": clip.clip, "database_frames": int(sum(d.n_frames for d in clip.database)),
              "build_cpu_s": np.nan, "build_wall_s": np.nan, "generate_cpu_s": np.nan, "generate_wall_s": np.nan,
              "frames_generated": 0, "peak_rss_mb": peak_rss_mb()}
    return rows, timing


def generation_query(gen, clip: Clip) -> dict:
    """What ``gen.generate`` is given besides the start, length and seed, by its ``query``
    (:class:`animsynth.generator.Generator`): nothing for ``"start"``; ``trajectory`` = the clip's held-out frames
    after the start (:attr:`Clip.future`) for ``"future_trajectory"``."""
    from ..generator import QUERY_FUTURE_TRAJECTORY, QUERY_START

    query = getattr(gen, "query", QUERY_START)
    if query == QUERY_START:
        return {}
    if query == QUERY_FUTURE_TRAJECTORY:
        return {"trajectory": clip.future}
    raise ValueError(f"generator {getattr(gen, 'name', gen)!r}: unknown query {query!r} (one of "
                     f"{[QUERY_START, QUERY_FUTURE_TRAJECTORY]})")


def native_inputs(gen, clip: Clip) -> tuple[dict, dict]:
    """What ``gen.fit`` and ``gen.generate`` are given at the generator's native rate: for a generator with
    ``input_rate = "native"`` (fairmotion's peer) whose ``native_fps`` the clip carries from the source
    (:class:`NativeRate`), ``({"native_clips": database}, {"native_start": start})``; else ``({}, {})`` (the generator
    upsamples the working-rate clips itself)."""
    if getattr(gen, "input_rate", "working") != "native" or getattr(gen, "native_fps", None) is None:
        return {}, {}
    nat = clip.at_rate(float(gen.native_fps))
    if nat is None or not nat.database:
        return {}, {}
    return {"native_clips": nat.database}, {"native_start": nat.start}


def _run_generator(clips, generator, cfg, master_seed, roles, showcase):
    from .cost import guard as cost_guard

    mcfg = cfg["metrics"]
    rows, trows, shown = [], [], None
    kin = DatabaseKinematics(roles)  # each database motion's forward kinematics, once for the whole job
    std = run_stats_by_skeleton(clips, mcfg, roles, kin)
    for clip in clips:
        seeds = clip_seeds(master_seed, cfg["seed"], clip.clip, cfg["seeds"])
        key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
        db_frames = int(sum(d.n_frames for d in clip.database))
        # the cost guard (compare.cost_guard; animsynth.compare.cost): an estimate before the build
        level, line = cost_guard(generator, clip.clip, db_frames, cfg, clip.length, len(seeds))
        if level == "refuse":
            log.error("%s", line)
            print(f"animsynth: compare: {line}", file=sys.stderr)
            r, t = _empty_rows(clip, generator, len(seeds), f"not run: {line}")
            rows += r
            trows.append(t)
            if showcase is not None and clip.clip == showcase[0]:
                shown = _start_only(clip, generator, f"not run: {line}")
            continue
        if level == "warn":
            log.warning("%s", line)
        gen = make_generator(generator, cfg, held_out=clip.held_out)
        fit_native, generate_native = native_inputs(gen, clip)
        if hasattr(gen, "child_cpu_s_"):  # a user generator: its log lines name the clip
            gen.clip = clip.clip
        c0, w0 = cpu_seconds(), time.perf_counter()
        try:
            gen.fit(clip.database, **fit_native)
        except ValueError as exc:  # e.g. a motion graph without transitions on a short database
            if showcase is not None and clip.clip == showcase[0]:
                raise ValueError(f"{generator} cannot be built on the showcase clip {clip.clip} ({exc}); choose "
                                 "another with config key 'compare.showcase.clip'") from exc
            log.warning("%s cannot be built on %s: %s", generator, clip.clip, exc)
            r, t = _empty_rows(clip, generator, len(seeds), f"not built: {exc}")
            rows += r
            trows.append(t)
            continue
        build_cpu, build_wall = cpu_seconds() - c0, time.perf_counter() - w0
        # a user generator's child process: its CPU is not among the job's finished children until it ends
        build_cpu += float(getattr(gen, "child_cpu_s_", 0.0))
        start = clip.start
        ref = reference(clip, mcfg, roles, std[joint_count(clip)], kin)
        gen_cpu = gen_wall = 0.0
        feats = []
        query = {**generation_query(gen, clip), **generate_native}
        for i, s in enumerate(seeds):
            c0, w0 = cpu_seconds(), time.perf_counter()
            m = gen.generate(start, clip.length, s, **query)
            gen_cpu += cpu_seconds() - c0 + float(getattr(gen, "child_cpu_s_", 0.0))
            gen_wall += time.perf_counter() - w0
            row, f = score(clip, ref, m, generator, mcfg, roles)
            feats.append(f)
            rows.append({**key, "seed": i, **row, "note": ""})
            if showcase is not None and (clip.clip, i) == tuple(showcase):
                seams = np.asarray(m.meta["seams"], np.int64)
                if generator != "replay":  # the entry is a seam, as scored
                    seams = np.union1d(seams, [0])
                shown = Motion(np.vstack([start.values, m.values]), m.skeleton, m.fps, f"{generator} {clip.clip}",
                               {"context": clip.context, "seams": seams + clip.context})
        per_run = run_values(gen, feats)  # the generator's own count, the spread over seeds: one value per clip
        for r in rows[-len(seeds):]:
            r.update(per_run)
        trows.append({"generator": generator, "clip": clip.clip, "database_frames": db_frames,
                      "build_cpu_s": build_cpu, "build_wall_s": build_wall, "generate_cpu_s": gen_cpu,
                      "generate_wall_s": gen_wall, "frames_generated": clip.length * len(seeds),
                      "peak_rss_mb": max(peak_rss_mb(), float(getattr(gen, "child_rss_mb_", 0.0)))})
        log.info("%s on %s: build %.3f s CPU, %d seeds x %d frames in %.3f s CPU", generator, clip.clip, build_cpu,
                 len(seeds), clip.length, gen_cpu)
    metrics = pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"])
    return metrics, pd.DataFrame(trows, columns=TIMING_COLUMNS), shown




# ----------------------------------------------------------------------------- the showcase file


def save_shown(path, motion: Motion) -> None:
    """Store the showcase motion (start + generated frames) with its start length and seams (and ``meta["note"]``
    when the generator failed: then the start alone)."""
    note = {"note": np.array(motion.meta["note"])} if motion.meta.get("note") else {}  # a run that failed
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez_compressed(tmp, values=np.asarray(motion.values, float), fps=np.float64(motion.fps),
                            name=np.array(motion.name), skeleton=np.array(motion.skeleton.to_json()),
                            context=np.int64(motion.meta["context"]),
                            seams=np.asarray(motion.meta.get("seams", []), np.int64), **note)


def load_shown(path) -> Motion:
    """The motion stored by :func:`save_shown` (``meta``: ``context``, ``seams``, ``note`` when stored)."""
    with np.load(path, allow_pickle=False) as z:
        meta = {"context": int(z["context"]), "seams": np.array(z["seams"])}
        if "note" in z.files:
            meta["note"] = str(z["note"])
        return Motion(np.array(z["values"]), Skeleton.from_json(str(z["skeleton"])), float(z["fps"]), str(z["name"]),
                      meta)



def run_isolated(clips: list[Clip], generator: str, cfg: dict, master_seed: int, roles: dict | None, showcase,
                 outputs) -> tuple:
    """:func:`run_generator` as one workflow job runs it: with one BLAS thread (the job's threads: 1; the simplex
    searches make many small LAPACK calls) and, for a user generator (``compare.user_generators``), a guard on the
    project (the working directory) and the folder of the job's ``outputs`` (paths), which it may not change."""
    from threadpoolctl import threadpool_limits

    if generator in (cfg.get("user_generators") or {}):
        outs = [os.path.dirname(os.path.abspath(p)) for p in outputs]
        cfg = dict(cfg, user_guard=list(dict.fromkeys([os.getcwd(), os.path.commonpath(outs)])))
    with threadpool_limits(1, user_api="blas"):
        return run_generator(clips, generator, cfg, master_seed, roles, showcase)
