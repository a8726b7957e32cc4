# Scale study (docs/scale.md): one job per family x size (cost curves), one per
# landmark-vs-exact size, the 100,000-frame re-sequencing benchmark, and the
# aggregation (cost_curves.csv, exponents, log-log plot). Included only when
# config key scale.enabled is true (config/scale.yaml).
from animsynth.families import scaled as scaled_families

SCALE = config["scale"]
SCALE_SOURCE = SCALE["source"]
if SCALE_SOURCE == "cmu" and not os.path.isdir(os.path.join(str(config["cmu_mirror"]), "subjects")):
    raise ConfigError(
        f"config key 'scale.source' is cmu but 'cmu_mirror' ({config['cmu_mirror']}) is not a local folder with subjects/"
    )
SCALE_MIRROR = config["cmu_mirror"] if SCALE_SOURCE == "cmu" else None


# (family, point) of every cost-curve job, for every family the registry says the scale study measures
# (animsynth.families: its sizes from scale.<family>.sizes; points of a family measured over mesh resolutions are
# frames x resolution).
SCALE_POINTS = [
    (f.name, f"n{n}_r{r}" if f.scale.resolutions else f"n{n}")
    for f in scaled_families()
    for n in SCALE[f.name]["sizes"]
    for r in (SCALE[f.name]["resolutions"] if f.scale.resolutions else [None])
]
SCALE_TARGETS = [
    R("scale/cost_curves.csv"),
    R("scale/cost_exponents.csv"),
    R("scale/cost_curves.png"),
    R("scale/landmark_vs_exact.csv"),
    R("scale/landmark_vs_exact_rv.csv"),
    R("scale/benchmarks.csv"),
    R("benchmarks.csv"),
]


wildcard_constraints:
    scfamily="|".join(f.name for f in scaled_families()),
    scpoint=r"n\d+(_r[0-9.]+)?",
    scn=r"\d+",


rule scale_measure:
    output:
        R("scale/work/{scfamily}_{scpoint}.csv"),
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=scale_point_seed,
    log:
        L("scale/measure/{scfamily}_{scpoint}.log"),
    benchmark:
        B("scale/measure/{scfamily}_{scpoint}.tsv")
    threads: 1
    resources:
        mem_mb=scale_point_mem_mb,
        runtime=60,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_measure.py"


rule scale_curves:
    input:
        [R(f"scale/work/{f}_{p}.csv") for f, p in SCALE_POINTS],
    output:
        curves=R("scale/cost_curves.csv"),
        exponents=report(
            R("scale/cost_exponents.csv"),
            caption="../report/scale_exponents.rst",
            category="6. Scale",
        ),
        plot=report(
            R("scale/cost_curves.png"),
            caption="../report/scale_cost_curves.rst",
            category="6. Scale",
        ),
    log:
        L("scale/curves.log"),
    benchmark:
        B("scale/curves.tsv")
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
        summary=R("scale/work/landmark_vs_exact_n{scn}.csv"),
        rv=R("scale/work/landmark_vs_exact_rv_n{scn}.csv"),
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=landmark_vs_exact_seed,
    log:
        L("scale/landmark_vs_exact/n{scn}.log"),
    benchmark:
        B("scale/landmark_vs_exact/n{scn}.tsv")
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
        summary=expand(R("scale/work/landmark_vs_exact_n{n}.csv"), n=SCALE["landmark_vs_exact"]["sizes"]),
        rv=expand(R("scale/work/landmark_vs_exact_rv_n{n}.csv"), n=SCALE["landmark_vs_exact"]["sizes"]),
    output:
        summary=report(
            R("scale/landmark_vs_exact.csv"),
            caption="../report/scale_landmark_vs_exact.rst",
            category="6. Scale",
        ),
        rv=R("scale/landmark_vs_exact_rv.csv"),
    log:
        L("scale/landmark_table.log"),
    benchmark:
        B("scale/landmark_table.tsv")
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
            R("scale/benchmarks.csv"),
            caption="../report/scale_benchmarks.rst",
            category="6. Scale",
        ),
    params:
        cfg=SCALE,
        mirror=SCALE_MIRROR,
        seed=seed_for("scale", "benchmark"),
    log:
        L("scale/benchmark.log"),
    benchmark:
        B("scale/benchmark.tsv")
    threads: 1
    resources:
        mem_mb=SCALE["resequencing"]["mem_mb"],
        runtime=60,
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/scale_benchmark.py"
