# Data layer: get every trial (generate synthetic ASF/AMC, or download real
# CMU / copy user files with checksums) and parse it with the real readers into
# results/data/trials/{trial}.npz (Gauch & Peters Table I of the subsets,
# results/data/datasets.csv, is the simplicial family's: simplicial.smk).
# Downloads are not retried by Snakemake: animsynth.data retries network
# failures itself, and a checksum mismatch is deterministic.
# threads/resources (mem_mb in MB, runtime in minutes) are sized from the
# measured peak memory and run time (results/rule_benchmarks_per_rule.csv)
# with headroom (2x memory, 3x time, at least 500 MB / 10 min); a SLURM
# profile submits each job with them. Measured (tiny and CMU configs, loaded
# 2-core machine): every data job peaks at <= 110 MB and takes <= 14 s; the
# downloads get 20 min for a slow network (3 attempts with a 60 s timeout each).

if SOURCE == "synthetic":

    # One job per trial (a fraction of a second each): a changed trial record
    # reruns that trial's jobs and the studies that read it, nothing else.
    rule synth_trial:
        output:
            amc=R("resources/mocap/{trial}.amc"),
            asf=R("resources/mocap/{trial}.asf"),
        params:
            spec=trial_spec,
            seed=synthetic_trial_seed,
            subject_seed=config["synthetic_mocap"]["seed"],
            fps=config["fps"],
        threads: 1
        resources:
            mem_mb=500,
            runtime=10,
        log:
            L("data/synth_trial/{trial}.log"),
        benchmark:
            B("data/synth_trial/{trial}.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_synth_trial.py"

else:

    rule download_trial:
        output:
            amc=R("resources/mocap/{trial}.amc"),
            asf=R("resources/mocap/{trial}.asf"),
        params:
            source=trial_source_param,
            amc=trial_field("amc"),
            asf=trial_field("asf"),
            sha256=trial_field("sha256", required=False),
            asf_sha256=trial_field("asf_sha256", required=False),
        threads: 1
        resources:
            mem_mb=500,
            runtime=20,
        log:
            L("data/download_trial/{trial}.log"),
        benchmark:
            B("data/download_trial/{trial}.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_download_trial.py"

    rule download_bvh_trial:
        output:
            bvh=R("resources/mocap/{trial}.bvh"),
        params:
            source=trial_source_param,
            bvh=trial_field("bvh"),
            sha256=trial_field("sha256", required=False),
        threads: 1
        resources:
            mem_mb=500,
            runtime=20,
        log:
            L("data/download_bvh_trial/{trial}.log"),
        benchmark:
            B("data/download_bvh_trial/{trial}.tsv")
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_download_trial.py"


# One job per trial, so that editing or adding one trial rewrites only its own
# .npz and reruns only the studies that read it.
rule parse_trial:
    input:
        unpack(raw_trial_input),
    output:
        R("data/trials/{trial}.npz"),
    params:
        fps=config["fps"],
        settings=trial_settings,
    threads: 1
    resources:
        mem_mb=500,
        runtime=10,
    log:
        L("data/parse_trial/{trial}.log"),
    benchmark:
        B("data/parse_trial/{trial}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/data_parse_trial.py"


DATA_TARGETS = [trial_npz(t) for t in USED_TRIALS]


# ---- mesh sequences of the hybrid mesh experiments -------------------------
# Each sequence's mesh_dir (MD_SEQS, common.smk) is a folder of OBJ / OBJ.gz
# frames, an archive of one (.zip, .tar.gz) or a URL of such an archive;
# archives are unpacked into <results_dir>/resources/mesh/<name>/. With mesh_sha256 set, every
# frame is checked against that list before any experiment reads it, and a
# mismatch names the frame.
MD_FRAMES = {}  # sequence name -> folder of frames (or the synthetic character's)
MESH_FETCH = {}  # <name> (of <results_dir>/resources/mesh/<name>) -> archive or URL
MESH_FETCH_SUMS = {}  # <name> -> [its SHA-256 list] or []
for _name, _s in MD_SEQS.items():
    _src = _s["mesh_dir"]
    if not _src:
        MD_FRAMES[_name] = R("meshdetail/character/main")
    elif is_url(_src) or is_archive(_src):
        MD_FRAMES[_name] = R(f"resources/mesh/{mesh_source_name(_src)}")
        MESH_FETCH[mesh_source_name(_src)] = _src
        # the fetch checks the frames against the sequence's list before it places them
        MESH_FETCH_SUMS[mesh_source_name(_src)] = [_s["mesh_sha256"]] if _s["mesh_sha256"] else []
    else:
        MD_FRAMES[_name] = _src
MESH_CHECK = {n: [R(f"data/mesh_checksums/{n}.csv")] for n, s in MD_SEQS.items() if s["mesh_dir"] and s["mesh_sha256"]}

if MESH_FETCH:

    rule mesh_fetch:
        input:
            sums=mesh_fetch_sums,
        output:
            directory(R("resources/mesh/{meshsrc}")),
        params:
            source=mesh_fetch_source,
            max_unpacked_mb=config["meshdetail"]["max_unpacked_mb"],
        log:
            L("data/mesh_fetch/{meshsrc}.log"),
        benchmark:
            B("data/mesh_fetch/{meshsrc}.tsv")
        threads: 1
        resources:
            mem_mb=1000,
            runtime=30,
        wildcard_constraints:
            meshsrc="|".join(map(re.escape, MESH_FETCH)),
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_mesh_fetch.py"


if MESH_CHECK:

    rule mesh_checksums:
        input:
            frames=mesh_sequence_frames,
            sums=mesh_sequence_sums,
        output:
            R("data/mesh_checksums/{mdseq}.csv"),
        log:
            L("data/mesh_checksums/{mdseq}.log"),
        benchmark:
            B("data/mesh_checksums/{mdseq}.tsv")
        threads: 1
        resources:
            mem_mb=1000,
            runtime=10,
        wildcard_constraints:
            mdseq="|".join(map(re.escape, MESH_CHECK)),
        conda:
            "../envs/animsynth.yaml"
        script:
            "../scripts/data_mesh_checksums.py"
