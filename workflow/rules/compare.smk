# Beyond the papers: every generator of the project and the classic motion graph side by side
# (animsynth.compare, docs/compare.md). The unit of work is the subject: compare_clips builds one subject's held-out
# windows and their databases (leave one out within each Gauch & Peters subset and each compare.subjects set of 2+
# trials, a temporal split in blocks of each re-sequencing clip and one-trial subject set) at the working rate; one
# job per subject and generator (the variant rows of one method in one job: Delaunay and k-NN, ...) fits each row
# once per database and runs every seed of every window from its start, scoring each motion (its benchmark file is
# that job's whole cost); compare_tables, compare_figures and compare_sweep gather them. Rerunning one subject's
# clips reruns that subject's jobs and the gathering only. A generator that cannot run here (fairmotion without its
# package) is left out at parse time with one line, and the tables and docs say why. Every job gets only the config
# keys it uses. Resources: measured on CMU (the paper run) with headroom.
from animsynth.compare.generators.names import FAIRMOTION_ROWS, METHOD_ROWS
from animsynth.compare.long_track import long_settings
from animsynth.compare.settings import (clips_cfg, first_frames, generator_order, groups, run_generators, showcase,
                                        subject_groups, trial_subjects, user_generators)

CMP = config["compare"]
# the leave-one-out groups and temporal splits (the Table I subsets, the re-sequencing clips, then the comparison's
# own per-subject sets of compare.subjects); a group holding a trial whose mirror cannot be read now is left out
CMP_SUBSETS, CMP_RESEQ = groups(config, CMP_MISSING)
# the same groups by subject: {subject: (leave-one-out groups, temporal splits)}, one clips job each
CMP_BY_SUBJECT = subject_groups(config, CMP_MISSING)
CMP_SUBJECTS = list(CMP_BY_SUBJECT)
CMP_RUN, CMP_LEFT_OUT = run_generators(config)
# the user's own generators (compare.user_generators), run after the family's; their job's rerun trigger is the
# content of their file (compare_job_cfg), and they are in every table and figure, not in the verdicts
CMP_USER = user_generators(config)
CMP_ORDER = generator_order(config)
for _gen, _why in CMP_LEFT_OUT.items():
    print(f"animsynth: compare: generator {_gen} left out ({_why})", file=sys.stderr)
# the strips figure's and BVH files' clip spec, seed index and subject
_SPEC, _SEED, CMP_SHOWCASE_SUBJECT = showcase(config, CMP_MISSING)
CMP_TRIALS = list(dict.fromkeys([t for ids in CMP_SUBSETS.values() for t in ids] + list(CMP_RESEQ.values())))
# the transition budget sweep: our motion graph and fairmotion with upstream's walk fixes (the peer's method; the
# as-released row builds the same graph) at every further budget of compare.budget_sweep, budget_sweep_seeds seeds
CMP_GRAPHS = [g for g in ("motion_graph", "fairmotion_fixed") if g in CMP_RUN]
CMP_SWEEP = [f"{float(b):g}" for b in CMP["budget_sweep"] if CMP["transitions_per_s"] is not None
             and float(b) != float(CMP["transitions_per_s"])]
