"""The compare family's metric table: one record per column of ``metrics.csv`` (and of the long track's table).

Every place that lists metrics reads it: the scoring (:func:`animsynth.compare.scoring.score` loops over the records
of a track, grouped by what they need, and calls the computation each record names; ``animsynth score`` leaves
empty what a file lacks, by :attr:`Metric.needs`), the runner (the columns of ``metrics.csv``), the tables (unit,
direction, the results' headings, the budget sweep's columns), the figures (panel titles, direction), the verdicts
(units, directions, margins, the exploratory metrics, the skating claims) and the docs' metric table
(``docs/compare/metrics.md``, rendered by :mod:`.metric_docs`). No numpy and no import of the computations: a
record names its computation by a path (``"<module>:<function>"`` in :mod:`animsynth.compare.measures`, imported on
first use by :func:`computation`), so the tables, verdicts and figures read the table without the metrics' code.

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
from dataclasses import dataclass

__all__ = ["Metric", "METRICS", "METRIC_NAMES", "KEY_COLUMNS", "TRACKS", "SENSITIVITY_SPEEDS", "SENSITIVITY_METRICS",
           "COVERAGE_TIMES_S", "EDGE_S", "at_speed", "after_time", "at_edge", "NEEDS", "PER_RUN", "MOTION_NEEDS",
           "RUN_NEEDS", "metric", "metric_or_blank", "names_needing", "on_track", "track_names", "computation",
           "by_computation", "SWEEP_METRICS", "SWEEP_PANELS", "FIGURE_METRICS", "RESULT_METRICS", "LONG_RESULT_METRICS",
           "EXPLORATORY_METRICS", "SKATING_CLAIM_METRICS"]

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
    exploratory : bool, a metric of the exploratory table (:data:`EXPLORATORY_METRICS`)
    skating_claim : bool, a skating metric of the claims (:data:`SKATING_CLAIM_METRICS`): a claim on it compares
        generators whose feet touch the floor
    margin : float or None, the smallest difference a user would care about, in the metric's units, declared before
        any run (never tuned to results): a claim on the metric takes it unless the claim gives its own
        (``compare.claims[i].min_effect``) or ``compare.verdicts.min_effect`` overrides it; ``None``: no margin
        (the metric is descriptive, or no claim or vote uses it)
    margin_why : str, one sentence of why that size matters to a user
    compute : str, the computation that gives its value: ``"<module>:<function>"`` in
        :mod:`animsynth.compare.measures` (:func:`computation`). It is called once per motion (``needs`` in
        :data:`MOTION_NEEDS`: with a :class:`~.scored.ScoredMotion`) or once per clip and generator (``needs`` in
        :data:`RUN_NEEDS`: with a :class:`~.scored.RunOutputs`) and returns ``{column: value}`` for at least every
        record that names it (one computation may fill several records: foot skating gives three)
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
_SHORT, _LONG = ("short",), ("long",)
_SKATE_SHARE = Metric("skate_share", "share of contact joint-frames", "lower", "floor", "skate share",
                      "foot skating: share of contact frames", exploratory=True, skating_claim=True,
                      margin=0.05, margin_why="5 percentage points of contact joint-frames: in a 2-s walk (about four "
                      "stances of 15 frames) some 3 more sliding frames per foot joint, about the smallest slide an "
                      "animator would go in to fix", compute="skating:score_foot_skating")
_SKATING_RATIO_GMD = Metric("skating_ratio_gmd", "share of frame steps (GMD)", "lower", "floor", "GMD skating ratio",
                            "skating ratio (GMD-style)", margin=0.05,
                            margin_why="5 percentage points of frame steps, as for the skate share",
                            compute="skating:score_skating_ratio_gmd")
_SENSITIVITY = (_SKATE_SHARE, _SKATING_RATIO_GMD)
#: the skating metrics measured again at each of :data:`SENSITIVITY_SPEEDS` (the ``<name>_at_<speed>`` columns,
#: :func:`at_speed`: no direction, the unit of the metric at that speed)
SENSITIVITY_METRICS = tuple(m.name for m in _SENSITIVITY)


def at_speed(name: str, speed: float) -> str:
    """The column of the sensitivity metric ``name`` (:data:`SENSITIVITY_METRICS`) at the speed threshold ``speed``
    (m/s): ``<name>_at_<speed>``."""
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


_COVERAGE_WHY = "5 % of the database's windows: about one second of a 20-s database reached or missed"
_SKATE_WHY = "5 percentage points of contact joint-frames, as for the skate share over the whole run"
_JUMP_WHY = "0.2 m/s within one frame, as for the per-frame velocity jump over the whole run"

#: the key columns of ``metrics.csv``, before :data:`METRIC_NAMES` and ``note``
KEY_COLUMNS = ["clip", "group", "protocol", "generator", "seed"]
#: every record: the short track's in the order of ``metrics.csv``, then the long track's own
METRICS = (
    Metric("contact_share", "share of foot joint-frames", "", "floor", compute="skating:score_foot_skating"),
    _SKATE_SHARE,
    Metric("skate_m_per_contact_frame", "m", "lower", "floor", compute="skating:score_foot_skating"),
    Metric("transition_skate_share", "share of contact joint-frames near seams", "lower", "seams",
           "skate share near seams", "skating near seams: share", exploratory=True, skating_claim=True, margin=0.05,
           margin_why="5 percentage points of the contact joint-frames near seams, as for the skate share",
           compute="skating:score_transition_skating"),
    _SKATING_RATIO_GMD,
    *(Metric(at_speed(m.name, v), f"{m.unit}, {v:g} m/s", "", m.needs, compute="skating:score_skating_sensitivity")
      for m in _SENSITIVITY for v in SENSITIVITY_SPEEDS),
    Metric("velocity_jump_p95", "m/s", "lower", "", "per-frame velocity jump p95 (m/s)",
           "per-frame velocity jump: 95th percentile (m/s)", exploratory=True, margin=0.2,
           margin_why="a change of joint velocity of 0.2 m/s within one frame (7 mm of position at 30 fps), about half "
                      "of a capture's own 95th percentile: smaller pops hide in the capture's own noise",
           compute="jumps:score_frame_jumps"),
    Metric("velocity_jump_max", "m/s", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("velocity_jump_over_capture", "share of frames", "lower", "reference",
           "frames above the capture's largest jump", "share of frames jumping more than the capture's largest",
           compute="jumps:score_jumps_over_capture"),
    Metric("accel_jump_p95", "m/s^2", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("accel_jump_max", "m/s^2", "lower", "", compute="jumps:score_frame_jumps"),
    Metric("accel_jump_over_capture", "share of frames", "lower", "reference", compute="jumps:score_jumps_over_capture"),
    Metric("n_seams", "seams", "", "seams", compute="transitions:score_seam_count"),
    Metric("seams_per_s", "1/s", "", "seams", compute="transitions:score_seam_count"),
    Metric("transitions_kept", "transitions before pruning", "", "generator", title="transitions kept (before pruning)",
           compute="transitions:run_transitions_kept"),
    # at the seams a generator reports (secondary: they trust the generator's own seams)
    Metric("velocity_jump", "m/s", "", "seams", "seam velocity jump (m/s)", "velocity jump at reported seams (m/s)",
           compute="transitions:score_seam_jumps"),
    Metric("velocity_jump_ratio", "x capture median", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("velocity_jump_pct", "percentile in capture", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump", "m/s^2", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump_ratio", "x capture median", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("accel_jump_pct", "percentile in capture", "", "seams", compute="transitions:score_seam_jumps"),
    Metric("ldlj", "log dimensionless jerk", "higher", "", "LDLJ",
           "smoothness: log dimensionless jerk (higher smoother)", compute="smoothness:score_ldlj"),
    Metric("sparc", "spectral arc length", "higher", "", compute="smoothness:score_sparc"),
    Metric("l2p", "LAFAN1 L2P (clip database statistics)", "lower", "database", "L2P", "L2P vs held-out continuation",
           exploratory=True, margin=0.25,
           margin_why="a quarter of the database's own per-joint position standard deviation (the unit L2P is "
                      "normalised by): a smaller gap to the capture is not a different continuation",
           compute="ground_truth:score_l2p", tracks=_SHORT),
    Metric("l2p_m", "m", "lower", "reference", "L2P (m)", compute="ground_truth:score_l2p_m", tracks=_SHORT),
    Metric("l2q", "LAFAN1 L2Q", "lower", "reference", compute="ground_truth:score_l2q", tracks=_SHORT),
    Metric("npss", "NPSS", "lower", "reference", title="NPSS vs held-out continuation",
           compute="ground_truth:score_npss", tracks=_SHORT),
    Metric("coverage", "share of database windows", "higher", "database", "coverage", "coverage of database windows",
           exploratory=True, margin=0.05, margin_why=_COVERAGE_WHY, compute="windows:score_windows"),
    Metric("local_diversity_m", "m", "", "database", compute="windows:score_windows"),
    Metric("seed_diversity_m", "m", "higher", "seeds", title="diversity across seeds (m)",
           compute="windows:run_seed_diversity"),
    Metric("novelty_median_m", "m", "", "database", "novelty (m)", "novelty: distance to nearest database frame (m)",
           margin=0.01, margin_why="1 cm median distance to the nearest database pose: closer, a pose is a copy with "
                                   "capture noise", compute="windows:score_novelty"),
    Metric("copy_share", "share of frames", "", "database", compute="windows:score_novelty"),
    # the long track's own: what shows only in long runs
    Metric("repetition_share", "share of frames", "lower", "", "repetition", "repetition: share of frames in a "
           "repeated window", margin=0.1, margin_why="a tenth of the run (2 s of 20 s) inside windows that replay an "
           "earlier second: one more pass of a 2-s loop, about the least a viewer notices as a loop",
           compute="repetition:score_repetition", tracks=_LONG),
    Metric("still_share", "share of frames", "", "", compute="root:score_still", tracks=_LONG),
    Metric("freezing_share", "share of frames beyond the capture's", "lower", "reference", "freezing",
           "freezing: still beyond the capture", margin=0.05, margin_why="1 s of a 20-s run standing still where the "
           "person moved: a stop a user sees as the character getting stuck", compute="root:score_freezing",
           tracks=_LONG),
    Metric("drift_share", "share of frames", "lower", "database", "drift", "drift: root height or tilt outside the "
           "capture's range", margin=0.05, margin_why="1 s of a 20-s run with the body sunk, floating or keeled over "
           "beyond anything the capture does", compute="root:score_drift", tracks=_LONG),
    *(Metric(after_time("coverage", t), "share of database windows", "higher", "database",
             margin=0.05, margin_why=_COVERAGE_WHY, compute="over_time:score_coverage_over_time", tracks=_LONG,
             min_seconds=float(t))
      for t in COVERAGE_TIMES_S),
    *(Metric(at_edge("skate_share", w), "share of contact joint-frames" + (", last minus first" if w == "change" else ""),
             "lower", "floor", skating_claim=True, margin=0.05, margin_why=_SKATE_WHY,
             compute="over_time:score_skating_first_last", tracks=_LONG, min_seconds=2 * EDGE_S)
      for w in ("first", "last", "change")),
    *(Metric(at_edge("velocity_jump_p95", w), "m/s" + (", last minus first" if w == "change" else ""), "lower", "",
             margin=0.2, margin_why=_JUMP_WHY, compute="over_time:score_jumps_first_last", tracks=_LONG,
             min_seconds=2 * EDGE_S)
      for w in ("first", "last", "change")),
)
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
    """The function a record names (:attr:`Metric.compute`, ``"<module>:<function>"``), imported on first use."""
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
        raise ValueError("a metric name is in the table twice")
    first_of: dict = {}
    for m in METRICS:
        _check_record(m, first_of)
    for what, names, text in (("SWEEP_METRICS", SWEEP_METRICS, None), ("SWEEP_PANELS", SWEEP_PANELS, "title"),
                              ("FIGURE_METRICS", FIGURE_METRICS, "title"), ("RESULT_METRICS", RESULT_METRICS, "label")):
        for n in names:
            if n not in _BY_NAME or (text and not getattr(_BY_NAME[n], text)):
                raise ValueError(f"{what}: {n!r} is not a metric of the table" + (f" with a {text}" if text else ""))
    if not set(SWEEP_PANELS) <= set(SWEEP_METRICS):
        raise ValueError("SWEEP_PANELS: a panel is not a column of the sweep table")


_check()
