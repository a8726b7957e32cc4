"""Workflow steps of the compare family (the scripts in workflow/scripts only call these): one function per step,
reading its inputs and writing its outputs; the work is done by the modules it calls.

* :func:`clips_job`: one subject's held-out clips (:mod:`animsynth.compare.protocol`) ->
  ``compare/clips/<subject>.npz`` and its table;
* :func:`run_job`: one generator over one subject's clips and seeds, fitted once per database, scored
  (:mod:`animsynth.compare.runner`, :mod:`animsynth.compare.scoring`) -> ``compare/runs/<subject>/<generator>.csv``,
  ``<generator>_timing.csv``, the subject's showcase; :func:`run_rows`: every row of one generator job through it;
* :func:`tables_job`: the family's tables and summary page, every subject's files gathered
  (:mod:`animsynth.compare.tables`, :mod:`animsynth.compare.verdicts`), the clips table (:func:`gather_clips`);
* :func:`sweep_job`: the transition budget sweep's table and figure;
* :func:`figures_job`: ``metrics.png``, ``strips.png`` (:mod:`animsynth.compare.plots`) and the showcase's BVH
  files;
* :func:`long_strips_job`: ``long_strips.png``, the long track's preview.
"""

from __future__ import annotations

import logging

log = logging.getLogger("animsynth.compare.jobs")

__all__ = ["clips_job", "run_job", "run_rows", "tables_job", "sweep_job", "figures_job", "long_strips_job", "gather_clips"]


def clips_job(trials: dict, subsets: dict, resequencing: dict, cfg: dict, out: dict, subjects: dict | None = None,
              first_frames: dict | None = None) -> list:
    """One subject's held-out clips into ``out``: ``clips`` (the ``.npz``), ``table`` (its rows of the clips table)
    and ``captures`` (its rows of ``capture_checks.csv``). Returns the clips.

    Every trial (``trials``: {trial id: Motion at its own rate}) is checked first
    (:func:`animsynth.capture_check.check_capture` with ``cfg["capture_check"]``; ``first_frames``: {trial id: the
    record's ``first_frame``}, for the notes), and its flagged frames stay out of held-out windows and databases
    (:func:`animsynth.compare.protocol.prepare_clips`; ``subjects``: {trial id: subject})."""
    from ..capture_check import check_capture, checks_table
    from ..tables import write_table
    from .protocol import clips_table, prepare_clips, save_clips

    checks = [check_capture(m, t, cfg["capture_check"], (first_frames or {}).get(t, 0)) for t, m in trials.items()]
    usable = {c.trial: c.usable for c in checks}
    clips = prepare_clips(trials, subsets, resequencing, cfg, subjects, usable)
    save_clips(out["clips"], clips)
    write_table(clips_table(clips, int(cfg.get("min_clips_per_subject") or 0)), out["table"], md=False)
    write_table(checks_table(checks), out["captures"], md=False)
    return clips


def run_job(clips_path, generator: str, cfg: dict, master_seed: int, roles: dict | None, showcase, out: dict,
            clips: list | None = None, refs=None) -> None:
    """One generator over one subject's clips and seeds (one row of a workflow job): ``out`` names ``metrics``,
    ``timing``, and optionally ``shown`` (with ``showcase``: (clip spec, seed[, required]),
    :func:`animsynth.compare.runner.showcase_clip`) and ``bvh`` (the showcase as BVH, start frames included); with
    the long track on (``cfg["long_track"]``), ``long_metrics``, ``long_timing`` and ``long_shown`` (its files,
    :mod:`animsynth.compare.long_track`, from the same builds). ``clips``: the clips already read from
    ``clips_path``, and ``refs`` their :class:`~animsynth.compare.scoring.References`, when the job's rows share
    them (:func:`run_rows`)."""
    from ..io.bvh import write_bvh
    from ..tables import write_table
    from .protocol import load_clips
    from .runner import run_isolated, save_shown

    clips = load_clips(clips_path) if clips is None else clips
    metrics, timing, shown, long = run_isolated(clips, generator, cfg, master_seed, roles, showcase, out.values(),
                                                refs)
    if "long_metrics" in out:
        if long is None or long["shown"] is None:
            raise ValueError(f"{generator}: the long track ran no context (config key 'compare.long_track')")
        write_table(long["metrics"], out["long_metrics"], md=False)
        write_table(long["timing"], out["long_timing"], md=False)
        save_shown(out["long_shown"], long["shown"])
    if "shown" in out and shown is None:
        raise ValueError(f"config key 'compare.showcase': clip {showcase[0]!r} seed {showcase[1]} was not run")
    write_table(metrics, out["metrics"], md=False)
    write_table(timing, out["timing"], md=False)
    if "shown" in out:  # the budget sweep's rows write metrics and timing only
        save_shown(out["shown"], shown)
    if "bvh" in out:
        write_bvh(out["bvh"], shown)


