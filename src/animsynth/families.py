"""The project's families, listed once: the registry the workflow, the summary, the report, the scale harness and
the layers test all read.

A family is a package ``animsynth.<name>`` (``settings.py`` with ``check(config)``, ``jobs.py``, ``verdicts.py``,
``plots.py``) and a rule file ``workflow/rules/<name>.smk``. Adding one is that package, that rule file and one
:class:`Family` line in :data:`FAMILIES`; nothing else names the families (``tests/test_layers.py`` checks that
every family of the registry has both and that no other package or rule file is one). The rule file defines, by
this naming convention (``<NAME>`` is the name in upper case):

``<NAME>_TARGETS``
    every output of the family (``rule all`` asks for them when the family runs);
``<NAME>_SUMMARY``
    its tables for ``summary.md`` (dicts ``title``, ``csv``, optional ``note``, ``group``; the first is its
    key table);
``<NAME>_VERDICTS``
    its ``verdicts.csv`` (and ``sanity_checks.csv``) files;
``<NAME>_FIGURES``
    its key figures for the summary and the report's home page (dicts ``png``, ``caption``);

and, with the family's input functions in ``workflow/rules/common.smk`` (Snakemake's lint keeps functions out of
the rule files):

``<name>_benchmarks()``
    the benchmark files of its jobs in this run (the inputs of the benchmark aggregation), called only when the
    family runs.

The workflow may import this module; this module imports nothing of the package (layer 0 of the import graph).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Family", "ScaleStudy", "FAMILIES", "DATA_KINDS", "names", "get", "report_order", "paper_families",
           "scaled"]

#: what a family's data are, as the workflow probes and labels them: motion capture (CMU, the user's, or the
#: synthetic mocap), mesh sequences (Vlasic et al. or the synthetic skirt character) or facial landmarks (CK+ or
#: the synthetic CK+-layout database)
DATA_KINDS = ("mocap", "mesh", "faces")


@dataclass(frozen=True)
class ScaleStudy:
    """What the scale study (``config/scale.yaml``, :mod:`animsynth.scale`) measures of a family.

    Attributes
    ----------
    steps : str
        ``"module:function"`` of the family's measured steps, ``function(recorder, n, seed=..., **kwargs)``
        (:class:`animsynth.scale.Steps` is the recorder).
    axis : str
        What ``n`` counts (the x axis of the cost curve).
    kwargs : dict
        Keyword of ``steps`` -> config key below ``scale`` (dotted, e.g. ``"simplicial.path_steps"``).
    resolutions : bool
        The points are sizes x ``scale.<family>.resolutions`` (passed as ``resolution``).
    mirror : str or None
        The keyword that receives the CMU mirror (``scale.source: cmu``), if the family reads it.
    """

    steps: str
    axis: str
    kwargs: dict = field(default_factory=dict)
    resolutions: bool = False
    mirror: str | None = None


@dataclass(frozen=True)
class Family:
    """One family of the project.

    Attributes
    ----------
    name : str
        The package (``animsynth.<name>``), the rule file (``workflow/rules/<name>.smk``), the results folder and
        the config block.
    paper : str
        Which paper its verdicts speak for (the claims table's ``paper`` column).
    short : str
        The paper's short name in the claims table.
    letter : str
        The letter of its claim ids (S1, S2, ...).
    section : str
        The heading of its section in ``summary.md`` and on the report's home page.
    data : str
        The kind of data it runs on (:data:`DATA_KINDS`): whether it ran, on what, and whether that is real data
        follow from that source.
    number : int
        Its place in the report (the papers in the project's order, then the comparison): the scoreboard's rows,
        the sections of the summary and of the home page, the provenance table.
    layer : int
        Its layer in the package's import graph: 4 for a paper's family (families never import each other), 5 for
        the comparison, which imports the families it scores.
    scale : ScaleStudy or None
        What the scale study measures of it (None: not measured).
    """

    name: str
    paper: str
    short: str
    letter: str
    section: str
    data: str
    number: int
    layer: int = 4
    scale: ScaleStudy | None = None

    def __post_init__(self):
        if self.data not in DATA_KINDS:
            raise ValueError(f"family {self.name!r}: data must be one of {DATA_KINDS}, got {self.data!r}")


#: every family, in the order the workflow runs and lists them (rule files, tables of the summary, verdicts)
FAMILIES: tuple[Family, ...] = (
    Family("simplicial", "Gauch & Peters (simplicial complex)", "Gauch & Peters", "S",
           "Gauch & Peters (simplicial complex)", "mocap", 1,
           scale=ScaleStudy("animsynth.simplicial.jobs:scale_steps", "training frames",
                            {"steps": "simplicial.path_steps", "trial_frames": "simplicial.trial_frames"})),
    Family("resequencing", "Isomap / ST-Isomap re-sequencing", "ST-Isomap", "R", "Isomap / ST-Isomap re-sequencing",
           "mocap", 2,
           scale=ScaleStudy("animsynth.resequencing.cost:scale_steps", "frames",
                            {k: f"resequencing.{k}" for k in ("metric", "method", "n_candidates", "k", "embedding",
                                                              "exact_max_frames", "n_landmarks", "landmarks")}
                            | {"trial_frames": "trial_frames"}, mirror="cmu_mirror")),
    Family("facegraph", "Serra et al. 2018 (facial motion graphs)", "Serra et al.", "F",
           "Serra et al. 2018 (facial motion graphs)", "faces", 4,
           scale=ScaleStudy("animsynth.facegraph.jobs:scale_steps", "sequences",
                            {"creation": "facegraph.creation", "merge": "facegraph.merge"})),
    Family("meshdetail", "Hybrid mesh animation", "Hybrid mesh", "M", "Hybrid mesh animation", "mesh", 3,
           scale=ScaleStudy("animsynth.meshdetail.jobs:scale_steps", "frames",
                            {"iterations": "meshdetail.iterations"}, resolutions=True)),
    Family("compare", "Beyond the papers: generators side by side", "Side by side", "C",
           "The generators side by side", "mocap", 5, layer=5),
)


def names() -> tuple[str, ...]:
    """Every family's name, in the order of :data:`FAMILIES`."""
    return tuple(f.name for f in FAMILIES)


def get(name: str) -> Family:
    """The family called ``name``; a ValueError naming the known families otherwise."""
    for f in FAMILIES:
        if f.name == name:
            return f
    raise ValueError(f"unknown family {name!r}; one of {list(names())}")


def report_order() -> tuple[Family, ...]:
    """The families in the report's order (:attr:`Family.number`)."""
    return tuple(sorted(FAMILIES, key=lambda f: f.number))


def paper_families() -> tuple[str, ...]:
    """The families that reproduce a paper (layer 4: they never import each other)."""
    return tuple(f.name for f in FAMILIES if f.layer == 4)


def scaled() -> tuple[Family, ...]:
    """The families the scale study measures, in the order of :data:`FAMILIES`."""
    return tuple(f for f in FAMILIES if f.scale is not None)
