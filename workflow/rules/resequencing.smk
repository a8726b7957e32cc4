# Re-sequencing motion with Isomap and ST-Isomap.
# Jobs: one analysis per dataset x global-DOF flag (distances, exact min k,
# Isomap / ST-Isomap fits at each configuration's min k, the fixed-k sweep,
# residual variance, 2-D embeddings); one explanation job per dataset (min k
# over sign mode x frame rate x global DOF, quaternion sign flips); one path job
# per dataset for every method x metric x global flag (Dijkstra paths, BVH, GIF,
# per-path and per-transition smoothness); one figures job per dataset (Fig 2
# per method, Fig 3); one aggregation (Table 2 beside the paper, explanations,
# smoothness, verdicts).
# Resources: measured on CMU (05_02 at 800 frames, 2 cores at load ~20): peak RSS 200 MB (analyse,
# explain, figures), 275 MB (path), 170 MB (tables); wall time at most 70 s (analyse, explain), 285 s
# (path; 24 s of CPU), 55 s (figures), 21 s (tables). Memory about 3x and runtime (minutes) about 4x that.
# Wildcards are prefixed rs* because `dataset` and `method` are constrained
# globally by other families. Input functions: common.smk ("resequencing input functions");
# config checks: animsynth.resequencing.settings.check (called from common.smk).
from animsynth.resequencing.tables import paper_comparable

RESEQ = config["resequencing"]
RESEQ_DATASETS = list(RESEQ["datasets"])
# the paper's Table 2 values stand only beside the trials it measured (its CMU clips, or the synthetic stand-ins)
RESEQ_COMPARABLE = paper_comparable(config, {d: RESEQ_TRIALS[d] for d in RESEQ_DATASETS})
RESEQ_METHODS = list(RESEQ["methods"])
RESEQ_METRICS = list(RESEQ["metrics"])
RESEQ_GDOF = ["global" if g else "noglobal" for g in RESEQ["global_dof"]]


wildcard_constraints:
    rsdata="|".join(RESEQ_DATASETS) if RESEQ_DATASETS else "walk|run|dance",
    rsmethod="isomap|stisomap",
    rsmetric="l2|lee",
    rsgdof="global|noglobal",


# The config keys each job depends on (passed as params, so a change reruns exactly those jobs).
RESEQ_ANALYSE_CFG = {
    k: RESEQ[k]
    for k in ("methods", "metrics", "max_frames", "frame_step", "linearisation", "fixed_k_sweep", "max_dim",
              "embedding", "lee", "stisomap")
}
RESEQ_EXPLAIN_CFG = {
    k: RESEQ[k] for k in ("methods", "metrics", "max_frames", "linearisation", "lee", "stisomap", "explanations")
}
RESEQ_PATH_CFG = {
    k: RESEQ[k]
    for k in ("max_frames", "frame_step", "linearisation", "lee", "stisomap", "path", "smoothness", "gif_fps")
}
RESEQ_TABLES_CFG = {
    k: RESEQ[k] for k in ("frame_step", "explanations", "verdict_share", "verdict_alpha", "lee")
}
RESEQ_WORK = R("resequencing/work")
RESEQ_CONFIGS = [
    (d, m, x, g) for d in RESEQ_DATASETS for m in RESEQ_METHODS for x in RESEQ_METRICS for g in RESEQ_GDOF
]


rule resequencing_analyse:
    input:
        reseq_trial_npz,
    output:
        min_k=f"{RESEQ_WORK}/{{rsdata}}_{{rsgdof}}_min_k.csv",
        rv=f"{RESEQ_WORK}/{{rsdata}}_{{rsgdof}}_residual_variance.csv",
        emb=f"{RESEQ_WORK}/{{rsdata}}_{{rsgdof}}_embedding.npz",
        timing=f"{RESEQ_WORK}/{{rsdata}}_{{rsgdof}}_timing.csv",
    params:
        trial=reseq_trial,
        cfg=RESEQ_ANALYSE_CFG,
        budget_gib=config["memory_budget_gib"],
    log:
        L("resequencing/analyse/{rsdata}_{rsgdof}.log"),
    benchmark:
        B("resequencing/analyse/{rsdata}_{rsgdof}.tsv")
    threads: 1
    resources:
        mem_mb=800,
        runtime=20,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/resequencing_analyse.py"