def run_rows(clips_path, rows, master_seed: int, output) -> None:
    """Every row of one generator job (the job's ``rows`` param, rule by rule built by the workflow's
    ``compare_rows``: ``[name, config, roles, output prefix, showcase]``) through :func:`run_job` on the clips at
    ``clips_path``; ``output(name)`` is the job's output path named ``name`` (the row's prefix, then ``metrics``,
    ``timing``, ``shown`` when the row has a showcase, and the long track's three files when its config runs it).

    The clips are read once and their references (each database motion's forward kinematics, each clip's
    :class:`~animsynth.compare.scoring.Reference`) made once for all the rows: no row's value depends on the
    generator that made them."""
    from .protocol import load_clips
    from .scoring import References

    clips, refs = load_clips(clips_path), References()
    for name, cfg, roles, prefix, show in rows:
        keys = ("metrics", "timing", "shown") if show is not None else ("metrics", "timing")
        if cfg.get("long_track"):  # the long track's files, from the same builds
            keys += ("long_metrics", "long_timing", "long_shown")
        run_job(clips_path, name, dict(cfg), int(master_seed), dict(roles), None if show is None else tuple(show),
                {k: output(f"{prefix}{k}") for k in keys}, clips, refs)


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


def gather_clips(paths, cfg: dict, clip_files=()):
    """The clips table of the run from every subject's rows (``paths``, in subject order), with ``figure``: ``own``,
    or ``generic`` for a subject whose skeleton another subject's trials share (a generic figure, not the subject's
    own bones: :func:`animsynth.skeleton.shared_figures` on the held-out trials' skeletons of ``clip_files``, the
    subjects' ``.npz``; without them every subject is ``own``), and each clip's note completed: where GenMM runs
    (``cfg["generators"]``) and a clip's database is too short for its pyramid floor
    (:func:`animsynth.compare.generators.genmm.pyramid_note`, on the ``database_longest`` column), the note says
    so."""
    import pandas as pd

    from ..skeleton import figure_kinds, shared_figures
    from .generators.genmm import pyramid_note
    from .protocol import load_skeletons

    clips = pd.concat([pd.read_csv(p, dtype={"held_out": str, "subject": str}, keep_default_na=False)
                       for p in paths], ignore_index=True)
    skeletons = {t: sk for f in clip_files for t, sk in load_skeletons(f).items()}
    trial_subject = {t: s for t, s in zip(clips["held_out"].str.split(" ").str[0], clips["subject"])}
    kinds = figure_kinds(shared_figures(skeletons, {t: trial_subject[t] for t in skeletons})) if skeletons else {}
    clips.insert(clips.columns.get_loc("subject") + 1, "figure", [kinds.get(s, "own") for s in clips["subject"]])
    if "genmm" in cfg.get("generators", ()) and "genmm" in cfg:
        gm = cfg["genmm"]
        notes = [pyramid_note(n, gm["patch_size"], gm["min_coarse_patches"], gm["min_levels"])
                 for n in clips["database_longest"]]
        clips["note"] = ["; ".join(x for x in (str(a), b) if x) for a, b in zip(clips["note"], notes)]
    return clips


