# Simplicial-complex motion generation (Gauch & Peters).
# Table I: the subsets' lengths beside the published ones (results/data/datasets.csv).
# Main table: one job per dataset runs its leave-one-out folds (fold = held-out
# trial id); each fold follows every method from the same ensemble of starts
# together (one vectorised field step for all paths), aggregated into folds.csv /
# table2*.csv / paired.csv. The derivative-variant grid and the
# beyond-the-paper grid run one job per dataset. Figures 1-6 and the Fig 7
# walk are one job each. Every job gets only the config keys it uses, so
# changing a value reruns exactly the affected jobs. The config checks of this
# family (animsynth.simplicial.settings.check) run from common.smk; the input
# functions are in common.smk ("simplicial input functions"). The published
# tables (published.simplicial.table1/table2) are inputs of the jobs that show
# them, declared only when the file exists; params.paper_label names the
# configured path in the tables' notes.

SIMP = config["simplicial"]
SIMP_PUBLISHED = config["published"]["simplicial"]
SIMP_DATASETS = list(SUBSETS)
SIMP_METHODS = list(SIMP["methods"])
SIMP_MAIN_KEYS = ("k", "latent_dim", "derivative", "weights", "steps", "dup_tol", "rank_tol")
# the parsed trials of the subset shown in Figs 1-7
SIMP_FIGURE_TRIALS = [trial_npz(t) for t in SUBSETS[SIMP["figures"]["dataset"]]]


wildcard_constraints:
    grid="derivative|beyond",


# The config keys each kind of job depends on (passed as params, so a changed
# value reruns exactly the jobs that use it).
SIMP_MAIN_CFG = {k: SIMP[k] for k in SIMP_MAIN_KEYS}
SIMP_ENSEMBLE_CFG = dict(SIMP_MAIN_CFG, methods=SIMP["methods"], ensemble=SIMP["ensemble"])
SIMP_GRID_CFG = {
    "derivative": {k: SIMP[k] for k in ("derivatives", "methods", "ensemble", *SIMP_MAIN_KEYS)},
    "beyond": {k: SIMP[k] for k in ("beyond", "k", "steps", "dup_tol", "rank_tol", "ensemble")},
}
SIMP_ENSEMBLE_SEED = seed_for("simplicial", SIMP["seed"], "ensemble")
SIMP_FOLD_JSONS = [R(f"simplicial/folds/{d}.json") for d in SIMP_DATASETS]


# Gauch & Peters Table I for the run's subsets, beside the published lengths.
rule simplicial_table1:
    input:
        trials=[trial_npz(t) for ids in SUBSETS.values() for t in ids],
        paper_table1=published_input("simplicial", "table1"),
    output:
        csv=report(
            R("data/datasets.csv"),
            caption="../report/data_datasets.rst",
            category="1. Data",
            labels={"table": "Gauch & Peters Table I"},
        ),
        md=R("data/datasets.md"),
    params:
        subsets=SUBSETS,
        source=SOURCE,
        paper_label=SIMP_PUBLISHED["table1"],
    log:
        L("simplicial/table1.log"),
    benchmark:
        B("simplicial/table1.tsv")
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_table1.py"


# One job per dataset runs its leave-one-out folds one after the other (a fold
# takes about a second, less than a job's start-up).
rule simplicial_fold:
    input:
        subset_npz,
    output:
        R("simplicial/folds/{dataset}.json"),
    params:
        ids=simplicial_subset_ids,
        cfg=SIMP_ENSEMBLE_CFG,
        seed=SIMP_ENSEMBLE_SEED,
    log:
        L("simplicial/fold/{dataset}.log"),
    benchmark:
        B("simplicial/fold/{dataset}.tsv")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=20,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_fold.py"