rule resequencing_explain:
    input:
        reseq_trial_npz,
    output:
        grid=f"{RESEQ_WORK}/{{rsdata}}_explain_min_k.csv",
        flips=f"{RESEQ_WORK}/{{rsdata}}_sign_flips.csv",
    params:
        trial=reseq_trial,
        cfg=RESEQ_EXPLAIN_CFG,
        budget_gib=config["memory_budget_gib"],
    log:
        L("resequencing/explain/{rsdata}.log"),
    benchmark:
        B("resequencing/explain/{rsdata}.tsv")
    threads: 1
    resources:
        mem_mb=800,
        runtime=20,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/resequencing_explain.py"


RESEQ_PATH_CONFIGS = [(m, x, g) for m in RESEQ_METHODS for x in RESEQ_METRICS for g in RESEQ_GDOF]


# One job per dataset runs every method x metric x global flag: each path takes
# about a second, less than a job's own start-up.
rule resequencing_path:
    input:
        npz=reseq_trial_npz,
        min_k=expand(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{g}}_min_k.csv", g=RESEQ_GDOF),
    output:
        csv=reseq_path_outputs(R("resequencing/paths/{{rsdata}}_{rsmethod}_{rsmetric}_{rsgdof}.csv")),
        bvh=reseq_path_outputs(R("resequencing/paths/{{rsdata}}_{rsmethod}_{rsmetric}_{rsgdof}.bvh")),
        gif=reseq_path_outputs(R("resequencing/paths/{{rsdata}}_{rsmethod}_{rsmetric}_{rsgdof}.gif")),
        smooth=reseq_path_outputs(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{rsmethod}}_{{rsmetric}}_{{rsgdof}}_smoothness.csv"),
        transitions=reseq_path_outputs(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{rsmethod}}_{{rsmetric}}_{{rsgdof}}_transitions.csv"),
    params:
        cfg=RESEQ_PATH_CFG,
        configs=RESEQ_PATH_CONFIGS,
        gdof=RESEQ_GDOF,
        seed=reseq_pairs_seed,
        budget_gib=config["memory_budget_gib"],
    log:
        L("resequencing/path/{rsdata}.log"),
    benchmark:
        B("resequencing/path/{rsdata}.tsv")
    threads: 1
    resources:
        mem_mb=1000,
        runtime=30,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/resequencing_path.py"


# Figures 2 and 3 of one dataset in one job (each takes less than a job's start-up).
rule resequencing_figures:
    input:
        emb=expand(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{g}}_embedding.npz", g=RESEQ_GDOF),
        min_k=expand(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{g}}_min_k.csv", g=RESEQ_GDOF),
        rv=expand(f"{RESEQ_WORK}/{{{{rsdata}}}}_{{g}}_residual_variance.csv", g=RESEQ_GDOF),
    output:
        fig2=[
            report(
                R(f"resequencing/figures/fig2_{{rsdata}}_{m}.png"),
                caption="../report/resequencing_fig2.rst",
                category="Re-sequencing",
                subcategory="Fig 2 embeddings",
            )
            for m in RESEQ_METHODS
        ],
        fig3=report(
            R("resequencing/figures/fig3_residual_variance_{rsdata}.png"),
            caption="../report/resequencing_fig3.rst",
            category="Re-sequencing",
            subcategory="Fig 3 residual variance",
        ),
    params:
        methods=RESEQ_METHODS,
        metrics=RESEQ_METRICS,
    log:
        L("resequencing/figures/{rsdata}.log"),
    benchmark:
        B("resequencing/figures/{rsdata}.tsv")
    threads: 1
    resources:
        mem_mb=600,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/resequencing_figures.py"


