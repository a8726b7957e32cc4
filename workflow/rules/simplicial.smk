# Simplicial-complex motion generation (Gauch & Peters), issue 3.
# Main table: one job per dataset x method x fold (fold = held-out trial id),
# aggregated into folds.csv / table2.csv / paired.csv. The derivative-variant
# grid and the beyond-the-paper grid run one job per dataset. Figures 1-6 and
# the Fig 7 walk are one job each. Every job gets only the config keys it uses,
# so changing a value reruns exactly the affected jobs.
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
    method="delaunay|knn|kdelaunay",
    fold="|".join(SIMP_FOLD_IDS),
    grid="derivative|beyond",


# The config keys each kind of job depends on (passed as params, so a changed
# value reruns exactly the jobs that use it).
SIMP_MAIN_CFG = {k: SIMP[k] for k in SIMP_MAIN_KEYS}
SIMP_GRID_CFG = {
    "derivative": {k: SIMP[k] for k in ("derivatives", "methods", *SIMP_MAIN_KEYS)},
    "beyond": {k: SIMP[k] for k in ("beyond", "k", "steps", "dup_tol", "rank_tol")},
}
SIMP_FOLD_JSONS = [
    f"results/simplicial/folds/{d}_{m}_{t}.json" for d in SIMP_DATASETS for m in SIMP_METHODS for t in SUBSETS[d]
]


rule simplicial_fold:
    input:
        subset_npz,
    output:
        "results/simplicial/folds/{dataset}_{method}_{fold}.json",
    params:
        ids=lambda wc: SUBSETS[wc.dataset],
        cfg=SIMP_MAIN_CFG,
    log:
        "logs/simplicial/fold/{dataset}_{method}_{fold}.log",
    benchmark:
        "benchmarks/rules/simplicial/fold/{dataset}_{method}_{fold}.tsv"
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
        table2=report(
            "results/simplicial/table2.csv",
            caption="../report/simplicial_table2.rst",
            category="Simplicial",
            subcategory="Table II",
        ),
        table2_md="results/simplicial/table2.md",
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
        cfg={k: SIMP[k] for k in ("paper_table2", "bootstrap", "alpha")},
        seed=seed_for("simplicial", SIMP["seed"], "bootstrap"),
    log:
        "logs/simplicial/table.log",
    benchmark:
        "benchmarks/rules/simplicial/table.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_table.py"


rule simplicial_grid:
    input:
        subset_npz,
    output:
        "results/simplicial/{grid}/{dataset}.csv",
    params:
        ids=lambda wc: SUBSETS[wc.dataset],
        cfg=lambda wc: SIMP_GRID_CFG[wc.grid],
    log:
        "logs/simplicial/{grid}/{dataset}.log",
    benchmark:
        "benchmarks/rules/simplicial/{grid}/{dataset}.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_grid.py"


rule simplicial_summary:
    input:
        derivative=expand("results/simplicial/derivative/{dataset}.csv", dataset=SIMP_DATASETS),
        beyond=expand("results/simplicial/beyond/{dataset}.csv", dataset=SIMP_DATASETS),
        folds="results/simplicial/folds.csv",
        paired="results/simplicial/paired.csv",
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
            "derivative": SIMP["derivative"],
            "bootstrap": SIMP["bootstrap"],
            "alpha": SIMP["alpha"],
            "beyond": {k: SIMP["beyond"][k] for k in ("derivative", "latent_dims")},
        },
        seed=seed_for("simplicial", SIMP["seed"], "bootstrap"),
    log:
        "logs/simplicial/summary.log",
    benchmark:
        "benchmarks/rules/simplicial/summary.tsv"
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
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/simplicial_walk.py"


SIMPLICIAL_TARGETS = [
    "results/simplicial/folds.csv",
    "results/simplicial/table2.csv",
    "results/simplicial/table2.md",
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
        "note": "Latent units and normalised by the fold's latent bounding-box diagonal. Paper columns are empty "
        "unless simplicial.paper_table2 is filled (the published values were not available to us).",
    },
    {
        "title": "Simplicial: paired Delaunay vs k-NN test over all folds",
        "csv": "results/simplicial/paired.csv",
        "note": "Wilcoxon signed-rank test and bootstrap CI of the median per-fold difference.",
    },
    {
        "title": "Simplicial: training-vector derivative variants (the printed 1/2)",
        "csv": "results/simplicial/derivative.csv",
        "note": "Which finite difference reproduces the paper's Delaunay-vs-k-NN ordering.",
    },
    {
        "title": "Simplicial: beyond the paper (latent dim, barycentric, k-Delaunay, k sweep, target-directed)",
        "csv": "results/simplicial/beyond.csv",
        "note": "Ranked by median pose-space Error A (joint-angle degrees).",
    },
]
SIMPLICIAL_VERDICTS = ["results/simplicial/verdicts.csv"]
