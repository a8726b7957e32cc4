"""The 20-second track: each subject's chosen held-out windows continued for ``compare.long_track.seconds`` from
the same fitted generator as the 2-s track (one build per database, shared by both tracks), scored on the long
track's records (:func:`animsynth.compare.measures.metric_table.on_track` ``"long"``).

* :func:`long_settings` -- the long track's settings of one generator row (``None``: the track is off);
* :func:`long_contexts` -- the windows a subject continues for the long track: spread evenly over its databases;
* :func:`generate_long` -- one long motion, or why a generator has none;
* :func:`not_run_rows` -- the rows of windows a generator has no long motion for (``note`` says why);
* the run itself, from the 2-s track's build of each database: :func:`animsynth.compare.runner.run_tracks`.

The contexts and seeds are the short track's (the first ``seeds`` of each window's short-track seeds,
:func:`animsynth.compare.protocol.clip_seeds`), so both tracks start from the same frames. A generator whose
``generate`` says it cannot continue this long (ValueError, NotImplementedError), or returns another number of
frames than asked, gets rows with no values and ``note`` = "did not run: <why>" (logged once per job): never a
silently shorter motion; any other exception stops the job. So does a generator whose declared query is the held-out
future (:data:`animsynth.generator.QUERY_FUTURE_TRAJECTORY`: the replay of the capture, motion matching queried with
the capture's path) when that future, the frames of the held-out stretch after the start, is shorter than the long
run, since a query that stops there would be another method; where the held-out stretch does last that long after
the start (a long trial held out whole), these rows run and hold values.

Files of one generator job: ``compare/runs/<subject>/<generator>_long.csv`` (:data:`LONG_COLUMNS`),
``<generator>_long_timing.csv`` (:data:`LONG_TIMING_COLUMNS`: the long track's generation and scoring CPU, so a
job's CPU splits by track) and ``<generator>_long_showcase.npz`` (the first long context's seed 0).
"""

from __future__ import annotations

import logging

import numpy as np

from .measures.metric_table import KEY_COLUMNS, track_names
from .protocol import Clip

__all__ = ["LONG_NAMES", "LONG_COLUMNS", "LONG_TIMING_COLUMNS", "long_settings", "long_frames", "long_contexts", "not_run_rows",
           "generate_long", "say_once"]

log = logging.getLogger("animsynth.compare.long_track")

#: the long track's metric columns (``compare/metrics_long.csv``)
LONG_NAMES = track_names("long")
#: the columns of ``<generator>_long.csv``
LONG_COLUMNS = KEY_COLUMNS + LONG_NAMES + ["note"]
#: the columns of ``<generator>_long_timing.csv``: one row per database with a long context (``score_cpu_s``: the
#: scoring, with each context's reference where no earlier row or track of the job made it:
#: :class:`~animsynth.compare.scoring.References`)
LONG_TIMING_COLUMNS = ["generator", "database", "contexts", "seeds", "frames_generated", "generate_cpu_s",
                       "generate_wall_s", "score_cpu_s"]


def long_frames(settings: dict, fps: float) -> int:
    """The frames one long run generates: ``settings["seconds"]`` (:func:`long_settings`) at the working rate."""
    return int(round(float(settings["seconds"]) * float(fps)))


def long_settings(block: dict | None, generator: str) -> dict | None:
    """The long track's settings of one generator row: ``{"seconds", "contexts_per_subject", "seeds"}`` (its seeds
    from ``seeds_by_generator`` where listed), or ``None`` when ``block`` (``compare.long_track``) is null or has
    ``enabled: false``."""
    if not block or not block.get("enabled", True):
        return None
    seeds = (block.get("seeds_by_generator") or {}).get(generator, block["seeds"])
    return {"seconds": float(block["seconds"]), "contexts_per_subject": int(block["contexts_per_subject"]),
            "seeds": int(seeds)}


def long_contexts(by_db: dict[str, list[Clip]], n: int) -> list[str]:
    """The ids of the ``n`` windows a subject continues on the long track: the first window of databases chosen
    evenly along the subject's databases (``by_db``: :func:`animsynth.compare.runner.by_database`, in the clips'
    order); with more contexts than databases, the next windows of each database in turn."""
    lists = list(by_db.values())
    if n <= len(lists):
        picks = np.unique(np.round(np.linspace(0, len(lists) - 1, n)).astype(int)) if n > 0 else []
        return [lists[i][0].clip for i in picks]
    out: list[str] = []
    for k in range(max(len(cs) for cs in lists)):
        out += [cs[k].clip for cs in lists if k < len(cs)]
    return out[:n]


def _key(clip: Clip, generator: str) -> dict:
    return {"clip": clip.clip, "group": clip.group, "protocol": clip.protocol, "generator": generator}


def not_run_rows(clips: list[Clip], generator: str, n_seeds: int, note: str) -> list[dict]:
    """The long rows (one per seed, no values, ``note``) of windows a generator has no long motion for."""
    return [{**_key(c, generator), "seed": i, **dict.fromkeys(LONG_NAMES, np.nan), "note": note}
            for c in clips for i in range(n_seeds)]


def generate_long(gen, clip: Clip, n: int, seed: int, query: dict):
    """``gen``'s ``n`` frames from the clip's start, or ``(None, why)`` when it says it cannot continue this long
    (a ValueError, as fairmotion's walk into a dead end, or NotImplementedError) or returns another number of
    frames. Any other exception is a bug, not a limit: it stops the job as on the short track (so does a user
    generator's own failure, :class:`UserGeneratorError`)."""
    from ..generator import QUERY_FUTURE_TRAJECTORY
    from .generators.user import UserGeneratorError

    if gen.query == QUERY_FUTURE_TRAJECTORY and clip.future.n_frames < n:
        return None, (f"its query is the held-out future, {clip.future.n_frames} frames after the start, {n} asked "
                      "for")
    try:
        m = gen.generate(clip.start, n, seed, **query)
    except UserGeneratorError:
        raise
    except (ValueError, NotImplementedError) as exc:  # a generator that cannot continue this long says why
        return None, " ".join(f"{type(exc).__name__}: {exc}".split())
    if m.n_frames != n:
        return None, f"returned {m.n_frames} frames, {n} asked for"
    return m, ""


def say_once(generator: str, clip: Clip, why: str, said: set) -> None:
    """Log a generator's reason for not running the long track, once per job."""
    if why in said:
        return
    said.add(why)
    log.warning("compare: %s did not run the long track from %s: %s", generator, clip.clip, why)
