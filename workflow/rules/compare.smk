# Beyond the papers: every generator of the project and the classic motion graph side by side
# (animsynth.compare, docs/compare.md). compare_clips builds every held-out clip's database and start
# (leave one out within each Gauch & Peters subset and each compare.subjects set of 2+ trials, a temporal split of each
# re-sequencing clip and one-trial subject set) at the
# working rate; one job per generator fits it on every clip's database and runs every seed from the clip's
# start, scoring each motion (its benchmark file is the generator's whole cost); compare_tables and
# compare_figures gather them. A generator that cannot run here (fairmotion without its package) is left
# out at parse time with one line, and the tables and docs say why. Every job gets only the config keys it
# uses. Resources: measured on CMU (the paper run) with headroom.
from animsynth.compare.generators.names import FAIRMOTION_ROWS
from animsynth.compare.settings import (clips_cfg, generator_order, groups, job_cfg, run_generators, showcase,
                                        user_generators)

CMP = config["compare"]
# the leave-one-out groups and temporal splits (the Table I subsets, the re-sequencing clips, then the comparison's
# own per-subject sets of compare.subjects); a group holding a trial whose mirror cannot be read now is left out
CMP_SUBSETS, CMP_RESEQ = groups(config, CMP_MISSING)
CMP_RUN, CMP_LEFT_OUT = run_generators(config)
# the user's own generators (compare.user_generators), run after the family's; their job's rerun trigger is the
# content of their file (compare_job_cfg), and they are in every table and figure, not in the verdicts
CMP_USER = user_generators(config)
CMP_ORDER = generator_order(config)
for _gen, _why in CMP_LEFT_OUT.items():
    print(f"animsynth: compare: generator {_gen} left out ({_why})", file=sys.stderr)
CMP_SHOWCASE = list(showcase(config))
CMP_TRIALS = list(dict.fromkeys([t for ids in CMP_SUBSETS.values() for t in ids] + list(CMP_RESEQ.values())))
# the transition budget sweep: our motion graph and fairmotion with upstream's walk fixes (the peer's method; the
# as-released row builds the same graph) at every further budget of compare.budget_sweep, budget_sweep_seeds seeds
CMP_GRAPHS = [g for g in ("motion_graph", "fairmotion_fixed") if g in CMP_RUN]
CMP_SWEEP = [f"{float(b):g}" for b in CMP["budget_sweep"] if CMP["transitions_per_s"] is not None
             and float(b) != float(CMP["transitions_per_s"])]
CMP_CLIPS = R("compare/clips.npz")
CMP_OUT = {
    "metrics": R("compare/runs/{cmpgen}.csv"),
    "timing": R("compare/runs/{cmpgen}_timing.csv"),
    "shown": R("compare/runs/{cmpgen}_showcase.npz"),
}
# fairmotion's rows and its budget sweep run in one job (compare_run_fairmotion): they build the same graphs, so
# fairmotion's loading of every trial and its graph construction run once; each row and budget keeps its own
# threshold and walks (animsynth.compare.generators.fairmotion_peer)
CMP_FM = [g for g in FAIRMOTION_ROWS if g in CMP_RUN]
CMP_FM_SWEEP = [(g, b) for b in CMP_SWEEP for g in CMP_GRAPHS if g in CMP_FM]
CMP_OWN_JOB = [g for g in CMP_RUN if g not in CMP_FM]
# the sweep's jobs of the other graph generators (compare_sweep_run): (generator, budget)
CMP_OWN_SWEEP = [(g, b) for b in CMP_SWEEP for g in CMP_GRAPHS if g not in CMP_FM]


wildcard_constraints:
    cmpgen="|".join(CMP_RUN),
    cmpgraph="|".join(CMP_GRAPHS) or "none",
    budget="[0-9.]+",



