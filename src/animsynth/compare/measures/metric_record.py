"""The record of one compare metric (:class:`Metric`) and the names its fields take: what a metric may need
(:data:`NEEDS`), the tracks it may be computed on (:data:`TRACKS`), and the names of the columns one measure repeats
at several settings (:func:`at_speed`, :func:`after_time`, :func:`at_edge`).

Each measure module of :mod:`animsynth.compare.measures` declares the records of the columns it computes, beside
their computations, in a module-level tuple ``RECORDS``; :mod:`.metric_table` collects them into the table. This
module imports nothing but the standard library, so that a measure module reads it without a cycle through the
table.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Metric", "NEEDS", "PER_RUN", "MOTION_NEEDS", "RUN_NEEDS", "TRACKS", "SENSITIVITY_SPEEDS",
           "COVERAGE_TIMES_S", "EDGE_S", "at_speed", "after_time", "at_edge"]

#: what a metric needs besides the generated motion and its start (:attr:`Metric.needs`)
NEEDS = {
    "": "the generated motion alone",
    "reference": "the held-out capture (the ground truth, its own largest jumps, its still frames)",
    "floor": "the floor height (the database's foot heights, or compare.metrics.floor_m)",
    "database": "the clips the generator learned from",
    "seams": "the seams the generator reports",
    "generator": "the generator's own count (its transitions)",
    "seeds": "every seed's motion from one start",
}
#: the needs that a run gives and one scored motion does not: the generator's seams, its count, the spread over seeds
PER_RUN = ("seams", "generator", "seeds")
#: the needs of a computation given one generated motion (:class:`~.scored.ScoredMotion`): :func:`score`'s records
MOTION_NEEDS = ("", "reference", "floor", "database", "seams")
#: the needs of a computation given one generator's run on a clip, every seed (:class:`~.scored.RunOutputs`):
#: the runner's hook, :func:`animsynth.compare.scoring.run_values`
RUN_NEEDS = ("generator", "seeds")
#: the tracks a record may be computed on: the 2-s continuations (``metrics.csv``) and the 20-s runs
TRACKS = ("short", "long")


@dataclass(frozen=True)
class Metric:
    """One column of ``metrics.csv`` (or of the long track's table).

    Attributes
    ----------
    name : str, the column
    unit : str, its unit (the ``unit`` column of ``summary.csv`` and ``winners.csv``, the verdicts' evidence)
    better : str, which way is better: ``"lower"``, ``"higher"`` or ``""`` (a descriptive number)
    needs : str, a key of :data:`NEEDS`: what it needs besides the generated motion and its start
    label : str, its heading in a table (the results page docs/compare/results.md); "" where none shows it
    title : str, its panel title in a figure (``metrics.png``, ``budget_sweep.png``); "" where none shows it
    exploratory : bool, a metric of the exploratory table (:data:`~.metric_table.EXPLORATORY_METRICS`)
    skating_claim : bool, a skating metric of the claims (:data:`~.metric_table.SKATING_CLAIM_METRICS`): a claim
        on it compares generators whose feet touch the floor
    margin : float or None, the smallest difference a user would care about, in the metric's units, declared before
        any run (never tuned to results): a claim on the metric takes it unless the claim gives its own
        (``compare.claims[i].min_effect``) or ``compare.verdicts.min_effect`` overrides it; ``None``: no margin
        (the metric is descriptive, or no claim or vote uses it)
    margin_why : str, one sentence of why that size matters to a user
    compute : str, the computation that gives its value: ``"<module>:<function>"``, a function of the measure
        module that declares the record (:func:`~.metric_table.computation`). It is called once per motion
        (``needs`` in :data:`MOTION_NEEDS`: with a :class:`~.scored.ScoredMotion`) or once per clip and generator
        (``needs`` in :data:`RUN_NEEDS`: with a :class:`~.scored.RunOutputs`) and returns ``{column: value}`` for at
        least every record that names it (one computation may fill several records: foot skating gives three)
    tracks : tuple of str, the :data:`TRACKS` it is computed on
    min_seconds : float, the shortest run (s) the value needs (coverage after 20 s: 20; the first against the last
        2 s: 4); a shorter run gives NaN, and a claim on it with a shorter ``compare.long_track.seconds`` is refused
    """

    name: str
    unit: str
    better: str
    needs: str
    label: str = ""
    title: str = ""
    exploratory: bool = False
    skating_claim: bool = False
    margin: float | None = None
    margin_why: str = ""
    compute: str = ""
    tracks: tuple = TRACKS
    min_seconds: float = 0.0


#: the skating threshold sensitivity speeds (m/s) of the ``*_at_<speed>`` columns
SENSITIVITY_SPEEDS = (0.15, 0.3, 0.5)
#: the times (s) of the coverage-against-time columns, ``coverage_after_<t>s`` (:func:`after_time`)
COVERAGE_TIMES_S = (5, 10, 20)
#: the span (s) of the first and last seconds of a long run (``*_first_2s``, ``*_last_2s``: :func:`at_edge`)
EDGE_S = 2.0


def at_speed(name: str, speed: float) -> str:
    """The column of the sensitivity metric ``name`` (:data:`~.metric_table.SENSITIVITY_METRICS`) at the speed
    threshold ``speed`` (m/s): ``<name>_at_<speed>``."""
    return f"{name}_at_{speed:g}"


def after_time(name: str, seconds: float) -> str:
    """The column of ``name`` over the frames up to ``seconds`` (:data:`COVERAGE_TIMES_S`): ``<name>_after_<s>s``."""
    return f"{name}_after_{seconds:g}s"


def at_edge(name: str, which: str) -> str:
    """The column of ``name`` over the first or the last :data:`EDGE_S` seconds (``which``: ``"first"``, ``"last"``),
    or their difference, last minus first (``"change"``): ``<name>_first_2s``, ``<name>_last_2s``,
    ``<name>_change``."""
    if which not in ("first", "last", "change"):
        raise ValueError(f"which must be 'first', 'last' or 'change', got {which!r}")
    return f"{name}_change" if which == "change" else f"{name}_{which}_{EDGE_S:g}s"