def tables_job(inp: dict, out: dict, generators, left_out: dict, cfg: dict, source: str, sweep: dict | None = None) -> None:
    """The clips table (:func:`gather_clips` of ``inp["clips"]``, the subjects' rows) into ``out["clips"]`` (+
    ``clips_md``) and the family's tables (:func:`animsynth.compare.tables.family_tables`, from ``inp``: the clips
    table, ``metrics``, ``timing`` lists; optional ``sweep``: the budget sweep's metrics files) into ``out``: ``metrics``,
    ``metrics_timing``, ``summary``, ``winners`` (+ ``winners_md``), ``cost`` (+ ``cost_md``), ``verdicts``
    (+ ``verdicts_md``), ``claims_stats``, ``exploratory`` (+ ``exploratory_md``), ``sanity`` (+ ``sanity_md``),
    ``sensitivity`` (+ ``sensitivity_md``), ``summary_md`` (the family's page); with the long track's files
    (``inp["long_metrics"]``, ``inp["long_timing"]``), ``metrics_long`` (+ ``metrics_long_md``: its medians) and
    ``metrics_long_timing``."""
    import pandas as pd

    from ..atomic import atomic_write_text
    from ..tables import to_markdown, write_table
    from .tables import family_tables

    write_table(gather_clips(inp["clips"], cfg, inp.get("clip_files", ())), out["clips"], md=out["clips_md"])
    if "captures" in inp:  # every subject's capture checks, gathered
        write_table(pd.concat([pd.read_csv(p, keep_default_na=False) for p in inp["captures"]], ignore_index=True),
                    out["captures"], md=False)
    t = family_tables(dict(inp, clips=out["clips"]), generators, left_out, cfg, source, sweep)
    if inp.get("long_metrics"):  # the long track: its rows, its claims after the 2-s ones, its own section
        from .long_tables import with_long_track

        t = with_long_track(t, inp, left_out, cfg, out["clips"])
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
    if "long" in t:  # the long track's rows, medians (the .md) and cost
        write_table(t["long"]["metrics"], out["metrics_long"], md=False)
        atomic_write_text(out["metrics_long_md"], to_markdown(
            t["long"]["medians"], "The long track: median and spread per generator and measure",
            "Over long contexts x seeds (rows: metrics_long.csv; docs/compare/long_track.md)."))
        write_table(t["long"]["timing"], out["metrics_long_timing"], md=False)
    atomic_write_text(out["summary_md"], t["summary_md"])


def long_strips_job(shown_paths, generators, source: str, seconds: float, path) -> None:
    """``compare/long_strips.png``: the showcase subject's first long context, seed 0, one row per generator
    (``shown_paths``: its ``<generator>_long_showcase.npz`` in the order of ``generators``;
    :func:`animsynth.compare.plots.long_strips_figure`)."""
    from .plots import long_strips_figure
    from .runner import load_shown

    data = "synthetic mocap" if source == "synthetic" else f"{source} mocap"
    shown = {g: load_shown(f) for g, f in zip(generators, shown_paths)}
    clip = next((m.name.split(" ", 1)[-1] for m in shown.values() if not m.meta.get("note")), "")
    long_strips_figure(path, shown, title=f"{seconds:g} s from the same start ({data}): {clip}\nleft: root path "
                       "from above (dots every 2 s); right: poses every 2 s (grey: last start frame, red: at a seam)")
    log.info("long_strips.png: %s", ", ".join(shown))


def figures_job(metrics_path, shown_paths, generators, source: str, out: dict) -> None:
    """``out["metrics"]`` (every metric of the figure per generator, :func:`animsynth.compare.plots.metrics_figure`),
    ``out["strips"]`` (one skeleton strip per generator from the showcase start, ``shown_paths`` in the order of
    ``generators``) and ``out["bvh"]`` (optional: one BVH file per generator, the showcase's start and generated
    frames, in the same order)."""
    import pandas as pd

    from ..io.bvh import write_bvh
    from .plots import metrics_figure, strips_figure
    from .runner import load_shown

    data = "synthetic mocap" if source == "synthetic" else f"{source} mocap"
    metrics = pd.read_csv(metrics_path)
    metrics_figure(out["metrics"], metrics, list(generators), f"Generators side by side ({data}): values over "
                   "held-out clips x seeds (box: IQR, whiskers: 5-95 %; grey: the realism bounds)")
    shown = {g: load_shown(f) for g, f in zip(generators, shown_paths)}
    names = [m.name.split(" ", 1)[-1] for m in shown.values()]
    clip = max(names, key=len)  # "<clip> seed <i>" where a generator ran
    strips_figure(out["strips"], shown, title=f"From the same start: clip {clip} ({data}); "
                  "grey: last start frame, red: frames at a seam")
    for path, m in zip(out.get("bvh") or [], shown.values()):
        write_bvh(path, m)
    log.info("metrics.png: %d rows; strips.png: %s", len(metrics), ", ".join(shown))
