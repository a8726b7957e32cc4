# Facial animation with region motion graphs (Serra et al. 2018).
# Data: a synthetic CK+-layout database is generated (or facegraph.ckplus_dir
# points at a real CK+ copy) and parsed by the strict CK+ loader, then
# pre-processed once. Table 1: one job fits every compression configuration (the
# paper's 15 targets with tolerances by default; per-sample threshold search,
# graph build, re-synthesis of every sequence), aggregated by facegraph_table1
# with the published values beside ours (published.facegraph.table1, a declared
# input: a changed file reruns Table 1). The baseline, uniqueness study and
# figures use the graphs of the showcase configuration. Every job gets only
# the config keys it uses.

# Config checks: animsynth.facegraph.settings.check, called with the others from common.smk.
from animsynth.facegraph.settings import configurations, showcase, sweep_configurations

FG = config["facegraph"]
FG_TABLE_CONFIGS = configurations(FG)
FG_SWEEP_CONFIGS = sweep_configurations(FG)
FG_SHOWCASE_CONF = showcase(FG)
FG_SHOWCASE = FG_SHOWCASE_CONF["name"]
FG_CONFIG_MAP = {c["name"]: c for c in FG_TABLE_CONFIGS + FG_SWEEP_CONFIGS}
FG_CONFIG_MAP.setdefault(FG_SHOWCASE, FG_SHOWCASE_CONF)
FG_SYNTHETIC = FG["ckplus_dir"] is None
FG_DB_DIR = R("resources/facegraph/ckplus_synthetic") if FG_SYNTHETIC else FG["ckplus_dir"]
FG_SOURCE = "synthetic CK+-layout database (animsynth.synth.faces)" if FG_SYNTHETIC else f"CK+ at {FG['ckplus_dir']}"
FG_SEED_GRAPH = seed_for("facegraph", FG["seed"], "graph")
FG_SHOWCASE_GRAPH = R(f"facegraph/graphs/{FG_SHOWCASE}.npz")
# Resources sized from measured use with headroom (rule benchmarks, 70 sequences / CK+ scale): peak RSS
# synth_db 107 / 115 MB, prepare 147 / 161 MB (13 / 66 s CPU), graph 230 / 475 MB (5-12 / 10-20 s CPU),
# baseline 446 / 685 MB (face graphs capped at baseline.max_nodes poses), table1/verdicts/uniqueness ~160 MB. Runtimes (minutes)
# allow for a machine shared by several jobs (wall up to 20x CPU seen) and scale with the database size
# (fg_mem_mb / fg_runtime in common.smk's facegraph block: times the attempt; runtimes also times FG_SCALE).
FG_SCALE = max(1.0, FG["synthetic"]["n_sequences"] / 70.0) if FG_SYNTHETIC else 5.0


