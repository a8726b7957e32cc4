"""The compare family's metric table: one record per column of ``metrics.csv``.

Every place that lists metrics reads it: the scoring (:func:`animsynth.compare.scoring.score` writes one value per
record a single motion gives; ``animsynth score`` leaves empty what a file lacks, by :attr:`Metric.needs`), the
runner (the columns of ``metrics.csv``), the tables (unit, direction, the results' headings, the budget sweep's
columns), the figures (panel titles, direction) and the verdicts (units, directions, the exploratory metrics, the
skating claims). No numpy, no import of the package: the tables, verdicts and figures read it without importing the
metrics' code or the generators.

Selections
    :data:`SWEEP_METRICS` (the budget sweep table's columns), :data:`SWEEP_PANELS` (its figure's panels),
    :data:`FIGURE_METRICS` (the panels of ``metrics.png``), :data:`RESULT_METRICS` (the columns of the results
    section of docs/compare.md): tuples of names in the order of their table or figure, each name checked against
    :data:`METRICS` on import. :data:`EXPLORATORY_METRICS` (the exploratory table's metrics) and
    :data:`SKATING_CLAIM_METRICS` (a claim on one of them compares generators whose feet touch the floor), in the
    table's order: flags of the records. :data:`SENSITIVITY_METRICS`: the skating metrics whose
    ``<name>_at_<speed>`` records (:func:`at_speed`) the table holds for every :data:`SENSITIVITY_SPEEDS`.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Metric", "METRICS", "METRIC_NAMES", "KEY_COLUMNS", "SENSITIVITY_SPEEDS", "SENSITIVITY_METRICS",
           "at_speed", "NEEDS", "PER_RUN", "metric", "metric_or_blank",
           "names_needing", "SWEEP_METRICS", "SWEEP_PANELS", "FIGURE_METRICS", "RESULT_METRICS", "EXPLORATORY_METRICS",
           "SKATING_CLAIM_METRICS"]

#: what a metric needs besides the generated motion and its start (:attr:`Metric.needs`)
NEEDS = {
    "": "the generated motion alone",
    "reference": "the held-out capture (the ground truth, its own largest jumps)",
    "floor": "the floor height (the database's foot heights, or compare.metrics.floor_m)",
    "database": "the clips the generator learned from",
    "seams": "the seams the generator reports",
    "generator": "the generator's own count (its transitions)",
    "seeds": "every seed's motion from one start",
}
#: the needs that a run gives and one scored motion does not: the generator's seams, its count, the spread over seeds
PER_RUN = ("seams", "generator", "seeds")


@dataclass(frozen=True)
class Metric:
    """One column of ``metrics.csv``.

    Attributes
    ----------
    name : str, the column
    unit : str, its unit (the ``unit`` column of ``summary.csv`` and ``winners.csv``, the verdicts' evidence)
    better : str, which way is better: ``"lower"``, ``"higher"`` or ``""`` (a descriptive number)
    needs : str, a key of :data:`NEEDS`: what it needs besides the generated motion and its start
    label : str, its heading in a table (the results section of docs/compare.md); "" where none shows it
    title : str, its panel title in a figure (``metrics.png``, ``budget_sweep.png``); "" where none shows it
    exploratory : bool, a metric of the exploratory table (:data:`EXPLORATORY_METRICS`)
    skating_claim : bool, a skating metric of the claims (:data:`SKATING_CLAIM_METRICS`): a claim on it compares
        generators whose feet touch the floor
    margin : float or None, the smallest difference a user would care about, in the metric's units, declared before
        any run (never tuned to results): a claim on the metric takes it unless the claim gives its own
        (``compare.claims[i].min_effect``) or ``compare.verdicts.min_effect`` overrides it; ``None``: no margin
        (the metric is descriptive, or no claim or vote uses it)
    margin_why : str, one sentence of why that size matters to a user
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


#: the skating threshold sensitivity speeds (m/s) of the ``*_at_<speed>`` columns
SENSITIVITY_SPEEDS = (0.15, 0.3, 0.5)
_SKATE_SHARE = Metric("skate_share", "share of contact joint-frames", "lower", "floor", "skate share",
                      "foot skating: share of contact frames", exploratory=True, skating_claim=True,
                      margin=0.05, margin_why="5 percentage points of contact joint-frames: in a 2-s walk (about four "
                      "stances of 15 frames) some 3 more sliding frames per foot joint, about the smallest slide an "
                      "animator would go in to fix")
_SKATING_RATIO_GMD = Metric("skating_ratio_gmd", "share of frame steps (GMD)", "lower", "floor", "GMD skating ratio",
                            "skating ratio (GMD-style)", margin=0.05,
                            margin_why="5 percentage points of frame steps, as for the skate share")
_SENSITIVITY = (_SKATE_SHARE, _SKATING_RATIO_GMD)
#: the skating metrics measured again at each of :data:`SENSITIVITY_SPEEDS` (the ``<name>_at_<speed>`` columns,
#: :func:`at_speed`: no direction, the unit of the metric at that speed)
SENSITIVITY_METRICS = tuple(m.name for m in _SENSITIVITY)


def at_speed(name: str, speed: float) -> str:
    """The column of the sensitivity metric ``name`` (:data:`SENSITIVITY_METRICS`) at the speed threshold ``speed``
    (m/s): ``<name>_at_<speed>``."""
    return f"{name}_at_{speed:g}"


#: the key columns of ``metrics.csv``, before :data:`METRIC_NAMES` and ``note``
KEY_COLUMNS = ["clip", "group", "protocol", "generator", "seed"]
#: every metric column of ``metrics.csv``, in its order
METRICS = (
    Metric("contact_share", "share of foot joint-frames", "", "floor"),
    _SKATE_SHARE,
    Metric("skate_m_per_contact_frame", "m", "lower", "floor"),
    Metric("transition_skate_share", "share of contact joint-frames near seams", "lower", "seams",
           "skate share near seams", "skating near seams: share", exploratory=True, skating_claim=True, margin=0.05,
           margin_why="5 percentage points of the contact joint-frames near seams, as for the skate share"),
    _SKATING_RATIO_GMD,
    *(Metric(at_speed(m.name, v), f"{m.unit}, {v:g} m/s", "", m.needs) for m in _SENSITIVITY for v in SENSITIVITY_SPEEDS),
    Metric("velocity_jump_p95", "m/s", "lower", "", "per-frame velocity jump p95 (m/s)",
           "per-frame velocity jump: 95th percentile (m/s)", exploratory=True, margin=0.2,
           margin_why="a change of joint velocity of 0.2 m/s within one frame (7 mm of position at 30 fps), about half "
                      "of a capture's own 95th percentile: smaller pops hide in the capture's own noise"),
    Metric("velocity_jump_max", "m/s", "lower", ""),
    Metric("velocity_jump_over_capture", "share of frames", "lower", "reference",
           "frames above the capture's largest jump", "share of frames jumping more than the capture's largest"),
    Metric("accel_jump_p95", "m/s^2", "lower", ""),
    Metric("accel_jump_max", "m/s^2", "lower", ""),
    Metric("accel_jump_over_capture", "share of frames", "lower", "reference"),
    Metric("n_seams", "seams", "", "seams"),
    Metric("seams_per_s", "1/s", "", "seams"),
    Metric("transitions_kept", "transitions before pruning", "", "generator", title="transitions kept (before pruning)"),
    # at the seams a generator reports (secondary: they trust the generator's own seams)
    Metric("velocity_jump", "m/s", "", "seams", "seam velocity jump (m/s)", "velocity jump at reported seams (m/s)"),
    Metric("velocity_jump_ratio", "x capture median", "", "seams"),
    Metric("velocity_jump_pct", "percentile in capture", "", "seams"),
    Metric("accel_jump", "m/s^2", "", "seams"),
    Metric("accel_jump_ratio", "x capture median", "", "seams"),
    Metric("accel_jump_pct", "percentile in capture", "", "seams"),
    Metric("ldlj", "log dimensionless jerk", "higher", "", "LDLJ",
           "smoothness: log dimensionless jerk (higher smoother)"),
    Metric("sparc", "spectral arc length", "higher", ""),
    Metric("l2p", "LAFAN1 L2P (clip database statistics)", "lower", "database", "L2P", "L2P vs held-out continuation",
           exploratory=True, margin=0.25,
           margin_why="a quarter of the database's own per-joint position standard deviation (the unit L2P is "
                      "normalised by): a smaller gap to the capture is not a different continuation"),
    Metric("l2p_m", "m", "lower", "reference", "L2P (m)"),
    Metric("l2q", "LAFAN1 L2Q", "lower", "reference"),
    Metric("npss", "NPSS", "lower", "reference", title="NPSS vs held-out continuation"),
    Metric("coverage", "share of database windows", "higher", "database", "coverage", "coverage of database windows",
           exploratory=True, margin=0.05,
           margin_why="5 % of the database's windows: about one second of a 20-s database reached or missed"),
    Metric("local_diversity_m", "m", "", "database"),
    Metric("seed_diversity_m", "m", "higher", "seeds", title="diversity across seeds (m)"),
    Metric("novelty_median_m", "m", "", "database", "novelty (m)", "novelty: distance to nearest database frame (m)",
           margin=0.01, margin_why="1 cm median distance to the nearest database pose: closer, a pose is a copy with "
                                   "capture noise"),
    Metric("copy_share", "share of frames", "", "database"),
)
METRIC_NAMES = [m.name for m in METRICS]
_BY_NAME = {m.name: m for m in METRICS}

#: the columns of the budget sweep table (medians over clips x seeds)
SWEEP_METRICS = ("transitions_kept", "skate_share", "transition_skate_share", "skating_ratio_gmd", "velocity_jump_p95",
                 "velocity_jump_over_capture", "velocity_jump", "l2p")
#: the panels of the budget sweep's figure (a median column of :data:`SWEEP_METRICS` each)
SWEEP_PANELS = ("transitions_kept", "transition_skate_share", "skate_share", "velocity_jump_p95", "velocity_jump", "l2p")
#: the panels of metrics.png
FIGURE_METRICS = ("skate_share", "transition_skate_share", "velocity_jump_p95", "velocity_jump_over_capture",
                  "skating_ratio_gmd", "ldlj", "l2p", "npss", "coverage", "novelty_median_m", "seed_diversity_m")
#: the columns of the results section of docs/compare.md
RESULT_METRICS = ("skate_share", "skating_ratio_gmd", "transition_skate_share", "velocity_jump", "velocity_jump_p95",
                  "velocity_jump_over_capture", "ldlj", "l2p", "l2p_m", "coverage", "novelty_median_m")
#: the metrics of the exploratory table (with every declared claim's metric)
EXPLORATORY_METRICS = tuple(m.name for m in METRICS if m.exploratory)
#: the skating metrics of the claims: a claim on one of them compares generators whose feet touch the floor
SKATING_CLAIM_METRICS = tuple(m.name for m in METRICS if m.skating_claim)


def metric(name: str) -> Metric:
    """The record of the column ``name`` (``KeyError`` naming the columns when there is none)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no metric {name!r} (one of {METRIC_NAMES})") from None


def metric_or_blank(name: str) -> Metric:
    """The record of the column ``name``, or for a name outside the table (a declared claim may name any column
    with its own ``direction``) a record with no unit and no direction."""
    return _BY_NAME.get(name) or Metric(name, "", "", "")


def names_needing(*needs: str) -> tuple[str, ...]:
    """The metrics whose :attr:`Metric.needs` is one of ``needs``, in the table's order."""
    return tuple(m.name for m in METRICS if m.needs in needs)


def _check() -> None:
    """Every record's direction and needs are known, its name unique; every selection names records (a figure's
    with a title, a table heading's with a label)."""
    if len(_BY_NAME) != len(METRICS):
        raise ValueError("a metric name is in the table twice")
    for m in METRICS:
        if m.better not in ("lower", "higher", "") or m.needs not in NEEDS:
            raise ValueError(f"metric {m.name!r}: better {m.better!r}, needs {m.needs!r}")
        if m.margin is not None and not (m.margin > 0 and m.margin_why):
            raise ValueError(f"metric {m.name!r}: a margin must be positive and say why (margin_why)")
    for what, names, text in (("SWEEP_METRICS", SWEEP_METRICS, None), ("SWEEP_PANELS", SWEEP_PANELS, "title"),
                              ("FIGURE_METRICS", FIGURE_METRICS, "title"), ("RESULT_METRICS", RESULT_METRICS, "label")):
        for n in names:
            if n not in _BY_NAME or (text and not getattr(_BY_NAME[n], text)):
                raise ValueError(f"{what}: {n!r} is not a metric of the table" + (f" with a {text}" if text else ""))
    if not set(SWEEP_PANELS) <= set(SWEEP_METRICS):
        raise ValueError("SWEEP_PANELS: a panel is not a column of the sweep table")


_check()
