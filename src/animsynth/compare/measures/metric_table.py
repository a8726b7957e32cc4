"""The compare family's metric table: one record per column of ``metrics.csv`` (and of the long track's table),
collected from the measure modules.

Each measure module of :mod:`animsynth.compare.measures` declares the records of the columns it computes beside
their computations, in a module-level tuple ``RECORDS`` of :class:`~.metric_record.Metric`; :data:`METRICS` is
theirs, module after module: first the modules of :data:`MEASURE_MODULES` in that order (the column order of
``metrics.csv`` and of the long track's table), then every other module of the package that declares records, by
name. A new metric in an existing module, or a new measure module, is thus no edit of this table; the import checks
every record (:func:`_check`: known direction, needs and tracks, a unique name, a computation of its own module
that exists).

Every place that lists metrics reads the table: the scoring (:func:`animsynth.compare.scoring.score` loops over the
records of a track, grouped by what they need, and calls the computation each record names; ``animsynth score``
leaves empty what a file lacks, by :attr:`Metric.needs`), the runner (the columns of ``metrics.csv``), the tables
(unit, direction, the results' headings, the budget sweep's columns), the figures (panel titles, direction), the
verdicts (units, directions, margins, the exploratory metrics, the skating claims) and the docs' metric table
(``docs/compare/metrics.md``, rendered by :mod:`.metric_docs`). Importing it imports the measure modules (numpy and
the package's kinematics), none of the heavy libraries (scikit-learn, scipy.stats, numba, matplotlib): their
computations import what else they need on first call.

Tracks
    :data:`TRACKS`: ``"short"`` (the 2-s continuation of every held-out start, ``metrics.csv``) and ``"long"``
    (20 s from the same starts). A record says on which it is computed (:attr:`Metric.tracks`): the measures
    against a ground truth of the same length (L2P, L2Q, NPSS) on the short track only, the measures that show
    only in long runs (repetition, freezing, drift, coverage against time, the first against the last seconds) on
    the long track only, the rest on both. :func:`track_names` gives a track's columns; :data:`METRIC_NAMES` the
    short track's (``metrics.csv``).

Selections
    :data:`SWEEP_METRICS` (the budget sweep table's columns), :data:`SWEEP_PANELS` (its figure's panels),
    :data:`FIGURE_METRICS` (the panels of ``metrics.png``), :data:`RESULT_METRICS` (the columns of the results
    page docs/compare/results.md): tuples of names in the order of their table or figure, each name checked against
    :data:`METRICS` on import. :data:`EXPLORATORY_METRICS` (the exploratory table's metrics) and
    :data:`SKATING_CLAIM_METRICS` (a claim on one of them compares generators whose feet touch the floor), in the
    table's order: flags of the records. :data:`SENSITIVITY_METRICS`: the skating metrics whose
    ``<name>_at_<speed>`` records (:func:`at_speed`) the table holds for every :data:`SENSITIVITY_SPEEDS`.
"""

from __future__ import annotations

import importlib
import pkgutil

from .metric_record import (COVERAGE_TIMES_S, EDGE_S, MOTION_NEEDS, NEEDS, PER_RUN, RUN_NEEDS, SENSITIVITY_SPEEDS,
                            TRACKS, Metric, after_time, at_edge, at_speed)
from .skating import SENSITIVITY_METRICS

__all__ = ["Metric", "METRICS", "METRIC_NAMES", "KEY_COLUMNS", "TRACKS", "SENSITIVITY_SPEEDS", "SENSITIVITY_METRICS",
           "COVERAGE_TIMES_S", "EDGE_S", "at_speed", "after_time", "at_edge", "NEEDS", "PER_RUN", "MOTION_NEEDS",
           "RUN_NEEDS", "MEASURE_MODULES", "metric", "metric_or_blank", "names_needing", "on_track", "track_names",
           "computation", "by_computation", "records_of", "SWEEP_METRICS", "SWEEP_PANELS", "FIGURE_METRICS",
           "RESULT_METRICS", "LONG_RESULT_METRICS", "EXPLORATORY_METRICS", "SKATING_CLAIM_METRICS"]

