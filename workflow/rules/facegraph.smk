# Facial animation with region motion graphs (Serra et al. 2018), issue 5.
# Data: a synthetic CK+-layout database is generated (or facegraph.ckplus_dir
# points at a real CK+ copy) and parsed by the strict CK+ loader, then
# pre-processed once. Table 1: one job per compression configuration
# (threshold search, graph build, re-synthesis of every sequence), aggregated
# by facegraph_table1. The baseline, uniqueness study and figures use the
# graphs of the showcase configuration. Every job gets only the config keys it uses.
from animsynth.facegraph.experiments import config_name
from animsynth.facegraph.settings import check_facegraph_config, configurations

FG = config["facegraph"]
check_facegraph_config(FG)
FG_TABLE_CONFIGS = configurations(FG)
FG_SHOWCASE = config_name(FG["showcase"]["creation"], FG["showcase"]["merge"])
FG_CONFIG_MAP = {name: (c, m) for name, c, m in FG_TABLE_CONFIGS}
FG_CONFIG_MAP.setdefault(FG_SHOWCASE, (float(FG["showcase"]["creation"]), float(FG["showcase"]["merge"])))
FG_SYNTHETIC = FG["ckplus_dir"] is None
FG_DB_DIR = "resources/facegraph/ckplus_synthetic" if FG_SYNTHETIC else FG["ckplus_dir"]
FG_SOURCE = "synthetic CK+-layout database (animsynth.synth.faces)" if FG_SYNTHETIC else f"CK+ at {FG['ckplus_dir']}"
FG_SEED_GRAPH = seed_for("facegraph", FG["seed"], "graph")
FG_SHOWCASE_GRAPH = f"results/facegraph/graphs/{FG_SHOWCASE}.npz"


wildcard_constraints:
    fgcfg=r"c[0-9]+(\.[0-9]+)?_m[0-9]+(\.[0-9]+)?",


if FG_SYNTHETIC:

    rule facegraph_synth_db:
        output:
            directory("resources/facegraph/ckplus_synthetic"),
        params:
            cfg=FG["synthetic"],
            seed=seed_for("facegraph", FG["seed"], "synthetic"),
        log:
            "logs/facegraph/synth_db.log",
        benchmark:
            "benchmarks/rules/facegraph/synth_db.tsv"
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/facegraph_synth_db.py"


rule facegraph_prepare:
    input:
        db=FG_DB_DIR,
    output:
        npz="results/facegraph/preprocessed.npz",
        csv=report(
            "results/facegraph/database.csv",
            caption="../report/facegraph_database.rst",
            category="Facegraph",
            subcategory="Data",
        ),
        md="results/facegraph/database.md",
    params:
        cfg=FG["preprocess"],
        source=FG_SOURCE,
    log:
        "logs/facegraph/prepare.log",
    benchmark:
        "benchmarks/rules/facegraph/prepare.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_prepare.py"


rule facegraph_graph:
    input:
        "results/facegraph/preprocessed.npz",
    output:
        graphs="results/facegraph/graphs/{fgcfg}.npz",
        run="results/facegraph/runs/{fgcfg}.json",
        samples="results/facegraph/runs/{fgcfg}_samples.csv",
    params:
        target=lambda wc: FG_CONFIG_MAP[wc.fgcfg],
        cfg={k: FG[k] for k in ("graph", "synthesis", "evaluation")},
        seed=FG_SEED_GRAPH,
    log:
        "logs/facegraph/graph/{fgcfg}.log",
    benchmark:
        "benchmarks/rules/facegraph/graph/{fgcfg}.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_graph.py"


