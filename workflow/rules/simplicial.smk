# Simplicial-complex motion generation (Gauch & Peters).
# Main table: one job per dataset x fold (fold = held-out trial id); each job
# follows every method from the same ensemble of starts together (one
# vectorised field step for all paths) and is aggregated into folds.csv /
# table2*.csv / paired.csv. The derivative-variant grid and the
# beyond-the-paper grid run one job per dataset. Figures 1-6 and the Fig 7
# walk are one job each. Every job gets only the config keys it uses, so
# changing a value reruns exactly the affected jobs.
from animsynth.config import ConfigError

SIMP = config["simplicial"]
SIMP_DATASETS = list(SUBSETS)
SIMP_METHODS = list(SIMP["methods"])
SIMP_FOLD_IDS = sorted({t for ids in SUBSETS.values() for t in ids})
SIMP_MAIN_KEYS = ("k", "latent_dim", "derivative", "weights", "steps", "dup_tol", "rank_tol")

if SIMP["figures"]["dataset"] not in SUBSETS:
    raise ConfigError(
        f"config key 'simplicial.figures.dataset': {SIMP['figures']['dataset']!r} is not a subset ({SIMP_DATASETS})"
    )


wildcard_constraints:
    fold="|".join(SIMP_FOLD_IDS),
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
SIMP_FOLD_JSONS = [f"results/simplicial/folds/{d}_{t}.json" for d in SIMP_DATASETS for t in SUBSETS[d]]


rule simplicial_fold:
    input:
        subset_npz,
    output:
        "results/simplicial/folds/{dataset}_{fold}.json",
    params:
        ids=lambda wc: SUBSETS[wc.dataset],
        cfg=SIMP_ENSEMBLE_CFG,
        seed=SIMP_ENSEMBLE_SEED,
    log:
        "logs/simplicial/fold/{dataset}_{fold}.log",
    benchmark:
        "benchmarks/rules/simplicial/fold/{dataset}_{fold}.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_fold.py"


