"""Workflow steps of the compare family (the scripts in workflow/scripts only call these): one function per step,
reading its inputs and writing its outputs; the work is done by the modules it calls.

* :func:`clips_job`: every held-out clip of the protocol (:mod:`animsynth.compare.protocol`) ->
  ``compare/clips.npz`` and its table;
* :func:`run_job`: one generator over every clip and seed, scored (:mod:`animsynth.compare.runner`,
  :mod:`animsynth.compare.scoring`) -> ``compare/runs/<generator>.csv``, ``<generator>_timing.csv``, the showcase;
* :func:`tables_job`: the family's tables and summary page (:mod:`animsynth.compare.tables`,
  :mod:`animsynth.compare.verdicts`);
* :func:`sweep_job`: the transition budget sweep's table and figure;
* :func:`figures_job`: ``metrics.png`` and ``strips.png`` (:mod:`animsynth.compare.plots`).
"""

from __future__ import annotations

import logging

log = logging.getLogger("animsynth.compare.jobs")

__all__ = ["clips_job", "run_job", "tables_job", "sweep_job", "figures_job"]


def clips_job(trials: dict, subsets: dict, resequencing: dict, cfg: dict, out: dict) -> list:
    """Every held-out clip (:func:`animsynth.compare.protocol.prepare_clips`; ``trials``: {trial id: Motion}) into
    ``out``: ``clips`` (the ``.npz``), ``table`` (+ ``table_md``: the clips table). Returns the clips."""
    from ..tables import write_table
    from .protocol import clips_table, prepare_clips, save_clips

    clips = prepare_clips(trials, subsets, resequencing, cfg)
    save_clips(out["clips"], clips)
    write_table(clips_table(clips), out["table"], md=out["table_md"])
    return clips


def run_job(clips_path, generator: str, cfg: dict, master_seed: int, roles: dict | None, showcase, out: dict) -> None:
    """One generator over every clip and seed (one workflow job): ``out`` names ``metrics``, ``timing``,
    ``shown`` and ``bvh`` (the showcase as BVH, start frames included; both optional, together)."""
    from ..io.bvh import write_bvh
    from ..tables import write_table
    from .protocol import load_clips
    from .runner import run_isolated, save_shown

    clips = load_clips(clips_path)
    metrics, timing, shown = run_isolated(clips, generator, cfg, master_seed, roles, showcase, out.values())
    if "shown" in out and shown is None:
        raise ValueError(f"config key 'compare.showcase': clip {showcase[0]!r} seed {showcase[1]} was not run")
    write_table(metrics, out["metrics"], md=False)
    write_table(timing, out["timing"], md=False)
    if "shown" in out:  # the budget sweep's jobs write metrics and timing only
        save_shown(out["shown"], shown)
        write_bvh(out["bvh"], shown)


def sweep_job(inp: dict, out: dict, default_budget: float, budgets, generators, order) -> None:
    """The sweep table and figure from the default run's graph-generator metrics (``inp["default"]``) and one
    metrics file per budget and generator (``inp["sweep"]``, in the order of ``budgets`` x ``generators``)."""
    from ..tables import write_table
    from .plots import sweep_figure
    from .tables import read_metrics, sweep_runs, sweep_table

    table = sweep_table(sweep_runs(read_metrics(inp["default"]), inp["sweep"], default_budget, budgets, generators),
                        order)
    write_table(table, out["table"], md=out["table_md"])
    sweep_figure(table, out["figure"], float(default_budget))


def tables_job(inp: dict, out: dict, generators, left_out: dict, cfg: dict, source: str, sweep: dict | None = None) -> None:
    """The family's tables (:func:`animsynth.compare.tables.family_tables`, from ``inp``: ``clips``, ``metrics``,
    ``timing`` lists; optional ``sweep``: the budget sweep's metrics files) into ``out``: ``metrics``,
    ``metrics_timing``, ``summary``, ``winners`` (+ ``winners_md``), ``cost`` (+ ``cost_md``), ``verdicts``
    (+ ``verdicts_md``), ``claims_stats``, ``exploratory`` (+ ``exploratory_md``), ``sanity`` (+ ``sanity_md``),
    ``sensitivity`` (+ ``sensitivity_md``), ``summary_md`` (the family's page)."""
    from ..atomic import atomic_write_text
    from ..tables import write_table
    from .tables import family_tables

    t = family_tables(inp, generators, left_out, cfg, source, sweep)
    write_table(t["metrics"], out["metrics"], md=False)
    write_table(t["metrics_timing"], out["metrics_timing"], md=False)
    write_table(t["summary"], out["summary"], md=False)  # compare/summary.md is the family's page below
    write_table(t["winners"], out["winners"], md=out["winners_md"])
    write_table(t["cost"], out["cost"], md=out["cost_md"])
    write_table(t["verdicts"], out["verdicts"], md=out["verdicts_md"])
    write_table(t["claims_stats"], out["claims_stats"], md=False)
    write_table(t["exploratory"], out["exploratory"], md=out["exploratory_md"])
    write_table(t["sanity"], out["sanity"], md=out["sanity_md"])
    write_table(t["sensitivity"], out["sensitivity"], md=out["sensitivity_md"])
    atomic_write_text(out["summary_md"], t["summary_md"])


def figures_job(metrics_path, shown_paths, generators, showcase, source: str, out: dict) -> None:
    """``out["metrics"]`` (every metric of the figure per generator, :func:`animsynth.compare.plots.metrics_figure`)
    and ``out["strips"]`` (one skeleton strip per generator from the showcase start, ``shown_paths`` in the order
    of ``generators``)."""
    import pandas as pd

    from .plots import metrics_figure, strips_figure
    from .runner import load_shown

    data = "synthetic mocap" if source == "synthetic" else f"{source} mocap"
    metrics = pd.read_csv(metrics_path)
    metrics_figure(out["metrics"], metrics, list(generators), f"Generators side by side ({data}): values over "
                   "held-out clips x seeds (box: IQR, whiskers: 5-95 %; grey: the realism bounds)")
    shown = {g: load_shown(f) for g, f in zip(generators, shown_paths)}
    strips_figure(out["strips"], shown, title=f"From the same start: clip {showcase[0]}, seed {showcase[1]} ({data}); "
                  "grey: last start frame, red: frames at a seam")
    log.info("metrics.png: %d rows; strips.png: %s", len(metrics), ", ".join(shown))