rule facegraph_table1:
    input:
        runs=[f"results/facegraph/runs/{name}.json" for name, _, _ in FG_TABLE_CONFIGS],
        db="results/facegraph/preprocessed.npz",
    output:
        csv=report(
            "results/facegraph/table1.csv",
            caption="../report/facegraph_table1.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        md="results/facegraph/table1.md",
        thresholds=report(
            "results/facegraph/thresholds.csv",
            caption="../report/facegraph_thresholds.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        thresholds_md="results/facegraph/thresholds.md",
    params:
        order=[name for name, _, _ in FG_TABLE_CONFIGS],
    log:
        "logs/facegraph/table1.log",
    benchmark:
        "benchmarks/rules/facegraph/table1.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_table1.py"


rule facegraph_baseline:
    input:
        db="results/facegraph/preprocessed.npz",
        graphs=FG_SHOWCASE_GRAPH,
    output:
        csv=report(
            "results/facegraph/baseline.csv",
            caption="../report/facegraph_baseline.rst",
            category="Facegraph",
            subcategory="Baseline",
        ),
        md="results/facegraph/baseline.md",
    params:
        cfg={k: FG[k] for k in ("baseline", "synthesis", "evaluation")},
        showcase=FG_SHOWCASE,
        seed=FG_SEED_GRAPH,
    log:
        "logs/facegraph/baseline.log",
    benchmark:
        "benchmarks/rules/facegraph/baseline.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_baseline.py"


rule facegraph_uniqueness:
    input:
        db="results/facegraph/preprocessed.npz",
        graphs=FG_SHOWCASE_GRAPH,
    output:
        csv=report(
            "results/facegraph/uniqueness.csv",
            caption="../report/facegraph_uniqueness.rst",
            category="Facegraph",
            subcategory="Uniqueness",
        ),
        md="results/facegraph/uniqueness.md",
        pairs="results/facegraph/uniqueness_pairs.csv",
    params:
        cfg={k: FG[k] for k in ("uniqueness", "synthesis")},
        seed=seed_for("facegraph", FG["seed"], "uniqueness"),
    log:
        "logs/facegraph/uniqueness.log",
    benchmark:
        "benchmarks/rules/facegraph/uniqueness.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_uniqueness.py"


rule facegraph_figures:
    input:
        db="results/facegraph/preprocessed.npz",
        graphs=FG_SHOWCASE_GRAPH,
    output:
        graph=report(
            "results/facegraph/region_graphs.png",
            caption="../report/facegraph_region_graphs.rst",
            category="Facegraph",
            subcategory="Figures",
        ),
        trajectories=report(
            "results/facegraph/trajectories.png",
            caption="../report/facegraph_trajectories.rst",
            category="Facegraph",
            subcategory="Figures",
        ),
        gif=report(
            "results/facegraph/sequence.gif",
            caption="../report/facegraph_sequence.rst",
            category="Facegraph",
            subcategory="Figures",
        ),
    params:
        cfg={k: FG[k] for k in ("figures", "synthesis", "evaluation")},
        showcase=FG_SHOWCASE,
        seed=seed_for("facegraph", FG["seed"], "figures"),
        graph_seed=FG_SEED_GRAPH,
    log:
        "logs/facegraph/figures.log",
    benchmark:
        "benchmarks/rules/facegraph/figures.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_figures.py"


rule facegraph_verdicts:
    input:
        table1="results/facegraph/table1.csv",
        baseline="results/facegraph/baseline.csv",
        uniqueness="results/facegraph/uniqueness.csv",
    output:
        csv=report(
            "results/facegraph/verdicts.csv",
            caption="../report/facegraph_verdicts.rst",
            category="Facegraph",
            subcategory="Verdicts",
        ),
        md="results/facegraph/verdicts.md",
    params:
        source=FG_SOURCE,
    log:
        "logs/facegraph/verdicts.log",
    benchmark:
        "benchmarks/rules/facegraph/verdicts.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_verdicts.py"


FACEGRAPH_TARGETS = [
    "results/facegraph/database.csv",
    "results/facegraph/table1.csv",
    "results/facegraph/thresholds.csv",
    "results/facegraph/baseline.csv",
    "results/facegraph/uniqueness.csv",
    "results/facegraph/region_graphs.png",
    "results/facegraph/trajectories.png",
    "results/facegraph/sequence.gif",
    "results/facegraph/verdicts.csv",
]
_FG_DATA_NOTE = (
    "Synthetic CK+-layout data generated by the workflow, not CK+." if FG_SYNTHETIC else f"Data: {FG_SOURCE}."
)
FACEGRAPH_SUMMARY = [
    {
        "title": "Serra et al. 2018 Table 1: region motion graphs per compression configuration",
        "csv": "results/facegraph/table1.csv",
        "note": f"{_FG_DATA_NOTE} paper_* columns are empty (the published values were not available to us); "
        "timing_* columns are machine-dependent.",
    },
    {
        "title": "Facegraph: face graph (Zhang et al. 2004) vs region graphs",
        "csv": "results/facegraph/baseline.csv",
        "note": f"{_FG_DATA_NOTE} paper_pathfinding_s is the paper's ~1.9 s face-graph path finding.",
    },
    {
        "title": "Facegraph: distinct animations from one label sequence",
        "csv": "results/facegraph/uniqueness.csv",
        "note": _FG_DATA_NOTE,
    },
]
FACEGRAPH_VERDICTS = ["results/facegraph/verdicts.csv"]
