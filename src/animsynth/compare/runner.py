"""One generator over the clips of one subject: fitted once on each database the clips share (:func:`by_database`),
every seed of every window of that database generated from the window's start and scored (:func:`run_generator`),
its cost measured; a generator that fails is kept as empty rows.

The runner reads of a generator only what :class:`animsynth.generator.Generator` declares (``query``,
``native_fps``, ``entry_seam``, :meth:`~animsynth.generator.Generator.run_notes`,
:meth:`~animsynth.generator.Generator.outside_cost`, :meth:`~animsynth.generator.Generator.set_label`); no
generator is special-cased by name.

Files of one generator job: per subject and generator ``compare/runs/<subject>/<generator>.csv`` (metrics, one row
per clip x seed), ``<generator>_timing.csv`` (build and generation cost, one row per database,
:data:`TIMING_COLUMNS`) and ``<generator>_showcase.npz`` (the subject's showcase clip's start and generated frames:
:func:`save_shown` / :func:`load_shown`); with ``compare.long_track`` on, the long track's files from the same
builds (:func:`run_tracks`, :mod:`animsynth.compare.long_track`).
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
from .scoring import References, run_values, score

__all__ = ["TIMING_COLUMNS", "cpu_seconds", "peak_rss_mb", "run_generator", "run_tracks", "run_isolated", "failed_run",
           "generation_query", "native_inputs", "by_database", "showcase_clip", "save_shown", "load_shown"]

log = logging.getLogger("animsynth.compare.runner")

#: the columns of ``<generator>_timing.csv``
TIMING_COLUMNS = ["generator", "database", "clips", "database_frames", "build_cpu_s", "build_wall_s",
                  "generate_cpu_s", "generate_wall_s", "frames_generated", "peak_rss_mb"]


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
    """Fit ``generator`` once on every database the clips share, generate every seed of every clip from the
    clip's start, score.

    Parameters
    ----------
    clips : list of Clip
    generator : a name of :data:`animsynth.compare.generators.names.GENERATORS`
    cfg : the ``compare`` block (with the re-sequencing study's ``stisomap`` block added)
    master_seed : the config's ``seed``
    roles : joint-role overrides (config ``joint_roles``)
    showcase : (clip spec, seed index[, required]) whose motion is returned (:func:`showcase_clip`; ``required``,
        default true: a build that stops on the showcase clip stops the job)

    Returns
    -------
    metrics : DataFrame, one row per clip x seed (:data:`KEY_COLUMNS` + :data:`METRIC_NAMES` + ``note``):
        a clip whose database the generator cannot be built on (its ``fit`` raises ValueError, e.g. a
        motion graph without transitions) keeps its rows with no values and ``note`` = "not built: <why>"
    timing : DataFrame, one row per database (:data:`TIMING_COLUMNS`): its clips, CPU (:func:`cpu_seconds`, child
        processes included, and the generator's :meth:`~animsynth.generator.Generator.outside_cost`) and wall
        seconds of the build and of the generation, the job's peak resident memory so far (:func:`peak_rss_mb`)
    shown : Motion or None, the showcase clip's start and generated frames joined
        (``meta["context"]``: start frames)

    A user generator (``compare.user_generators``) that fails in any way (:class:`UserGeneratorError`) stops at
    its first failure: one error line, and every row of it empty (:func:`failed_run`).
    """
    return run_tracks(clips, generator, dict(cfg, long_track=None), master_seed, roles, showcase)[:3]


def run_tracks(clips: list[Clip], generator: str, cfg: dict, master_seed: int, roles: dict | None = None,
               showcase: tuple[str, int] | None = None, refs: References | None = None):
    """:func:`run_generator` and, from the same build of each database, the long track
    (:mod:`animsynth.compare.long_track`, ``cfg["long_track"]``: :func:`~.long_track.long_settings` of the row).

    Returns
    -------
    metrics, timing, shown : as :func:`run_generator`
    long : dict or None (the track off): ``metrics`` (one row per long context x seed,
        :data:`~.long_track.LONG_COLUMNS`), ``timing`` (one row per database with a long context,
        :data:`~.long_track.LONG_TIMING_COLUMNS`), ``shown`` (the first long context's start and seed 0's frames)

    ``refs``: the job's :class:`~animsynth.compare.scoring.References`, shared by the rows it runs on the same
    clips (made here if not given).
    """
    from .generators.user import UserGeneratorError, close_processes

    try:
        return _run_generator(clips, generator, cfg, master_seed, roles, showcase, refs or References())
    except UserGeneratorError as exc:
        return failed_run(clips, generator, cfg, str(exc), showcase)
    finally:
        close_processes()  # a user generator's child process ends with its job


def failed_run(clips: list[Clip], generator: str, cfg: dict, why: str, showcase: tuple | None = None):
    """The files of a generator that could not run at all: ``why`` logged as one error line (and printed to
    stderr, the run's console), every clip x seed row with no values and ``note`` = "failed: <why>", every timing
    row empty, and as the showcase the showcase clip's start alone (no generated frame; ``meta["note"]``)."""
    line = " ".join(why.split())
    log.error("%s", line)
    print(f"animsynth: ERROR: {line}", file=sys.stderr)
    from .long_track import long_contexts, long_settings, not_run_rows

    rows, trows, shown = [], [], None
    shown_id = None if showcase is None else showcase_clip(clips, showcase[0])
    grouped = by_database(clips)
    for key, cs in grouped.items():
        r, sh = _not_run(cs, generator, int(cfg["seeds"]), f"failed: {line}", shown_id)
        rows += r
        shown = shown or sh
        trows.append(_timing_row(generator, key, cs))
    long = None
    ls = long_settings(cfg.get("long_track"), generator)
    if ls:
        ids = long_contexts(grouped, ls["contexts_per_subject"])
        lcs = [c for c in clips if c.clip in ids]
        long = {"rows": not_run_rows(lcs, generator, ls["seeds"], f"did not run: failed: {line}"), "timing": [],
                "shown": _start_only(lcs[0], generator, f"failed: {line}") if lcs else None}
    return (pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"]), pd.DataFrame(trows, columns=TIMING_COLUMNS),
            shown, _long_frames(long))


def _start_only(clip: Clip, generator: str, note: str) -> Motion:
    """The showcase of a generator with no motion for the clip: the start alone, ``meta["note"]`` saying why."""
    start = clip.start
    return Motion(np.asarray(start.values, float), start.skeleton, start.fps, f"{generator} {clip.clip}",
                  {"context": clip.context, "seams": np.zeros(0, np.int64), "note": note})


def _empty_rows(clip: Clip, generator: str, n_seeds: int, note: str) -> list:
    """The metric rows (one per seed, no values, ``note``) of a clip a generator has no motion for."""
    key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
    return [{**key, "seed": i, **{m: np.nan for m in METRIC_NAMES}, "note": note} for i in range(n_seeds)]


def generation_query(gen, clip: Clip) -> dict:
    """What ``gen.generate`` is given besides the start, length and seed, by its declared ``query``
    (:class:`animsynth.generator.Generator`): nothing for ``"start"``; ``trajectory`` = the clip's held-out frames
    after the start (:attr:`Clip.future`) for ``"future_trajectory"``."""
    from ..generator import QUERY_FUTURE_TRAJECTORY, QUERY_START

    if gen.query == QUERY_START:
        return {}
    if gen.query == QUERY_FUTURE_TRAJECTORY:
        return {"trajectory": clip.future}
    raise ValueError(f"generator {gen.name!r}: unknown query {gen.query!r} (one of "
                     f"{[QUERY_START, QUERY_FUTURE_TRAJECTORY]})")


def native_inputs(gen, clip: Clip) -> tuple[dict, dict]:
    """What ``gen.fit`` and ``gen.generate`` are given at the generator's declared native rate ``native_fps``
    (:class:`animsynth.generator.Generator`): ``({"native_clips": database}, {"native_start": start})`` from the
    clip at that rate (:class:`NativeRate`), ``None`` for both when the generator has no native rate or the clip
    does not carry it (then the generator works from the working-rate clips)."""
    nat = None if gen.native_fps is None else clip.at_rate(float(gen.native_fps))
    if nat is None or not nat.database:
        return {"native_clips": None}, {"native_start": None}
    return {"native_clips": nat.database}, {"native_start": nat.start}


def by_database(clips: list[Clip]) -> dict[str, list[Clip]]:
    """The clips grouped by the database they share (``database_id``; a clip without one is its own), in order."""
    out: dict[str, list[Clip]] = {}
    for c in clips:
        out.setdefault(c.database_id or c.clip, []).append(c)
    return out


def _timing_row(generator: str, key: str, cs: list[Clip], **cost) -> dict:
    """One build's timing row (:data:`TIMING_COLUMNS`); the costs not given are empty."""
    row = {"generator": generator, "database": key, "clips": len(cs),
           "database_frames": int(sum(d.n_frames for d in cs[0].database)), "build_cpu_s": np.nan,
           "build_wall_s": np.nan, "generate_cpu_s": np.nan, "generate_wall_s": np.nan, "frames_generated": 0,
           "peak_rss_mb": peak_rss_mb()}
    row.update(cost)
    return row


def _not_run(cs, generator, n_seeds, note, shown_id):
    """The rows of every clip of one database a generator has no motion for (and its showcase: the start alone)."""
    rows = [r for c in cs for r in _empty_rows(c, generator, n_seeds, note)]
    shown = next((_start_only(c, generator, note) for c in cs if c.clip == shown_id), None)
    return rows, shown


def _fit(generator, cs, cfg, key, shown, long_frames: int = 0):
    """A fitted generator for the database of ``cs`` with its build cost, or ``(None, why)`` when the cost guard
    refuses it or its build stops with a reason (``shown``: (showcase clip id, required)). The guard's estimate
    counts every frame the build will serve: each window's seeds and ``long_frames``, the long track's."""
    from .cost import guard as cost_guard

    c0 = cs[0]
    db_frames = int(sum(d.n_frames for d in c0.database))
    generated = sum(c.length for c in cs) * int(cfg["seeds"]) + int(long_frames)
    level, line = cost_guard(generator, key, db_frames, cfg, generated, 1)
    if level == "refuse":
        log.error("%s", line)
        print(f"animsynth: compare: {line}", file=sys.stderr)
        return None, f"not run: {line}"
    if level == "warn":
        log.warning("%s", line)
    gen = make_generator(generator, cfg)
    gen.set_label(key)
    gen.warm_up()  # its first-use imports, outside the build's time (whichever row of a job builds first)
    fit_native, _ = native_inputs(gen, c0)
    c0_cpu, w0 = cpu_seconds(), time.perf_counter()
    try:
        gen.fit(c0.database, **fit_native)
    except ValueError as exc:  # e.g. a motion graph without transitions on a short database
        if shown[1] and any(c.clip == shown[0] for c in cs):
            raise ValueError(f"{generator} cannot be built on the showcase clip {shown[0]} ({exc}); choose "
                             "another with config key 'compare.showcase.clip'") from exc
        log.warning("%s cannot be built on %s: %s", generator, key, exc)
        return None, f"not built: {exc}"
    # work outside this process (a user generator's child) is not among its finished children until it ends
    cost = {"build_cpu_s": cpu_seconds() - c0_cpu + gen.outside_cost()["cpu_s"],
            "build_wall_s": time.perf_counter() - w0}
    return gen, cost


def _run_windows(gen, generator, cs, cfg, master_seed, roles, refs, shown_id):
    """Every seed of every window ``cs`` of one database from the fitted ``gen``, scored: (rows, showcase motion or
    None, generation CPU and wall seconds, frames generated, the largest outside memory)."""
    mcfg = cfg["metrics"]
    rows, shown, gen_cpu, gen_wall, frames, rss = [], None, 0.0, 0.0, 0, 0.0
    for clip in cs:
        gen.set_label(clip.clip)
        seeds = clip_seeds(master_seed, cfg["seed"], clip.clip, cfg["seeds"])
        key = {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}
        ref = refs(clip, mcfg, roles)  # L2P normalised by this clip's own database
        query = {**generation_query(gen, clip), **native_inputs(gen, clip)[1]}
        start, feats = clip.start, []
        for i, s in enumerate(seeds):
            c0, w0 = cpu_seconds(), time.perf_counter()
            m = gen.generate(start, clip.length, s, **query)
            outside = gen.outside_cost()
            gen_cpu += cpu_seconds() - c0 + outside["cpu_s"]
            gen_wall += time.perf_counter() - w0
            rss = max(rss, outside["rss_mb"])
            row, f = score(clip, ref, m, generator, mcfg, roles, entry_seam=gen.entry_seam)
            feats.append(f)
            rows.append({**key, "seed": i, **row, "note": ""})
            if (clip.clip, i) == shown_id:
                shown = _shown(clip, m, f"{generator} {clip.clip} seed {i}", gen.entry_seam)
        per_run = run_values(gen, feats)  # the generator's own count, the spread over seeds: one value per clip
        for r in rows[-len(seeds):]:
            r.update(per_run)
        frames += clip.length * len(seeds)
    return rows, shown, gen_cpu, gen_wall, frames, rss


def _shown(clip: Clip, m: Motion, name: str, entry_seam: bool) -> Motion:
    """The start and the generated motion joined (``name``: generator, clip and seed), its seams (the entry one too
    where it is a seam, as scored)."""
    seams = np.asarray(m.meta["seams"], np.int64)
    if entry_seam:
        seams = np.union1d(seams, [0])
    return Motion(np.vstack([clip.start.values, m.values]), m.skeleton, m.fps, name,
                  {"context": clip.context, "seams": seams + clip.context})


def showcase_clip(clips: list[Clip], spec: str | None) -> str | None:
    """The id of the clip a showcase ``spec`` names among ``clips``: the clip itself (``<group>/<trial>@<frame>``),
    the first clip of a held-out trial (``<group>/<trial>``), or with ``None`` the first clip; ``None`` when the
    spec names none of them."""
    if not clips:
        return None
    if spec is None:
        return clips[0].clip
    for c in clips:
        if c.clip == spec or c.clip.split("@", 1)[0] == spec:
            return c.clip
    return None


def _run_generator(clips, generator, cfg, master_seed, roles, showcase, refs):
    """:func:`run_tracks`: one build per database (:func:`by_database`), every window and seed of it from that
    build, then the database's long contexts from the same build (``refs``: the job's references: each database
    motion's forward kinematics and each clip's reference, once for the whole job)."""
    from .long_track import long_contexts, long_frames, long_settings, not_run_rows

    rows, trows, shown = [], [], None
    shown_id = (None, 0) if showcase is None else (showcase_clip(clips, showcase[0]), int(showcase[1]))
    required = showcase is not None and (len(showcase) < 3 or bool(showcase[2]))
    grouped = by_database(clips)
    ls = long_settings(cfg.get("long_track"), generator)
    long_ids = set(long_contexts(grouped, ls["contexts_per_subject"])) if ls else set()
    long = {"rows": [], "timing": [], "shown": None, "said": set()} if ls else None
    for key, cs in grouped.items():
        lcs = [c for c in cs if c.clip in long_ids]
        n_long = len(lcs) * ls["seeds"] * long_frames(ls, cfg["fps"]) if lcs else 0
        gen, cost = _fit(generator, cs, cfg, key, (shown_id[0], required), n_long)
        if gen is None:
            r, sh = _not_run(cs, generator, int(cfg["seeds"]), cost, shown_id[0])
            rows += r
            shown = shown or sh
            trows.append(_timing_row(generator, key, cs))
            if lcs:
                long["rows"] += not_run_rows(lcs, generator, ls["seeds"], f"did not run: {cost}")
                long["shown"] = long["shown"] or _start_only(lcs[0], generator, cost)
            continue
        r, sh, g_cpu, g_wall, frames, rss = _run_windows(gen, generator, cs, cfg, master_seed, roles, refs, shown_id)
        rows += r
        shown = shown or sh
        trows.append(_timing_row(generator, key, cs, **cost, generate_cpu_s=g_cpu, generate_wall_s=g_wall,
                                 frames_generated=frames, peak_rss_mb=max(peak_rss_mb(), rss,
                                                                          gen.outside_cost()["rss_mb"])))
        log.info("%s on %s: build %.3f s CPU, %d windows x %d seeds: %d frames in %.3f s CPU", generator, key,
                 cost["build_cpu_s"], len(cs), int(cfg["seeds"]), frames, g_cpu)
        if lcs:  # the long track from the same build
            r, sh, lcost = _run_long(gen, generator, lcs, ls, cfg, master_seed, roles, refs, long["said"])
            long["rows"] += r
            long["shown"] = long["shown"] or sh or _start_only(lcs[0], generator, r[0]["note"])
            long["timing"].append({**lcost, "database": key})
            log.info("%s on %s, long track: %d contexts x %d seeds: %d frames, %.3f s CPU generating, %.3f s CPU "
                     "scoring", generator, key, len(lcs), ls["seeds"], lcost["frames_generated"],
                     lcost["generate_cpu_s"], lcost["score_cpu_s"])
    metrics = pd.DataFrame(rows, columns=KEY_COLUMNS + METRIC_NAMES + ["note"])
    return metrics, pd.DataFrame(trows, columns=TIMING_COLUMNS), shown, _long_frames(long)


def _run_long(gen, generator: str, cs: list[Clip], settings: dict, cfg: dict, master_seed: int, roles, refs,
             said: set) -> tuple[list[dict], object, dict]:
    """Every long seed of the windows ``cs`` (one database's chosen long contexts) from the fitted ``gen``
    (:mod:`animsynth.compare.long_track`).

    Parameters
    ----------
    gen : the fitted generator (the short track's build of this database)
    generator : its row name
    cs : list of Clip, the database's long contexts (:func:`~.long_track.long_contexts`)
    settings : :func:`~.long_track.long_settings` of the row
    cfg : the job's ``compare`` config (``fps``, ``seed``, ``seeds``, ``metrics``)
    master_seed : the config's ``seed``
    roles : joint-role overrides
    refs : the job's :class:`~animsynth.compare.scoring.References`
    said : the "did not run" reasons already logged by this job (a reason is logged once)

    Returns
    -------
    rows : list of dict, one per window x seed (:data:`~.long_track.LONG_COLUMNS`)
    shown : Motion or None, the first window's start and seed 0's frames joined
    cost : dict, this database's row of :data:`~.long_track.LONG_TIMING_COLUMNS`
    """
    from .long_track import generate_long, long_frames, not_run_rows, say_once

    n = long_frames(settings, cfg["fps"])
    n_seeds, mcfg = settings["seeds"], cfg["metrics"]
    rows, shown = [], None
    cost = {"generator": generator, "contexts": len(cs), "seeds": n_seeds, "frames_generated": 0,
            "generate_cpu_s": 0.0, "generate_wall_s": 0.0, "score_cpu_s": 0.0}
    for clip in cs:
        gen.set_label(f"{clip.clip} long")
        seeds = clip_seeds(master_seed, cfg["seed"], clip.clip, max(n_seeds, int(cfg["seeds"])))[:n_seeds]
        query = {**generation_query(gen, clip), **native_inputs(gen, clip)[1]}
        feats, these = [], []
        for i, s in enumerate(seeds):
            c0, w0 = cpu_seconds(), time.perf_counter()
            m, why = generate_long(gen, clip, n, s, query)
            cost["generate_cpu_s"] += cpu_seconds() - c0 + gen.outside_cost()["cpu_s"]
            cost["generate_wall_s"] += time.perf_counter() - w0
            if m is None:
                say_once(generator, clip, why, said)
                these += not_run_rows([clip], generator, 1, f"did not run: {why}")
                these[-1]["seed"] = i
                continue
            c0 = cpu_seconds()
            row, f = score(clip, refs(clip, mcfg, roles), m, generator, mcfg, roles, track="long", entry_seam=gen.entry_seam)
            cost["score_cpu_s"] += cpu_seconds() - c0
            cost["frames_generated"] += n
            feats.append(f)
            these.append({"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator,
                          "seed": i, **row, "note": ""})
            if i == 0 and shown is None:
                shown = _shown(clip, m, f"{generator} {clip.clip} seed 0, {settings['seconds']:g} s", gen.entry_seam)
        if feats and len(feats) == len(seeds):  # the spread over seeds and the generator's own counts
            per_run = run_values(gen, feats, track="long")
            for r in these:
                r.update(per_run)
        rows += these
    return rows, shown, cost


def _long_frames(long: dict | None) -> dict | None:
    """The long track's results as frames: ``metrics`` (:data:`~.long_track.LONG_COLUMNS`), ``timing``
    (:data:`~.long_track.LONG_TIMING_COLUMNS`) and ``shown``; ``None`` when the track is off."""
    from .long_track import LONG_COLUMNS, LONG_TIMING_COLUMNS

    if long is None:
        return None
    return {"metrics": pd.DataFrame(long["rows"], columns=LONG_COLUMNS),
            "timing": pd.DataFrame(long["timing"], columns=LONG_TIMING_COLUMNS), "shown": long["shown"]}




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
                 outputs, refs: References | None = None) -> tuple:
    """:func:`run_tracks` as one workflow job runs it: with one BLAS thread (the job's threads: 1; the simplex
    searches make many small LAPACK calls) and, for a user generator (``compare.user_generators``), a guard on the
    project (the working directory) and the folder of the job's ``outputs`` (paths), which it may not change
    (``refs``: the job's references, :func:`run_tracks`)."""
    from threadpoolctl import threadpool_limits

    if generator in (cfg.get("user_generators") or {}):
        outs = [os.path.dirname(os.path.abspath(p)) for p in outputs]
        cfg = dict(cfg, user_guard=list(dict.fromkeys([os.getcwd(), os.path.commonpath(outs)])))
    with threadpool_limits(1, user_api="blas"):
        return run_tracks(clips, generator, cfg, master_seed, roles, showcase, refs)
