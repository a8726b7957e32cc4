# Facial animation with region motion graphs (Serra et al. 2018).
# Data: a synthetic CK+-layout database is generated (or facegraph.ckplus_dir
# points at a real CK+ copy) and parsed by the strict CK+ loader, then
# pre-processed once. Table 1: one job per compression configuration (the
# paper's 15 targets with tolerances by default; per-sample threshold search,
# graph build, re-synthesis of every sequence), aggregated by facegraph_table1
# with the published values beside ours. The baseline, uniqueness study and
# figures use the graphs of the showcase configuration. Every job gets only
# the config keys it uses.
import re

from animsynth.facegraph.settings import (check_facegraph_config, configurations, showcase,
                                          sweep_configurations)

FG = config["facegraph"]
check_facegraph_config(FG)
FG_TABLE_CONFIGS = configurations(FG)
FG_SWEEP_CONFIGS = sweep_configurations(FG)
FG_SHOWCASE_CONF = showcase(FG)
FG_SHOWCASE = FG_SHOWCASE_CONF["name"]
FG_CONFIG_MAP = {c["name"]: c for c in FG_TABLE_CONFIGS + FG_SWEEP_CONFIGS}
FG_CONFIG_MAP.setdefault(FG_SHOWCASE, FG_SHOWCASE_CONF)
FG_SYNTHETIC = FG["ckplus_dir"] is None
FG_DB_DIR = "resources/facegraph/ckplus_synthetic" if FG_SYNTHETIC else FG["ckplus_dir"]
FG_SOURCE = "synthetic CK+-layout database (animsynth.synth.faces)" if FG_SYNTHETIC else f"CK+ at {FG['ckplus_dir']}"
FG_SEED_GRAPH = seed_for("facegraph", FG["seed"], "graph")
FG_SHOWCASE_GRAPH = f"results/facegraph/graphs/{FG_SHOWCASE}.npz"
# Resources sized from measured use with headroom (rule benchmarks, 70 sequences / CK+ scale): peak RSS
# synth_db 107 / 115 MB, prepare 147 / 161 MB (13 / 66 s CPU), graph 230 / 475 MB (5-12 / 10-20 s CPU),
# baseline 446 / 685 MB (face graphs capped at baseline.max_nodes poses), table1/verdicts/uniqueness ~160 MB. Runtimes (minutes)
# allow for a machine shared by several jobs (wall up to 20x CPU seen) and scale with the database size.
FG_SCALE = max(1.0, FG["synthetic"]["n_sequences"] / 70.0) if FG_SYNTHETIC else 5.0


wildcard_constraints:
    fgcfg="|".join(re.escape(n) for n in sorted(FG_CONFIG_MAP)),