CMP_CLIPS = R("compare/clips/{cmpsubj}.npz")
CMP_OUT = {
    "metrics": R("compare/runs/{cmpsubj}/{cmpgen}.csv"),
    "timing": R("compare/runs/{cmpsubj}/{cmpgen}_timing.csv"),
    "shown": R("compare/runs/{cmpsubj}/{cmpgen}_showcase.npz"),
}
CMP_SWEEP_OUT = R("compare/sweep/{cmpsubj}/{cmpgen}_{budget}.csv")
# the long track (compare.long_track, docs/compare/long_track.md): each default-budget row's job continues its
# subject's long contexts from the same builds and writes these beside its 2-s files
CMP_LONG_ON = long_settings(CMP.get("long_track"), "") is not None
CMP_LONG_OUT = {
    "long_metrics": R("compare/runs/{cmpsubj}/{cmpgen}_long.csv"),
    "long_timing": R("compare/runs/{cmpsubj}/{cmpgen}_long_timing.csv"),
    "long_shown": R("compare/runs/{cmpsubj}/{cmpgen}_long_showcase.npz"),
} if CMP_LONG_ON else {}
# fairmotion's rows and its budget sweep run in one job per subject (compare_run_fairmotion): they build the same
# graphs, so fairmotion's loading of every trial and its graph construction run once per database; each row and
# budget keeps its own threshold and walks (animsynth.compare.generators.fairmotion_peer)
CMP_FM = [g for g in FAIRMOTION_ROWS if g in CMP_RUN]
CMP_FM_SWEEP = [(g, b) for b in CMP_SWEEP for g in CMP_GRAPHS if g in CMP_FM]
# our other graph generator's further budgets run in its own job per subject (compare_run_graph), beside its row
CMP_OWN_SWEEP = [(g, b) for b in CMP_SWEEP for g in CMP_GRAPHS if g not in CMP_FM]
CMP_SWEEP_GRAPH = list(dict.fromkeys(g for g, _b in CMP_OWN_SWEEP))
# the rows of one method (names.METHOD_ROWS: Delaunay and k-NN, Isomap and ST-Isomap, motion matching's three feature
# sets, the two bounds) run in one job per subject (compare_run_<method>): one process start per method, not per
# row; each row still builds, is timed and scored on its own, and a changed row's config reruns its method's job
CMP_METHOD_JOBS = {j: [g for g in rows if g in CMP_RUN] for j, rows in METHOD_ROWS.items() if set(rows) & set(CMP_RUN)}
CMP_OWN_JOB = [g for g in CMP_RUN if g not in CMP_FM and g not in CMP_SWEEP_GRAPH
               and not any(g in rows for rows in CMP_METHOD_JOBS.values())]


wildcard_constraints:
    cmpsubj="|".join(CMP_SUBJECTS) or "none",
    cmpgen="|".join(CMP_RUN) or "none",
    budget="[0-9.]+",


