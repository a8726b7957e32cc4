# Scale study (docs/scale.md): one job per family x size (cost curves), one per
# landmark-vs-exact size, the 100,000-frame re-sequencing benchmark, and the
# aggregation (cost_curves.csv, exponents, log-log plot). Included only when
# config key scale.enabled is true (config/scale.yaml).
SCALE = config["scale"]
SCALE_SOURCE = SCALE["source"]
if SCALE_SOURCE == "cmu" and not os.path.isdir(os.path.join(str(config["cmu_mirror"]), "subjects")):
    raise ConfigError(
        f"config key 'scale.source' is cmu but 'cmu_mirror' ({config['cmu_mirror']}) is not a local folder with subjects/"
    )
SCALE_MIRROR = config["cmu_mirror"] if SCALE_SOURCE == "cmu" else None


# (family, point) of every cost-curve job; meshdetail points are frames x resolution.
SCALE_POINTS = (
    [("resequencing", f"n{n}") for n in SCALE["resequencing"]["sizes"]]
    + [("simplicial", f"n{n}") for n in SCALE["simplicial"]["sizes"]]
    + [("facegraph", f"n{n}") for n in SCALE["facegraph"]["sizes"]]
    + [("meshdetail", f"n{n}_r{r}") for n in SCALE["meshdetail"]["sizes"] for r in SCALE["meshdetail"]["resolutions"]]
)
SCALE_TARGETS = [
    "results/scale/cost_curves.csv",
    "results/scale/cost_exponents.csv",
    "results/scale/cost_curves.png",
    "results/scale/landmark_vs_exact.csv",
    "results/scale/landmark_vs_exact_rv.csv",
    "results/scale/benchmarks.csv",
]


wildcard_constraints:
    scfamily="resequencing|simplicial|facegraph|meshdetail",
    scpoint=r"n\d+(_r[0-9.]+)?",
    scn=r"\d+",


rule scale_measure:
    output:
        "results/scale/work/{scfamily}_{scpoint}.csv",
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=lambda wc: seed_for("scale", wc.scfamily, wc.scpoint),
    log:
        "logs/scale/measure/{scfamily}_{scpoint}.log",
    benchmark:
        "benchmarks/rules/scale/measure/{scfamily}_{scpoint}.tsv"
    threads: 1
    resources:
        mem_mb=lambda wc: SCALE["resequencing"]["mem_mb"] if wc.scfamily == "resequencing" else 3000,
        runtime=60,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_measure.py"


rule scale_curves:
    input:
        [f"results/scale/work/{f}_{p}.csv" for f, p in SCALE_POINTS],
    output:
        curves="results/scale/cost_curves.csv",
        exponents=report(
            "results/scale/cost_exponents.csv",
            caption="../report/scale_exponents.rst",
            category="6. Scale",
        ),
        plot=report(
            "results/scale/cost_curves.png",
            caption="../report/scale_cost_curves.rst",
            category="6. Scale",
        ),
    log:
        "logs/scale/curves.log",
    benchmark:
        "benchmarks/rules/scale/curves.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_curves.py"


rule scale_landmark_vs_exact:
    output:
        summary="results/scale/work/landmark_vs_exact_n{scn}.csv",
        rv="results/scale/work/landmark_vs_exact_rv_n{scn}.csv",
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=lambda wc: seed_for("scale", "landmark_vs_exact", wc.scn),
    log:
        "logs/scale/landmark_vs_exact/n{scn}.log",
    benchmark:
        "benchmarks/rules/scale/landmark_vs_exact/n{scn}.tsv"
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_landmark_vs_exact.py"


rule scale_landmark_table:
    input:
        summary=expand("results/scale/work/landmark_vs_exact_n{n}.csv", n=SCALE["landmark_vs_exact"]["sizes"]),
        rv=expand("results/scale/work/landmark_vs_exact_rv_n{n}.csv", n=SCALE["landmark_vs_exact"]["sizes"]),
    output:
        summary=report(
            "results/scale/landmark_vs_exact.csv",
            caption="../report/scale_landmark_vs_exact.rst",
            category="6. Scale",
        ),
        rv="results/scale/landmark_vs_exact_rv.csv",
    log:
        "logs/scale/landmark_table.log",
    benchmark:
        "benchmarks/rules/scale/landmark_table.tsv"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_landmark_table.py"


rule scale_benchmark:
    input:
        "benchmarks/scale_reseq.py",
    output:
        report(
            "results/scale/benchmarks.csv",
            caption="../report/scale_benchmarks.rst",
            category="6. Scale",
        ),
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=seed_for("scale", "benchmark"),
    log:
        "logs/scale/benchmark.log",
    benchmark:
        "benchmarks/rules/scale/benchmark.tsv"
    threads: 1
    resources:
        mem_mb=SCALE["resequencing"]["mem_mb"],
        runtime=60,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_benchmark.py"