rule simplicial_table:
    input:
        SIMP_FOLD_JSONS,
    output:
        folds=report(
            "results/simplicial/folds.csv",
            caption="../report/simplicial_folds.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        members="results/simplicial/members.csv",
        table2=report(
            "results/simplicial/table2.csv",
            caption="../report/simplicial_table2.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        table2_md="results/simplicial/table2.md",
        table2_units="results/simplicial/table2_units.csv",
        table2_ensemble=report(
            "results/simplicial/table2_ensemble.csv",
            caption="../report/simplicial_table2_ensemble.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        table2_ensemble_md="results/simplicial/table2_ensemble.md",
        fold_ensemble=report(
            "results/simplicial/fold_ensemble.csv",
            caption="../report/simplicial_fold_ensemble.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        paired=report(
            "results/simplicial/paired.csv",
            caption="../report/simplicial_paired.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        paired_md="results/simplicial/paired.md",
    params:
        datasets=SIMP_DATASETS,
        methods=SIMP_METHODS,
        cfg={k: SIMP[k] for k in ("paper_table2", "bootstrap", "alpha", "ensemble")},
        seed=seed_for("simplicial", SIMP["seed"], "bootstrap"),
    log:
        "logs/simplicial/table.log",
    benchmark:
        "benchmarks/rules/simplicial/table.tsv"
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
        folds="results/simplicial/{grid}/{dataset}.csv",
        members="results/simplicial/{grid}/{dataset}_members.csv",
    params:
        ids=lambda wc: SUBSETS[wc.dataset],
        cfg=lambda wc: SIMP_GRID_CFG[wc.grid],
        seed=SIMP_ENSEMBLE_SEED,
    log:
        "logs/simplicial/{grid}/{dataset}.log",
    benchmark:
        "benchmarks/rules/simplicial/{grid}/{dataset}.tsv"
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
        derivative=expand("results/simplicial/derivative/{dataset}.csv", dataset=SIMP_DATASETS),
        derivative_members=expand("results/simplicial/derivative/{dataset}_members.csv", dataset=SIMP_DATASETS),
        beyond=expand("results/simplicial/beyond/{dataset}.csv", dataset=SIMP_DATASETS),
        beyond_members=expand("results/simplicial/beyond/{dataset}_members.csv", dataset=SIMP_DATASETS),
        folds="results/simplicial/folds.csv",
        members="results/simplicial/members.csv",
        paired="results/simplicial/paired.csv",
        table2="results/simplicial/table2.csv",
        table2_ensemble="results/simplicial/table2_ensemble.csv",
    output:
        derivative=report(
            "results/simplicial/derivative.csv",
            caption="../report/simplicial_derivative.rst",
            category="Simplicial",
            subcategory="Derivative variants",
        ),
        derivative_md="results/simplicial/derivative.md",
        derivative_png=report(
            "results/simplicial/figures/derivative.png",
            caption="../report/simplicial_derivative.rst",
            category="Simplicial",
            subcategory="Derivative variants",
        ),
        beyond=report(
            "results/simplicial/beyond.csv",
            caption="../report/simplicial_beyond.rst",
            category="Simplicial",
            subcategory="Beyond the paper",
        ),
        beyond_md="results/simplicial/beyond.md",
        beyond_folds="results/simplicial/beyond_folds.csv",
        beyond_png=report(
            "results/simplicial/figures/beyond.png",
            caption="../report/simplicial_beyond.rst",
            category="Simplicial",
            subcategory="Beyond the paper",
        ),
        verdicts=report(
            "results/simplicial/verdicts.csv",
            caption="../report/simplicial_verdicts.rst",
            category="Simplicial",
            subcategory="Verdicts",
        ),
        verdicts_md="results/simplicial/verdicts.md",
    params:
        datasets=SIMP_DATASETS,
        cfg={
            "methods": SIMP["methods"],
            "paper_claim": SIMP["paper_claim"],
            "paper_table2": SIMP["paper_table2"],
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
        "logs/simplicial/summary.log",
    benchmark:
        "benchmarks/rules/simplicial/summary.tsv"
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
        lambda wc: [trial_npz(t) for t in SUBSETS[SIMP["figures"]["dataset"]]],
    output:
        **{
            f"fig{n}": report(
                f"results/simplicial/figures/fig{n}_{what}.png",
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
        "logs/simplicial/figures.log",
    benchmark:
        "benchmarks/rules/simplicial/figures.tsv"
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
        lambda wc: [trial_npz(t) for t in SUBSETS[SIMP["figures"]["dataset"]]],
    output:
        png=report(
            "results/simplicial/figures/fig7_walk.png",
            caption="../report/simplicial_fig7.rst",
            category="Simplicial",
            subcategory="Figures 1-7",
        ),
        gif=report(
            "results/simplicial/figures/fig7_walk.gif",
            caption="../report/simplicial_fig7.rst",
            category="Simplicial",
            subcategory="Figures 1-7",
        ),
        bvh="results/simplicial/figures/fig7_walk.bvh",
    params:
        dataset=SIMP["figures"]["dataset"],
        ids=SUBSETS[SIMP["figures"]["dataset"]],
        cfg=dict(SIMP_MAIN_CFG, figures=SIMP["figures"]),
    log:
        "logs/simplicial/walk.log",
    benchmark:
        "benchmarks/rules/simplicial/walk.tsv"
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_walk.py"


SIMPLICIAL_TARGETS = [
    "results/simplicial/folds.csv",
    "results/simplicial/table2.csv",
    "results/simplicial/table2.md",
    "results/simplicial/table2_units.csv",
    "results/simplicial/table2_ensemble.csv",
    "results/simplicial/fold_ensemble.csv",
    "results/simplicial/paired.csv",
    "results/simplicial/derivative.csv",
    "results/simplicial/beyond.csv",
    "results/simplicial/verdicts.csv",
    "results/simplicial/figures/fig1_graph_knn.png",
    "results/simplicial/figures/fig2_graph_delaunay.png",
    "results/simplicial/figures/fig3_field_knn.png",
    "results/simplicial/figures/fig4_field_delaunay.png",
    "results/simplicial/figures/fig5_paths_knn.png",
    "results/simplicial/figures/fig6_paths_delaunay.png",
    "results/simplicial/figures/fig7_walk.png",
    "results/simplicial/figures/fig7_walk.gif",
    "results/simplicial/figures/fig7_walk.bvh",
]

# Tables for results/summary.md and verdict files (collected by report.smk).
SIMPLICIAL_SUMMARY = [
    {
        "title": "Gauch & Peters Table II: median Error A / Error F per subset (Delaunay vs k-NN)",
        "csv": "results/simplicial/table2.csv",
        "note": "Ours normalised by the fold's latent bounding-box diagonal, from the held-out start; paper_* = the "
        "published Table II (simplicial.paper_table2; empty when the file is absent).",
    },
    {
        "title": "Simplicial: Table II over the ensemble of jittered starts",
        "csv": "results/simplicial/table2_ensemble.csv",
        "note": "Median and IQR over starts, share of starts in which Delaunay is lower, stable or within start-noise.",
    },
    {
        "title": "Simplicial: paired Delaunay vs k-NN test over all folds",
        "csv": "results/simplicial/paired.csv",
        "note": "Wilcoxon signed-rank test and bootstrap CI of the median per-fold difference.",
    },
    {
        "title": "Simplicial: training-vector derivative variants (the printed 1/2)",
        "csv": "results/simplicial/derivative.csv",
        "note": "Which finite difference reproduces the paper's Delaunay-vs-k-NN ordering, over the ensemble of "
        "starts, and how fast nearby paths separate.",
    },
    {
        "title": "Simplicial: beyond the paper (latent dim, barycentric, k-Delaunay, k sweep, target-directed)",
        "csv": "results/simplicial/beyond.csv",
        "note": "Ranked by median pose-space Error A (joint-angle degrees).",
    },
]
SIMPLICIAL_VERDICTS = ["results/simplicial/verdicts.csv"]