if FG_SYNTHETIC:

    rule facegraph_synth_db:
        output:
            directory("resources/facegraph/ckplus_synthetic"),
        params:
            cfg=FG["synthetic"],
            seed=seed_for("facegraph", FG["seed"], "synthetic"),
        threads: 1
        resources:
            mem_mb=lambda wc, attempt: 500 * attempt,
            runtime=lambda wc, attempt: int(10 * FG_SCALE * attempt),
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
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 1000 * attempt,
        runtime=lambda wc, attempt: int(20 * FG_SCALE * attempt),
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
        sample_thresholds="results/facegraph/runs/{fgcfg}_thresholds.csv",
    params:
        conf=lambda wc: FG_CONFIG_MAP[wc.fgcfg],
        cfg={k: FG[k] for k in ("graph", "synthesis", "evaluation")},
        seed=FG_SEED_GRAPH,
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 1000 * attempt,
        runtime=lambda wc, attempt: int(20 * FG_SCALE * attempt),
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
        runs=[f"results/facegraph/runs/{c['name']}.json" for c in FG_TABLE_CONFIGS],
        db="results/facegraph/preprocessed.npz",
    output:
        csv=report(
            "results/facegraph/table1.csv",
            caption="../report/facegraph_table1.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        md="results/facegraph/table1.md",
        timing="results/facegraph/table1_timing.csv",
        thresholds=report(
            "results/facegraph/thresholds.csv",
            caption="../report/facegraph_thresholds.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        thresholds_md="results/facegraph/thresholds.md",
    params:
        order=[c["name"] for c in FG_TABLE_CONFIGS],
        paper=FG["paper_table1"],
        title="Table 1: region motion graphs for the paper's 15 compression configurations",
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    log:
        "logs/facegraph/table1.log",
    benchmark:
        "benchmarks/rules/facegraph/table1.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_table1.py"


if FG_SWEEP_CONFIGS:

    rule facegraph_sweep:
        input:
            runs=[f"results/facegraph/runs/{c['name']}.json" for c in FG_SWEEP_CONFIGS],
            db="results/facegraph/preprocessed.npz",
        output:
            csv=report(
                "results/facegraph/sweep.csv",
                caption="../report/facegraph_table1.rst",
                category="Facegraph",
                subcategory="Table 1",
            ),
            md="results/facegraph/sweep.md",
            timing="results/facegraph/sweep_timing.csv",
            thresholds="results/facegraph/sweep_thresholds.csv",
            thresholds_md="results/facegraph/sweep_thresholds.md",
        params:
            order=[c["name"] for c in FG_SWEEP_CONFIGS],
            paper=None,
            title="Optional sweep: creation x merge targets (one tolerance)",
        threads: 1
        resources:
            mem_mb=500,
            runtime=5,
        log:
            "logs/facegraph/sweep.log",
        benchmark:
            "benchmarks/rules/facegraph/sweep.tsv"
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
        timing="results/facegraph/baseline_timing.csv",
    params:
        cfg={k: FG[k] for k in ("baseline", "synthesis", "evaluation")},
        showcase=FG_SHOWCASE,
        seed=FG_SEED_GRAPH,
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 3000 * attempt,
        runtime=lambda wc, attempt: int(30 * FG_SCALE * attempt),
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
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 800 * attempt,
        runtime=lambda wc, attempt: int(15 * FG_SCALE * attempt),
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
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 1000 * attempt,
        runtime=lambda wc, attempt: int(15 * FG_SCALE * attempt),
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
        samples=[f"results/facegraph/runs/{c['name']}_samples.csv" for c in FG_TABLE_CONFIGS],
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
        order=[c["name"] for c in FG_TABLE_CONFIGS],
    threads: 1
    resources:
        mem_mb=lambda wc, attempt: 500 * attempt,
        runtime=lambda wc, attempt: int(5 * FG_SCALE * attempt),
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
] + (["results/facegraph/sweep.csv"] if FG_SWEEP_CONFIGS else [])
_FG_DATA_NOTE = (
    "Synthetic CK+-layout data generated by the workflow, not CK+." if FG_SYNTHETIC else f"Data: {FG_SOURCE}."
)
FACEGRAPH_SUMMARY = [
    {
        "title": "Serra et al. 2018 Table 1: region motion graphs for the paper's 15 configurations",
        "csv": "results/facegraph/table1.csv",
        "note": f"{_FG_DATA_NOTE} paper_* columns: the published values (facegraph.paper_table1), empty if that "
        "file is missing. Creation/synthesis times (CPU and wall) are in table1_timing.csv.",
    },
    {
        "title": "Facegraph: face graph (Zhang et al. 2004) vs region graphs",
        "csv": "results/facegraph/baseline.csv",
        "note": f"{_FG_DATA_NOTE} Path-finding times (and the paper's ~1.9 s) are in baseline_timing.csv.",
    },
    {
        "title": "Facegraph: distinct animations from one label sequence",
        "csv": "results/facegraph/uniqueness.csv",
        "note": _FG_DATA_NOTE,
    },
]
FACEGRAPH_VERDICTS = ["results/facegraph/verdicts.csv"]