rule simplicial_table:
    input:
        folds=SIMP_FOLD_JSONS,
        paper_table2=published_input("simplicial", "table2"),
    output:
        folds=report(
            R("simplicial/folds.csv"),
            caption="../report/simplicial_folds.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        members=R("simplicial/members.csv"),
        table2=report(
            R("simplicial/table2.csv"),
            caption="../report/simplicial_table2.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        table2_md=R("simplicial/table2.md"),
        table2_units=R("simplicial/table2_units.csv"),
        table2_ensemble=report(
            R("simplicial/table2_ensemble.csv"),
            caption="../report/simplicial_table2_ensemble.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        table2_ensemble_md=R("simplicial/table2_ensemble.md"),
        fold_ensemble=report(
            R("simplicial/fold_ensemble.csv"),
            caption="../report/simplicial_fold_ensemble.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        paired=report(
            R("simplicial/paired.csv"),
            caption="../report/simplicial_paired.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        paired_md=R("simplicial/paired.md"),
    params:
        datasets=SIMP_DATASETS,
        methods=SIMP_METHODS,
        cfg={k: SIMP[k] for k in ("bootstrap", "alpha", "ensemble")},
        seed=seed_for("simplicial", SIMP["seed"], "bootstrap"),
        paper_label=SIMP_PUBLISHED["table2"],
    log:
        L("simplicial/table.log"),
    benchmark:
        B("simplicial/table.tsv")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_table.py"


rule simplicial_grid:
    input:
        subset_npz,
    output:
        folds=R("simplicial/{grid}/{dataset}.csv"),
        members=R("simplicial/{grid}/{dataset}_members.csv"),
    params:
        ids=simplicial_subset_ids,
        cfg=simplicial_grid_cfg,
        seed=SIMP_ENSEMBLE_SEED,
    log:
        L("simplicial/{grid}/{dataset}.log"),
    benchmark:
        B("simplicial/{grid}/{dataset}.tsv")
    threads: 1
    resources:
        mem_mb=1500,
        runtime=30,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_grid.py"


rule simplicial_summary:
    input:
        derivative=expand(R("simplicial/derivative/{dataset}.csv"), dataset=SIMP_DATASETS),
        derivative_members=expand(R("simplicial/derivative/{dataset}_members.csv"), dataset=SIMP_DATASETS),
        beyond=expand(R("simplicial/beyond/{dataset}.csv"), dataset=SIMP_DATASETS),
        beyond_members=expand(R("simplicial/beyond/{dataset}_members.csv"), dataset=SIMP_DATASETS),
        folds=R("simplicial/folds.csv"),
        members=R("simplicial/members.csv"),
        paired=R("simplicial/paired.csv"),
        table2=R("simplicial/table2.csv"),
        table2_ensemble=R("simplicial/table2_ensemble.csv"),
        paper_table2=published_input("simplicial", "table2"),
    output:
        derivative=report(
            R("simplicial/derivative.csv"),
            caption="../report/simplicial_derivative.rst",
            category="Simplicial",
            subcategory="Derivative variants",
        ),
        derivative_md=R("simplicial/derivative.md"),
        derivative_png=report(
            R("simplicial/figures/derivative.png"),
            caption="../report/simplicial_derivative.rst",
            category="Simplicial",
            subcategory="Derivative variants",
        ),
        beyond=report(
            R("simplicial/beyond.csv"),
            caption="../report/simplicial_beyond.rst",
            category="Simplicial",
            subcategory="Beyond the paper",
        ),
        beyond_md=R("simplicial/beyond.md"),
        beyond_folds=R("simplicial/beyond_folds.csv"),
        beyond_png=report(
            R("simplicial/figures/beyond.png"),
            caption="../report/simplicial_beyond.rst",
            category="Simplicial",
            subcategory="Beyond the paper",
        ),
        verdicts=report(
            R("simplicial/verdicts.csv"),
            caption="../report/simplicial_verdicts.rst",
            category="Simplicial",
            subcategory="Verdicts",
        ),
        verdicts_md=R("simplicial/verdicts.md"),
    params:
        datasets=SIMP_DATASETS,
        cfg={
            "methods": SIMP["methods"],
            "paper_claim": SIMP["paper_claim"],
            "magnitude_factor": SIMP["magnitude_factor"],
            "derivative": SIMP["derivative"],
            "bootstrap": SIMP["bootstrap"],
            "alpha": SIMP["alpha"],
            "ensemble": SIMP["ensemble"],
            "data_label": {"cmu": "CMU", "synthetic": "synthetic"}.get(SOURCE, SOURCE),
            "beyond": {k: SIMP["beyond"][k] for k in ("derivative", "latent_dims")},
        },
        seed=seed_for("simplicial", SIMP["seed"], "bootstrap"),
    log:
        L("simplicial/summary.log"),
    benchmark:
        B("simplicial/summary.tsv")
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_summary.py"


rule simplicial_figures:
    input:
        SIMP_FIGURE_TRIALS,
    output:
        **{
            f"fig{n}": report(
                R(f"simplicial/figures/fig{n}_{what}.png"),
                caption=f"../report/simplicial_fig{n}.rst",
                category="Simplicial",
                subcategory="Figures 1-7",
            )
            for n, what in (
                (1, "graph_knn"),
                (2, "graph_delaunay"),
                (3, "field_knn"),
                (4, "field_delaunay"),
                (5, "paths_knn"),
                (6, "paths_delaunay"),
            )
        },
    params:
        dataset=SIMP["figures"]["dataset"],
        ids=SUBSETS[SIMP["figures"]["dataset"]],
        cfg=dict(SIMP_MAIN_CFG, figures=SIMP["figures"]),
    log:
        L("simplicial/figures.log"),
    benchmark:
        B("simplicial/figures.tsv")
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_figures.py"


rule simplicial_walk:
    input:
        SIMP_FIGURE_TRIALS,
    output:
        png=report(
            R("simplicial/figures/fig7_walk.png"),
            caption="../report/simplicial_fig7.rst",
            category="Simplicial",
            subcategory="Figures 1-7",
        ),
        gif=report(
            R("simplicial/figures/fig7_walk.gif"),
            caption="../report/simplicial_fig7.rst",
            category="Simplicial",
            subcategory="Figures 1-7",
        ),
        bvh=R("simplicial/figures/fig7_walk.bvh"),
    params:
        dataset=SIMP["figures"]["dataset"],
        ids=SUBSETS[SIMP["figures"]["dataset"]],
        cfg=dict(SIMP_MAIN_CFG, figures=SIMP["figures"]),
    log:
        L("simplicial/walk.log"),
    benchmark:
        B("simplicial/walk.tsv")
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_walk.py"


SIMPLICIAL_TARGETS = [
    R("data/datasets.csv"),
    R("simplicial/folds.csv"),
    R("simplicial/table2.csv"),
    R("simplicial/table2.md"),
    R("simplicial/table2_units.csv"),
    R("simplicial/table2_ensemble.csv"),
    R("simplicial/fold_ensemble.csv"),
    R("simplicial/paired.csv"),
    R("simplicial/derivative.csv"),
    R("simplicial/beyond.csv"),
    R("simplicial/verdicts.csv"),
    R("simplicial/figures/fig1_graph_knn.png"),
    R("simplicial/figures/fig2_graph_delaunay.png"),
    R("simplicial/figures/fig3_field_knn.png"),
    R("simplicial/figures/fig4_field_delaunay.png"),
    R("simplicial/figures/fig5_paths_knn.png"),
    R("simplicial/figures/fig6_paths_delaunay.png"),
    R("simplicial/figures/fig7_walk.png"),
    R("simplicial/figures/fig7_walk.gif"),
    R("simplicial/figures/fig7_walk.bvh"),
]

# Tables for results/summary.md and verdict files (collected by report.smk).
SIMPLICIAL_SUMMARY = [
    {
        "title": "Gauch & Peters Table II: median Error A / Error F per subset (Delaunay vs k-NN)",
        "csv": R("simplicial/table2.csv"),
        "note": "Ours normalised by the fold's latent bounding-box diagonal, from the held-out start; paper_* = the "
        "published Table II (published.simplicial.table2; empty when the file is absent).",
    },
    {
        "title": "Simplicial: Table II over the ensemble of jittered starts",
        "csv": R("simplicial/table2_ensemble.csv"),
        "note": "Median and IQR over starts, share of starts in which Delaunay is lower, stable or within start-noise.",
    },
    {
        "title": "Simplicial: paired Delaunay vs k-NN test over all folds",
        "csv": R("simplicial/paired.csv"),
        "note": "Wilcoxon signed-rank test and bootstrap CI of the median per-fold difference.",
    },
    {
        "title": "Simplicial: training-vector derivative variants (the printed 1/2)",
        "csv": R("simplicial/derivative.csv"),
        "note": "Which finite difference reproduces the paper's Delaunay-vs-k-NN ordering, over the ensemble of "
        "starts, and how fast nearby paths separate.",
    },
    {
        "title": "Simplicial: beyond the paper (latent dim, barycentric, k-Delaunay, k sweep, target-directed)",
        "csv": R("simplicial/beyond.csv"),
        "note": "Ranked by median pose-space Error A (joint-angle degrees).",
    },
]
SIMPLICIAL_VERDICTS = [R("simplicial/verdicts.csv")]
# Key figures for the summary and the report's home page, with what to see in them.
SIMPLICIAL_FIGURES = [
    {
        "png": R("simplicial/figures/fig6_paths_delaunay.png"),
        "caption": "Held-out (black) against generated (red) latent paths of the Delaunay field, one panel per "
        "fold: the closer the red path ends to the black one's final square, the smaller Error F; the panel "
        "titles give the Error A and F that Table II takes the median of.",
    }
]