if FG_SYNTHETIC:

    rule facegraph_synth_db:
        output:
            directory(FG_DB_DIR),
        params:
            cfg=FG["synthetic"],
            seed=seed_for("facegraph", FG["seed"], "synthetic"),
        threads: 1
        resources:
            mem_mb=fg_mem_mb(500),
            runtime=fg_runtime(10),
        log:
            L("facegraph/synth_db.log"),
        benchmark:
            B("facegraph/synth_db.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/facegraph_synth_db.py"


rule facegraph_prepare:
    input:
        db=FG_DB_DIR,
    output:
        npz=R("facegraph/preprocessed.npz"),
        csv=report(
            R("facegraph/database.csv"),
            caption="../report/facegraph_database.rst",
            category="Facegraph",
            subcategory="Data",
        ),
        md=R("facegraph/database.md"),
    params:
        cfg=FG["preprocess"],
        source=FG_SOURCE,
    threads: 1
    resources:
        mem_mb=fg_mem_mb(1000),
        runtime=fg_runtime(20),
    log:
        L("facegraph/prepare.log"),
    benchmark:
        B("facegraph/prepare.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_prepare.py"


# Table 1's configurations and the showcase in one job (each fit takes about a
# second, less than a job's start-up); the optional sweep has a job of its own,
# so switching it on does not rerun Table 1.
FG_MAIN_NAMES = list(dict.fromkeys([c["name"] for c in FG_TABLE_CONFIGS] + [FG_SHOWCASE]))
FG_SWEEP_NAMES = [n for n in dict.fromkeys(c["name"] for c in FG_SWEEP_CONFIGS) if n not in FG_MAIN_NAMES]


rule facegraph_graphs:
    input:
        R("facegraph/preprocessed.npz"),
    output:
        **fg_graph_outputs(FG_MAIN_NAMES),
    params:
        confs=[FG_CONFIG_MAP[n] for n in FG_MAIN_NAMES],
        cfg={k: FG[k] for k in ("graph", "synthesis", "evaluation")},
        seed=FG_SEED_GRAPH,
    threads: 1
    resources:
        mem_mb=fg_mem_mb(1000),
        runtime=fg_runtime(5 * len(FG_MAIN_NAMES)),
    log:
        L("facegraph/graphs.log"),
    benchmark:
        B("facegraph/graphs.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_graphs.py"


if FG_SWEEP_NAMES:

    rule facegraph_sweep_graphs:
        input:
            R("facegraph/preprocessed.npz"),
        output:
            **fg_graph_outputs(FG_SWEEP_NAMES),
        params:
            confs=[FG_CONFIG_MAP[n] for n in FG_SWEEP_NAMES],
            cfg={k: FG[k] for k in ("graph", "synthesis", "evaluation")},
            seed=FG_SEED_GRAPH,
        threads: 1
        resources:
            mem_mb=fg_mem_mb(1000),
            runtime=fg_runtime(5 * len(FG_SWEEP_NAMES)),
        log:
            L("facegraph/sweep_graphs.log"),
        benchmark:
            B("facegraph/sweep_graphs.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/facegraph_graphs.py"


rule facegraph_table1:
    input:
        runs=[R(f"facegraph/runs/{c['name']}.json") for c in FG_TABLE_CONFIGS],
        db=R("facegraph/preprocessed.npz"),
        paper=published_input("facegraph", "table1"),
    output:
        csv=report(
            R("facegraph/table1.csv"),
            caption="../report/facegraph_table1.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        md=R("facegraph/table1.md"),
        timing=R("facegraph/table1_timing.csv"),
        thresholds=report(
            R("facegraph/thresholds.csv"),
            caption="../report/facegraph_thresholds.rst",
            category="Facegraph",
            subcategory="Table 1",
        ),
        thresholds_md=R("facegraph/thresholds.md"),
    params:
        order=[c["name"] for c in FG_TABLE_CONFIGS],
        title="Table 1: region motion graphs for the paper's 15 compression configurations",
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    log:
        L("facegraph/table1.log"),
    benchmark:
        B("facegraph/table1.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_table1.py"


if FG_SWEEP_CONFIGS:

    rule facegraph_sweep:
        input:
            runs=[R(f"facegraph/runs/{c['name']}.json") for c in FG_SWEEP_CONFIGS],
            db=R("facegraph/preprocessed.npz"),
        output:
            csv=report(
                R("facegraph/sweep.csv"),
                caption="../report/facegraph_table1.rst",
                category="Facegraph",
                subcategory="Table 1",
            ),
            md=R("facegraph/sweep.md"),
            timing=R("facegraph/sweep_timing.csv"),
            thresholds=R("facegraph/sweep_thresholds.csv"),
            thresholds_md=R("facegraph/sweep_thresholds.md"),
        params:
            order=[c["name"] for c in FG_SWEEP_CONFIGS],
            title="Optional sweep: creation x merge targets (one tolerance)",
        threads: 1
        resources:
            mem_mb=500,
            runtime=5,
        log:
            L("facegraph/sweep.log"),
        benchmark:
            B("facegraph/sweep.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/facegraph_table1.py"


rule facegraph_baseline:
    input:
        db=R("facegraph/preprocessed.npz"),
        graphs=FG_SHOWCASE_GRAPH,
    output:
        csv=report(
            R("facegraph/baseline.csv"),
            caption="../report/facegraph_baseline.rst",
            category="Facegraph",
            subcategory="Baseline",
        ),
        md=R("facegraph/baseline.md"),
        timing=R("facegraph/baseline_timing.csv"),
    params:
        cfg={k: FG[k] for k in ("baseline", "synthesis", "evaluation")},
        showcase=FG_SHOWCASE,
        seed=FG_SEED_GRAPH,
    threads: 1
    resources:
        mem_mb=fg_mem_mb(3000),
        runtime=fg_runtime(30),
    log:
        L("facegraph/baseline.log"),
    benchmark:
        B("facegraph/baseline.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_baseline.py"


rule facegraph_uniqueness:
    input:
        db=R("facegraph/preprocessed.npz"),
        graphs=FG_SHOWCASE_GRAPH,
    output:
        csv=report(
            R("facegraph/uniqueness.csv"),
            caption="../report/facegraph_uniqueness.rst",
            category="Facegraph",
            subcategory="Uniqueness",
        ),
        md=R("facegraph/uniqueness.md"),
        pairs=R("facegraph/uniqueness_pairs.csv"),
    params:
        cfg={k: FG[k] for k in ("uniqueness", "synthesis")},
        seed=seed_for("facegraph", FG["seed"], "uniqueness"),
    threads: 1
    resources:
        mem_mb=fg_mem_mb(800),
        runtime=fg_runtime(15),
    log:
        L("facegraph/uniqueness.log"),
    benchmark:
        B("facegraph/uniqueness.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_uniqueness.py"


rule facegraph_figures:
    input:
        db=R("facegraph/preprocessed.npz"),
        graphs=FG_SHOWCASE_GRAPH,
    output:
        graph=report(
            R("facegraph/region_graphs.png"),
            caption="../report/facegraph_region_graphs.rst",
            category="Facegraph",
            subcategory="Figures",
        ),
        trajectories=report(
            R("facegraph/trajectories.png"),
            caption="../report/facegraph_trajectories.rst",
            category="Facegraph",
            subcategory="Figures",
        ),
        gif=report(
            R("facegraph/sequence.gif"),
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
        mem_mb=fg_mem_mb(1000),
        runtime=fg_runtime(15),
    log:
        L("facegraph/figures.log"),
    benchmark:
        B("facegraph/figures.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_figures.py"


rule facegraph_verdicts:
    input:
        table1=R("facegraph/table1.csv"),
        baseline=R("facegraph/baseline.csv"),
        uniqueness=R("facegraph/uniqueness.csv"),
        samples=[R(f"facegraph/runs/{c['name']}_samples.csv") for c in FG_TABLE_CONFIGS],
    output:
        csv=report(
            R("facegraph/verdicts.csv"),
            caption="../report/facegraph_verdicts.rst",
            category="Facegraph",
            subcategory="Verdicts",
        ),
        md=R("facegraph/verdicts.md"),
    params:
        source=FG_SOURCE,
        order=[c["name"] for c in FG_TABLE_CONFIGS],
    threads: 1
    resources:
        mem_mb=fg_mem_mb(500),
        runtime=fg_runtime(5),
    log:
        L("facegraph/verdicts.log"),
    benchmark:
        B("facegraph/verdicts.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/facegraph_verdicts.py"


FACEGRAPH_TARGETS = [
    R("facegraph/database.csv"),
    R("facegraph/table1.csv"),
    R("facegraph/thresholds.csv"),
    R("facegraph/baseline.csv"),
    R("facegraph/uniqueness.csv"),
    R("facegraph/region_graphs.png"),
    R("facegraph/trajectories.png"),
    R("facegraph/sequence.gif"),
    R("facegraph/verdicts.csv"),
] + ([R("facegraph/sweep.csv")] if FG_SWEEP_CONFIGS else [])
_FG_DATA_NOTE = (
    "Synthetic CK+-layout data generated by the workflow, not CK+." if FG_SYNTHETIC else f"Data: {FG_SOURCE}."
)
FACEGRAPH_SUMMARY = [
    {
        "title": "Serra et al. 2018 Table 1: region motion graphs for the paper's 15 configurations",
        "csv": R("facegraph/table1.csv"),
        "note": f"{_FG_DATA_NOTE} paper_* columns: the published values (published.facegraph.table1), empty if that "
        "file is missing. Creation/synthesis times (CPU and wall) are in table1_timing.csv.",
    },
    {
        "title": "Facegraph: face graph (Zhang et al. 2004) vs region graphs",
        "csv": R("facegraph/baseline.csv"),
        "note": f"{_FG_DATA_NOTE} Path-finding times (and the paper's ~1.9 s) are in baseline_timing.csv.",
    },
    {
        "title": "Facegraph: distinct animations from one label sequence",
        "csv": R("facegraph/uniqueness.csv"),
        "note": _FG_DATA_NOTE,
    },
]
FACEGRAPH_VERDICTS = [R("facegraph/verdicts.csv")]
# Key figures for the summary and the report's home page, with what to see in them.
FACEGRAPH_FIGURES = [
    {
        "png": R("facegraph/trajectories.png"),
        "caption": "Landmark trajectories of original sequences (blue) and their re-synthesis through the region "
        "graphs (red): the same shape and timing is the Table 1 claim that synthesis keeps the original "
        "durations and displacements.",
    }
]