#: the measure modules whose records come first, in this order: the column order of ``metrics.csv`` (the short
#: track's records) and of the long track's table (the long track's own after the shared ones)
MEASURE_MODULES = ("skating", "jumps", "transitions", "smoothness", "ground_truth", "windows", "repetition", "root",
                   "over_time")
#: the table's own modules, never searched for records (the docs page's renderer imports this table)
_TABLE_MODULES = ("metric_record", "metric_table", "metric_docs")


def records_of(package: str, first=(), skip=()) -> tuple[Metric, ...]:
    """The records (each module's ``RECORDS``) of the modules of ``package``: those named in ``first`` in that order,
    then every other module that declares records, by name; the modules in ``skip`` are not imported.

    A module named in ``first`` without ``RECORDS``, ``RECORDS`` that is not a non-empty tuple of :class:`Metric`,
    or a record whose computation (:attr:`Metric.compute`) is not of its own module, is a ``ValueError`` naming the
    module."""
    pkg = importlib.import_module(package)
    found = sorted(i.name for i in pkgutil.iter_modules(pkg.__path__) if i.name not in (*first, *skip))
    out = []
    for name in (*first, *found):
        records = getattr(importlib.import_module(f"{package}.{name}"), "RECORDS", None)
        if records is None and name not in first:
            continue
        if not (isinstance(records, tuple) and records and all(isinstance(m, Metric) for m in records)):
            raise ValueError(f"{package}.{name}: RECORDS must be a non-empty tuple of Metric records")
        for m in records:
            if m.compute.partition(":")[0] != name:
                raise ValueError(f"{package}.{name}: the record {m.name!r} names the computation {m.compute!r}, not "
                                 f"'{name}:<function>' of its own module")
        out.extend(records)
    return tuple(out)


#: the key columns of ``metrics.csv``, before :data:`METRIC_NAMES` and ``note``
KEY_COLUMNS = ["clip", "group", "protocol", "generator", "seed"]
#: every record: the short track's in the order of ``metrics.csv``, then the long track's own
METRICS = records_of(__package__, MEASURE_MODULES, _TABLE_MODULES)
_BY_NAME = {m.name: m for m in METRICS}


def on_track(track: str) -> tuple[Metric, ...]:
    """The records computed on ``track`` (:data:`TRACKS`), in the table's order."""
    if track not in TRACKS:
        raise ValueError(f"unknown track {track!r} (one of {list(TRACKS)})")
    return tuple(m for m in METRICS if track in m.tracks)


def track_names(track: str) -> list[str]:
    """The metric columns of ``track``'s table, in their order (``"short"``: :data:`METRIC_NAMES`)."""
    return [m.name for m in on_track(track)]


#: every metric column of ``metrics.csv`` (the short track), in its order
METRIC_NAMES = track_names("short")

#: the columns of the budget sweep table (medians over clips x seeds)
SWEEP_METRICS = ("transitions_kept", "skate_share", "transition_skate_share", "skating_ratio_gmd", "velocity_jump_p95",
                 "velocity_jump_over_capture", "velocity_jump", "l2p")
#: the panels of the budget sweep's figure (a median column of :data:`SWEEP_METRICS` each)
SWEEP_PANELS = ("transitions_kept", "transition_skate_share", "skate_share", "velocity_jump_p95", "velocity_jump", "l2p")
#: the panels of metrics.png
FIGURE_METRICS = ("skate_share", "transition_skate_share", "velocity_jump_p95", "velocity_jump_over_capture",
                  "skating_ratio_gmd", "ldlj", "l2p", "npss", "coverage", "novelty_median_m", "seed_diversity_m")
#: the columns of the results page docs/compare/results.md
RESULT_METRICS = ("skate_share", "skating_ratio_gmd", "transition_skate_share", "velocity_jump", "velocity_jump_p95",
                  "velocity_jump_over_capture", "ldlj", "l2p", "l2p_m", "coverage", "novelty_median_m")
#: the long track's columns of the results page (the long-only measures beside skating and jumps over 20 s)
LONG_RESULT_METRICS = ("repetition_share", "freezing_share", "drift_share", "coverage_after_5s", "coverage_after_20s",
                       "skate_share", "skate_share_change", "velocity_jump_p95", "velocity_jump_p95_change")