rule resequencing_tables:
    input:
        min_k=expand(f"{RESEQ_WORK}/{{d}}_{{g}}_min_k.csv", d=RESEQ_DATASETS, g=RESEQ_GDOF),
        explain=expand(f"{RESEQ_WORK}/{{d}}_explain_min_k.csv", d=RESEQ_DATASETS),
        flips=expand(f"{RESEQ_WORK}/{{d}}_sign_flips.csv", d=RESEQ_DATASETS),
        rv=expand(f"{RESEQ_WORK}/{{d}}_{{g}}_residual_variance.csv", d=RESEQ_DATASETS, g=RESEQ_GDOF),
        timing=expand(f"{RESEQ_WORK}/{{d}}_{{g}}_timing.csv", d=RESEQ_DATASETS, g=RESEQ_GDOF),
        smooth=[f"{RESEQ_WORK}/{d}_{m}_{x}_{g}_smoothness.csv" for d, m, x, g in RESEQ_CONFIGS],
        transitions=[f"{RESEQ_WORK}/{d}_{m}_{x}_{g}_transitions.csv" for d, m, x, g in RESEQ_CONFIGS],
        published_table2=published_input("resequencing", "table2"),
        published_lee_weights=published_input("resequencing", "lee_weights"),
    output:
        table2=report(
            R("resequencing/table2_min_k.csv"),
            caption="../report/resequencing_table2.rst",
            category="Re-sequencing",
            subcategory="Table 2 minimum k",
        ),
        table2_md=R("resequencing/table2_min_k.md"),
        explanations=report(
            R("resequencing/min_k_explanations.csv"),
            caption="../report/resequencing_explanations.rst",
            category="Re-sequencing",
            subcategory="Table 2 minimum k",
        ),
        explanations_md=R("resequencing/min_k_explanations.md"),
        flips=report(
            R("resequencing/sign_flips.csv"),
            caption="../report/resequencing_sign_flips.rst",
            category="Re-sequencing",
            subcategory="Table 2 minimum k",
        ),
        lee_weights=R("resequencing/lee_weights.csv"),
        rv=report(
            R("resequencing/residual_variance.csv"),
            caption="../report/resequencing_residual_variance.rst",
            category="Re-sequencing",
            subcategory="Fig 3 residual variance",
        ),
        smooth=report(
            R("resequencing/smoothness.csv"),
            caption="../report/resequencing_smoothness.rst",
            category="Re-sequencing",
            subcategory="Smoothness",
        ),
        smooth_md=R("resequencing/smoothness.md"),
        smooth_paths=R("resequencing/smoothness_paths.csv"),
        smooth_transitions=R("resequencing/smoothness_transitions.csv"),
        verdicts=report(
            R("resequencing/verdicts.csv"),
            caption="../report/resequencing_verdicts.rst",
            category="Re-sequencing",
            subcategory="Verdicts",
        ),
        verdicts_md=R("resequencing/verdicts.md"),
        timing=R("resequencing/resequencing_timing.csv"),
    params:
        cfg=RESEQ_TABLES_CFG,
        trials={d: RESEQ_TRIALS[d] for d in RESEQ_DATASETS},
        comparable=RESEQ_COMPARABLE,
    log:
        L("resequencing/tables.log"),
    benchmark:
        B("resequencing/tables.tsv")
    threads: 1
    resources:
        mem_mb=600,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/resequencing_tables.py"


RESEQUENCING_TARGETS = (
    [
        R("resequencing/table2_min_k.csv"),
        R("resequencing/min_k_explanations.csv"),
        R("resequencing/sign_flips.csv"),
        R("resequencing/residual_variance.csv"),
        R("resequencing/smoothness.csv"),
        R("resequencing/verdicts.csv"),
    ]
    + [R(f"resequencing/figures/fig2_{d}_{m}.png") for d in RESEQ_DATASETS for m in RESEQ_METHODS]
    + [R(f"resequencing/figures/fig3_residual_variance_{d}.png") for d in RESEQ_DATASETS]
    + [
        R(f"resequencing/paths/{d}_{m}_{x}_{g}.{ext}")
        for d, m, x, g in RESEQ_CONFIGS
        for ext in ("csv", "bvh", "gif")
    ]
)


# Collected by report.smk into results/summary.md.
RESEQUENCING_SUMMARY = [
    {
        "title": "Re-sequencing Table 2: smallest k giving one connected neighbourhood graph",
        "csv": R("resequencing/table2_min_k.csv"),
        "note": "Exact (MST bottleneck over neighbour ranks), cross-checked with connected_components, in both "
        "linearisation sign modes (continuous = our method; matrix_naive = reproduction of a probable artefact); "
        "min_k_paper from published.resequencing.table2 (empty when the file is absent).",
    },
    {
        "title": "Re-sequencing: smoothness of the re-sequenced motions",
        "csv": R("resequencing/smoothness.csv"),
        "note": "Transition counts over all pairs (end before start); per-transition smoothness means over the "
        "re-sequencing paths only; ratios against the original capture.",
    },
]
RESEQUENCING_VERDICTS = [R("resequencing/verdicts.csv")]
# Key figures for the summary and the report's home page, with what to see in them.
RESEQUENCING_FIGURES = [
    {
        "png": R(f"resequencing/figures/fig3_residual_variance_{RESEQ_DATASETS[0]}.png"),
        "caption": f"Residual variance against embedding dimension ({RESEQ_DATASETS[0]}): red (ST-Isomap) "
        "below blue (Isomap) means the spatio-temporal embedding explains the motion's geodesic distances "
        "with fewer dimensions, the paper's Fig. 3 claim; solid = L2, dashed = Lee metric.",
    }
] if RESEQ_DATASETS else []
