# Data layer: get every trial (generate synthetic ASF/AMC, or download real
# CMU / copy user files with checksums), parse it with the real readers into
# results/data/trials/{trial}.npz, and write Gauch & Peters Table I.

if SOURCE == "synthetic":

    rule synth_trial:
        output:
            amc="resources/mocap/{trial}.amc",
            asf="resources/mocap/{trial}.asf",
        params:
            spec=lambda wc: TRIALS[wc.trial],
            seed=lambda wc: seed_for("synthetic_mocap", config["synthetic_mocap"]["seed"], wc.trial),
            subject_seed=config["synthetic_mocap"]["seed"],
            fps=config["fps"],
        log:
            "logs/data/synth_trial/{trial}.log",
        benchmark:
            "benchmarks/rules/data/synth_trial/{trial}.tsv"
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_synth_trial.py"

else:

    rule download_trial:
        output:
            amc="resources/mocap/{trial}.amc",
            asf="resources/mocap/{trial}.asf",
        params:
            source=MOCAP_MIRROR,
            amc=lambda wc: TRIALS[wc.trial]["amc"],
            asf=lambda wc: TRIALS[wc.trial]["asf"],
            sha256=lambda wc: TRIALS[wc.trial].get("sha256"),
            asf_sha256=lambda wc: TRIALS[wc.trial].get("asf_sha256"),
        log:
            "logs/data/download_trial/{trial}.log",
        benchmark:
            "benchmarks/rules/data/download_trial/{trial}.tsv"
        retries: 2
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_download_trial.py"

    rule download_bvh_trial:
        output:
            bvh="resources/mocap/{trial}.bvh",
        params:
            source=MOCAP_MIRROR,
            bvh=lambda wc: TRIALS[wc.trial]["bvh"],
            sha256=lambda wc: TRIALS[wc.trial].get("sha256"),
        log:
            "logs/data/download_bvh_trial/{trial}.log",
        benchmark:
            "benchmarks/rules/data/download_bvh_trial/{trial}.tsv"
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_download_trial.py"


rule parse_trial:
    input:
        unpack(raw_trial_files),
    output:
        "results/data/trials/{trial}.npz",
    params:
        fps=config["fps"],
    log:
        "logs/data/parse_trial/{trial}.log",
    benchmark:
        "benchmarks/rules/data/parse_trial/{trial}.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/data_parse_trial.py"


rule datasets_table:
    input:
        lambda wc: [trial_npz(t) for ids in SUBSETS.values() for t in ids],
    output:
        csv=report(
            "results/data/datasets.csv",
            caption="../report/data_datasets.rst",
            category="1. Data",
            labels={"table": "Gauch & Peters Table I"},
        ),
        md="results/data/datasets.md",
    params:
        subsets=SUBSETS,
        source=SOURCE,
        paper_table1=config.get("simplicial", {}).get("paper_table1"),
    log:
        "logs/data/datasets_table.log",
    benchmark:
        "benchmarks/rules/data/datasets_table.tsv"
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/data_datasets_table.py"


DATA_TARGETS = ["results/data/datasets.csv"] + [trial_npz(t) for t in USED_TRIALS]