rule compare_clips:
    input:
        compare_trial_npz,
    output:
        clips=CMP_CLIPS,
        table=report(
            R("compare/clips.csv"),
            caption="../report/compare_clips.rst",
            category="The generators side by side",
        ),
        table_md=R("compare/clips.md"),
    params:
        trials=CMP_TRIALS,
        subsets=CMP_SUBSETS,
        resequencing=CMP_RESEQ,
        cfg=clips_cfg(config),
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("compare/clips.log"),
    benchmark:
        B("compare/clips.tsv")
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
        bvh=R("compare/bvh/{cmpgen}.bvh"),
    params:
        cfg=compare_job_cfg,
        seed=config["seed"],
        roles={},  # each trial's roles (top-level joint_roles merged with its own) are stored on its skeleton
        showcase=CMP_SHOWCASE,
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    log:
        L("compare/run/{cmpgen}.log"),
    benchmark:
        B("compare/run/{cmpgen}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_run.py"


rule compare_tables:
    input:
        clips=R("compare/clips.csv"),
        metrics=expand(CMP_OUT["metrics"], cmpgen=CMP_RUN),
        timing=expand(CMP_OUT["timing"], cmpgen=CMP_RUN),
        # the budget sweep's runs: quoted as evidence in the claims against the peer
        sweep=[R(f"compare/sweep/{g}_{b}.csv") for b in CMP_SWEEP for g in CMP_GRAPHS],
    output:
        metrics=report(
            R("compare/metrics.csv"),
            caption="../report/compare_metrics.rst",
            category="The generators side by side",
        ),
        metrics_timing=R("compare/metrics_timing.csv"),
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
             for k in ("generators", "seeds", "fps", "context", "length", "verdicts", "claims", "seed")},
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


if CMP_FM:

    rule compare_run_fairmotion:
        input:
            CMP_CLIPS,
        output:
            **{f"{k}_{g}": (CMP_OUT[k].format(cmpgen=g) if k in CMP_OUT else R(f"compare/bvh/{g}.bvh"))
               for g in CMP_FM for k in ("metrics", "timing", "shown", "bvh")},
            **{f"sweep{i}{k}": R(f"compare/sweep/{g}_{b}{k}.csv") for i, (g, b) in enumerate(CMP_FM_SWEEP)
               for k in ("", "_timing")},
        params:
            # each row's and budget's config as compare_run's and compare_sweep_run's (compare_job_cfg,
            # compare_sweep_cfg): a changed block reruns this job only if one of them reads it
            rows=[(g, job_cfg(config, g)) for g in CMP_FM],
            sweep=[(g, b, job_cfg(config, g, budget=b)) for g, b in CMP_FM_SWEEP],
            seed=config["seed"],
            roles={},  # as compare_run's
            sweep_roles=config["joint_roles"],  # as compare_sweep_run's
            showcase=CMP_SHOWCASE,
        # the comparison's longest job (438 s of CPU on the paper run): started early, so it does not run alone at the end
        priority: 10
        threads: 1
        resources:
            mem_mb=2500,
            runtime=60,
        log:
            L("compare/run/fairmotion_rows_and_sweep.log"),
        benchmark:
            B("compare/run/fairmotion_rows_and_sweep.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/compare_run_fairmotion.py"


rule compare_sweep_run:
    wildcard_constraints:
        cmpgraph="|".join(dict.fromkeys(g for g, _b in CMP_OWN_SWEEP)) or "none",
    input:
        CMP_CLIPS,
    output:
        metrics=R("compare/sweep/{cmpgraph}_{budget}.csv"),
        timing=R("compare/sweep/{cmpgraph}_{budget}_timing.csv"),
    params:
        cfg=compare_sweep_cfg,
        seed=config["seed"],
        roles=config["joint_roles"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    log:
        L("compare/sweep/{cmpgraph}_{budget}.log"),
    benchmark:
        B("compare/sweep/{cmpgraph}_{budget}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/compare_sweep_run.py"


rule compare_sweep:
    input:
        default=expand(CMP_OUT["metrics"], cmpgen=CMP_GRAPHS),
        sweep=[R(f"compare/sweep/{g}_{b}.csv") for b in CMP_SWEEP for g in CMP_GRAPHS],
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
        shown=expand(CMP_OUT["shown"], cmpgen=CMP_RUN),
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
    params:
        generators=CMP_RUN,
        showcase=CMP_SHOWCASE,
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
        "note": "Leave one out within each Gauch & Peters subset; temporal split of each re-sequencing clip.",
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