#: the metrics of the exploratory table (with every declared claim's metric)
EXPLORATORY_METRICS = tuple(m.name for m in METRICS if m.exploratory)
#: the skating metrics of the claims: a claim on one of them compares generators whose feet touch the floor
SKATING_CLAIM_METRICS = tuple(m.name for m in METRICS if m.skating_claim)


def metric(name: str) -> Metric:
    """The record of the column ``name`` (``KeyError`` naming the columns when there is none)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no metric {name!r} (one of {list(_BY_NAME)})") from None


def metric_or_blank(name: str) -> Metric:
    """The record of the column ``name``, or for a name outside the table (a declared claim may name any column
    with its own ``direction``) a record with no unit and no direction."""
    return _BY_NAME.get(name) or Metric(name, "", "", "")


def names_needing(*needs: str, track: str = "short") -> tuple[str, ...]:
    """The metrics of ``track`` whose :attr:`Metric.needs` is one of ``needs``, in the table's order."""
    return tuple(m.name for m in on_track(track) if m.needs in needs)


def by_computation(records) -> dict[str, list[str]]:
    """``{computation path: [the names of the records that name it]}``, in the records' order (a computation is
    called once for all the records it fills)."""
    out: dict[str, list[str]] = {}
    for m in records:
        out.setdefault(m.compute, []).append(m.name)
    return out


def computation(path: str):
    """The function a record names (:attr:`Metric.compute`, ``"<module>:<function>"`` in this package)."""
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), name)


def _check_record(m: Metric, first_of: dict) -> None:
    """One record's fields are known; the records of one computation share its needs."""
    if m.better not in ("lower", "higher", "") or m.needs not in NEEDS:
        raise ValueError(f"metric {m.name!r}: better {m.better!r}, needs {m.needs!r}")
    if m.margin is not None and not (m.margin > 0 and m.margin_why):
        raise ValueError(f"metric {m.name!r}: a margin must be positive and say why (margin_why)")
    module, _, func = m.compute.partition(":")
    if not (module.isidentifier() and func.isidentifier()):
        raise ValueError(f"metric {m.name!r}: compute {m.compute!r} is not '<module>:<function>'")
    if not callable(getattr(importlib.import_module(f"{__package__}.{module}"), func, None)):
        raise ValueError(f"metric {m.name!r}: compute {m.compute!r} names no function of its module")
    if not m.tracks or set(m.tracks) - set(TRACKS):
        raise ValueError(f"metric {m.name!r}: tracks {m.tracks!r} (a non-empty subset of {TRACKS})")
    other = first_of.setdefault(m.compute, m)
    if other.needs != m.needs:
        raise ValueError(f"metrics {other.name!r} and {m.name!r} share the computation {m.compute!r} but not their "
                         f"needs ({other.needs!r}, {m.needs!r})")


def _check() -> None:
    """Every record's direction, needs, computation and tracks are known, its name unique; every selection names
    records (a figure's with a title, a table heading's with a label)."""
    if len(_BY_NAME) != len(METRICS):
        twice = sorted({m.name for m in METRICS if sum(o.name == m.name for o in METRICS) > 1})
        raise ValueError(f"metric names in the table twice: {twice}")
    first_of: dict = {}
    for m in METRICS:
        _check_record(m, first_of)
    for what, names, text in (("SWEEP_METRICS", SWEEP_METRICS, None), ("SWEEP_PANELS", SWEEP_PANELS, "title"),
                              ("FIGURE_METRICS", FIGURE_METRICS, "title"), ("RESULT_METRICS", RESULT_METRICS, "label"),
                              ("LONG_RESULT_METRICS", LONG_RESULT_METRICS, None)):
        for n in names:
            if n not in _BY_NAME or (text and not getattr(_BY_NAME[n], text)):
                raise ValueError(f"{what}: {n!r} is not a metric of the table" + (f" with a {text}" if text else ""))
    if not set(SWEEP_PANELS) <= set(SWEEP_METRICS):
        raise ValueError("SWEEP_PANELS: a panel is not a column of the sweep table")


_check()