rule compare_clips:
    input:
        compare_subject_trials,
    output:
        clips=CMP_CLIPS,
        table=R("compare/clips/{cmpsubj}.csv"),
        captures=R("compare/clips/{cmpsubj}_captures.csv"),
    params:
        subsets=lambda w: CMP_BY_SUBJECT[w.cmpsubj][0],
        resequencing=lambda w: CMP_BY_SUBJECT[w.cmpsubj][1],
        trials=compare_subject_trial_ids,
        subjects=lambda w: {t: trial_subjects(config)[t] for t in compare_subject_trial_ids(w)},
        first_frames=lambda w: {t: first_frames(config)[t] for t in compare_subject_trial_ids(w)},
        cfg=clips_cfg(config),
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("compare/clips/{cmpsubj}.log"),
    benchmark:
        B("compare/clips/{cmpsubj}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_clips.py"


rule compare_run:
    wildcard_constraints:
        cmpgen="|".join(CMP_OWN_JOB) or "none",
    input:
        CMP_CLIPS,
    output:
        metrics=CMP_OUT["metrics"],
        timing=CMP_OUT["timing"],
        shown=CMP_OUT["shown"],
        **CMP_LONG_OUT,
    params:
        rows=lambda w: compare_rows(w, [(w.cmpgen, None, "")]),
        seed=config["seed"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    log:
        L("compare/run/{cmpsubj}/{cmpgen}.log"),
    benchmark:
        B("compare/run/{cmpsubj}/{cmpgen}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_run.py"


if CMP_SWEEP_GRAPH:

    rule compare_run_graph:
        wildcard_constraints:
            cmpgen="|".join(CMP_SWEEP_GRAPH),
        input:
            CMP_CLIPS,
        output:
            metrics=CMP_OUT["metrics"],
            timing=CMP_OUT["timing"],
            shown=CMP_OUT["shown"],
            **CMP_LONG_OUT,
            **{f"sweep{i}_{k}": R(f"compare/sweep/{{cmpsubj}}/{{cmpgen}}_{b}{ext}")
               for i, b in enumerate(CMP_SWEEP) for k, ext in (("metrics", ".csv"), ("timing", "_timing.csv"))},
        params:
            # its row, then each further budget of the sweep (compare_sweep_cfg's config) in the same process
            rows=lambda w: compare_rows(w, [(w.cmpgen, None, "")] + [(w.cmpgen, b, f"sweep{i}_")
                                                                     for i, b in enumerate(CMP_SWEEP)]),
            seed=config["seed"],
        threads: 1
        resources:
            mem_mb=2000,
            runtime=30,
        log:
            L("compare/run/{cmpsubj}/{cmpgen}.log"),
        benchmark:
            B("compare/run/{cmpsubj}/{cmpgen}.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/compare_run.py"


if CMP_FM:

    rule compare_run_fairmotion:
        input:
            CMP_CLIPS,
        output:
            **{f"{g}_{k}": CMP_OUT[k].replace("{cmpgen}", g) for g in CMP_FM for k in ("metrics", "timing", "shown")},
            **{f"{g}_{k}": v.replace("{cmpgen}", g) for g in CMP_FM for k, v in CMP_LONG_OUT.items()},
            **{f"sweep{i}_{k}": R(f"compare/sweep/{{cmpsubj}}/{g}_{b}{ext}") for i, (g, b) in enumerate(CMP_FM_SWEEP)
               for k, ext in (("metrics", ".csv"), ("timing", "_timing.csv"))},
        params:
            # each row's and budget's config as compare_run's (job_cfg): a changed block reruns this job only if
            # one of them reads it
            rows=compare_rows_of([(g, None, f"{g}_") for g in CMP_FM]
                                 + [(g, b, f"sweep{i}_") for i, (g, b) in enumerate(CMP_FM_SWEEP)]),
            seed=config["seed"],
        # the comparison's longest jobs: started early, so they do not run alone at the end
        priority: 10
        threads: 1
        resources:
            mem_mb=2500,
            runtime=60,
        log:
            L("compare/run/{cmpsubj}/fairmotion_rows_and_sweep.log"),
        benchmark:
            B("compare/run/{cmpsubj}/fairmotion_rows_and_sweep.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/compare_run.py"


for _method, _rows in CMP_METHOD_JOBS.items():

    rule:
        name:
            f"compare_run_{_method}"
        input:
            CMP_CLIPS,
        output:
            **{f"{g}_{k}": v.replace("{cmpgen}", g) for g in _rows for k, v in {**CMP_OUT, **CMP_LONG_OUT}.items()},
        params:
            # each row's config as compare_run's (job_cfg): a changed block reruns this job only if a row reads it
            rows=compare_rows_of([(g, None, f"{g}_") for g in _rows]),
            seed=config["seed"],
        threads: 1
        resources:
            mem_mb=2000,
            runtime=30,
        log:
            L(f"compare/run/{{cmpsubj}}/{_method}-rows.log"),
        benchmark:
            B(f"compare/run/{{cmpsubj}}/{_method}-rows.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/compare_run.py"


CMP_METRICS = [CMP_OUT["metrics"].format(cmpsubj=s, cmpgen=g) for s in CMP_SUBJECTS for g in CMP_RUN]
CMP_TIMING = [CMP_OUT["timing"].format(cmpsubj=s, cmpgen=g) for s in CMP_SUBJECTS for g in CMP_RUN]
CMP_LONG_FILES = {k: [v.format(cmpsubj=s, cmpgen=g) for s in CMP_SUBJECTS for g in CMP_RUN]
                  for k, v in CMP_LONG_OUT.items()}
# the budget sweep's files: budget by budget, then graph generator, then subject (compare.tables.sweep_runs)
CMP_SWEEP_FILES = [CMP_SWEEP_OUT.format(cmpsubj=s, cmpgen=g, budget=b) for b in CMP_SWEEP for g in CMP_GRAPHS
                   for s in CMP_SUBJECTS]


rule compare_tables:
    input:
        clips=expand(R("compare/clips/{cmpsubj}.csv"), cmpsubj=CMP_SUBJECTS),
        # the subjects' clips files: their held-out trials' skeletons, for the figure check (own or generic)
        clip_files=expand(CMP_CLIPS, cmpsubj=CMP_SUBJECTS),
        captures=expand(R("compare/clips/{cmpsubj}_captures.csv"), cmpsubj=CMP_SUBJECTS),
        metrics=CMP_METRICS,
        timing=CMP_TIMING,
        # the budget sweep's runs: quoted as evidence in the claims against the peer
        sweep=CMP_SWEEP_FILES,
        # the long track's rows and costs (none when compare.long_track is off)
        long_metrics=CMP_LONG_FILES.get("long_metrics", []),
        long_timing=CMP_LONG_FILES.get("long_timing", []),
    output:
        clips=report(
            R("compare/clips.csv"),
            caption="../report/compare_clips.rst",
            category="The generators side by side",
        ),
        clips_md=R("compare/clips.md"),
        captures=R("compare/capture_checks.csv"),
        metrics=report(
            R("compare/metrics.csv"),
            caption="../report/compare_metrics.rst",
            category="The generators side by side",
        ),
        metrics_timing=R("compare/metrics_timing.csv"),
        **({"metrics_long": report(R("compare/metrics_long.csv"), caption="../report/compare_metrics_long.rst",
                                   category="The generators side by side"),
            "metrics_long_md": R("compare/metrics_long.md"),
            "metrics_long_timing": R("compare/metrics_long_timing.csv")} if CMP_LONG_ON else {}),
        summary=report(
            R("compare/summary.csv"),
            caption="../report/compare_summary.rst",
            category="The generators side by side",
        ),
        winners=report(
            R("compare/winners.csv"),
            caption="../report/compare_winners.rst",
            category="The generators side by side",
        ),
        winners_md=R("compare/winners.md"),
        cost=report(
            R("compare/cost_timing.csv"),
            caption="../report/compare_cost.rst",
            category="The generators side by side",
        ),
        cost_md=R("compare/cost_timing.md"),
        verdicts=report(
            R("compare/verdicts.csv"),
            caption="../report/compare_verdicts.rst",
            category="The generators side by side",
        ),
        verdicts_md=R("compare/verdicts.md"),
        claims_stats=report(
            R("compare/claims_stats.csv"),
            caption="../report/compare_claims_stats.rst",
            category="The generators side by side",
        ),
        exploratory=report(
            R("compare/exploratory.csv"),
            caption="../report/compare_exploratory.rst",
            category="The generators side by side",
        ),
        exploratory_md=R("compare/exploratory.md"),
        sanity=report(
            R("compare/sanity_checks.csv"),
            caption="../report/compare_sanity.rst",
            category="The generators side by side",
        ),
        sanity_md=R("compare/sanity_checks.md"),
        sensitivity=report(
            R("compare/skating_sensitivity.csv"),
            caption="../report/compare_sensitivity.rst",
            category="The generators side by side",
        ),
        sensitivity_md=R("compare/skating_sensitivity.md"),
        summary_md=report(
            R("compare/summary.md"),
            caption="../report/compare_summary_md.rst",
            category="The generators side by side",
        ),
    params:
        generators=CMP_RUN,
        left_out=CMP_LEFT_OUT,
        cfg={k: CMP_ORDER if k == "generators" else CMP[k]
             for k in ("generators", "seeds", "fps", "context", "length", "verdicts", "claims", "seed", "genmm",
                       "long_track")},
        source=SOURCE,
        sweep={"default": CMP["transitions_per_s"], "budgets": [float(b) for b in CMP_SWEEP], "generators": CMP_GRAPHS},
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("compare/tables.log"),
    benchmark:
        B("compare/tables.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_tables.py"


rule compare_sweep:
    input:
        default=[CMP_OUT["metrics"].format(cmpsubj=s, cmpgen=g) for s in CMP_SUBJECTS for g in CMP_GRAPHS],
        sweep=CMP_SWEEP_FILES,
    output:
        table=report(
            R("compare/budget_sweep.csv"),
            caption="../report/compare_sweep.rst",
            category="The generators side by side",
        ),
        table_md=R("compare/budget_sweep.md"),
        figure=report(
            R("compare/budget_sweep.png"),
            caption="../report/compare_sweep_png.rst",
            category="The generators side by side",
        ),
    params:
        default=CMP["transitions_per_s"],
        budgets=[float(b) for b in CMP_SWEEP],
        generators=CMP_GRAPHS,
        order=CMP["generators"],
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("compare/sweep.log"),
    benchmark:
        B("compare/sweep.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_sweep.py"


rule compare_figures:
    input:
        metrics=R("compare/metrics.csv"),
        # the showcase subject's (compare.showcase) motion of every generator
        shown=[CMP_OUT["shown"].format(cmpsubj=CMP_SHOWCASE_SUBJECT, cmpgen=g) for g in CMP_RUN],
    output:
        metrics=report(
            R("compare/metrics.png"),
            caption="../report/compare_metrics_png.rst",
            category="The generators side by side",
        ),
        strips=report(
            R("compare/strips.png"),
            caption="../report/compare_strips.rst",
            category="The generators side by side",
        ),
        # the showcase as BVH files, start frames included (animsynth score reads them back)
        bvh=expand(R("compare/bvh/{cmpgen}.bvh"), cmpgen=CMP_RUN),
    params:
        generators=CMP_RUN,
        source=SOURCE,
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("compare/figures.log"),
    benchmark:
        B("compare/figures.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_figures.py"


if CMP_LONG_ON:

    rule compare_long_strips:
        input:
            # the showcase subject's (compare.showcase) first long context, seed 0, of every generator
            shown=[CMP_LONG_OUT["long_shown"].format(cmpsubj=CMP_SHOWCASE_SUBJECT, cmpgen=g) for g in CMP_RUN],
        output:
            strips=report(
                R("compare/long_strips.png"),
                caption="../report/compare_long_strips.rst",
                category="The generators side by side",
            ),
        params:
            generators=CMP_RUN,
            source=SOURCE,
            seconds=CMP["long_track"]["seconds"],
        threads: 1
        resources:
            mem_mb=1000,
            runtime=10,
        log:
            L("compare/long_strips.log"),
        benchmark:
            B("compare/long_strips.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/compare_long_strips.py"


COMPARE_TARGETS = [
    R("compare/clips.csv"),
    R("compare/metrics.csv"),
    R("compare/summary.csv"),
    R("compare/winners.csv"),
    R("compare/cost_timing.csv"),
    R("compare/verdicts.csv"),
    R("compare/sanity_checks.csv"),
    R("compare/claims_stats.csv"),
    R("compare/exploratory.csv"),
    R("compare/skating_sensitivity.csv"),
    R("compare/summary.md"),
    R("compare/metrics.png"),
    R("compare/strips.png"),
] + expand(R("compare/bvh/{cmpgen}.bvh"), cmpgen=CMP_RUN)
if CMP_SWEEP and CMP_GRAPHS:
    COMPARE_TARGETS += [R("compare/budget_sweep.csv"), R("compare/budget_sweep.png")]
if CMP_LONG_ON:
    COMPARE_TARGETS += [R("compare/metrics_long.csv"), R("compare/long_strips.png")]

# Tables for results/summary.md (its section "The generators side by side") and the verdict file.
COMPARE_SUMMARY = [
    {
        "title": "Which generator wins which metric",
        "csv": R("compare/winners.csv"),
        "group": "The generators side by side",
        "note": f"On {FAMILY_STATUS['compare'][0]}. Best and second-best generator by median over held-out clips x seeds (replay and concat, the "
        "realism bounds, aside), whether their IQRs are apart, and the share of clip x seed pairs the best wins; "
        "every metric's median and spread per generator: compare/summary.csv, figure compare/metrics.png.",
    },
    {
        "title": "Held-out clips",
        "csv": R("compare/clips.csv"),
        "group": "The generators side by side",
        "note": "Held-out windows of every subject: leave one out within each Gauch & Peters subset and subject set "
        "of 2 or more trials; a temporal split in blocks of each re-sequencing clip and one-trial subject set; "
        "windows of context + length frames, at most compare.max_clips_per_subject per subject.",
    },
]
COMPARE_VERDICTS = [R("compare/verdicts.csv"), R("compare/sanity_checks.csv")]
# Key figures for the summary and the report's home page, with what to see in them.
COMPARE_FIGURES = [
    {
        "png": R("compare/metrics.png"),
        "caption": "Every generator's values over held-out clips x seeds, one panel per metric (box: "
        "interquartile range; grey: the realism bounds replay and concat): a generator whose box lies apart "
        "from another's wins that metric beyond the spread.",
    },
    {
        "png": R("compare/strips.png"),
        "caption": "One skeleton strip per generator from the same start (seams in red): where each generator "
        "breaks the motion, and whether its poses stay plausible.",
    },
]
if CMP_LONG_ON:
    COMPARE_FIGURES.append({
        "png": R("compare/long_strips.png"),
        "caption": f"The long track: {CMP['long_track']['seconds']:g} s of every generator from the same start, its "
        "root path from above beside its poses every 2 s: loops and freezes the long track's measures count.",
    })
