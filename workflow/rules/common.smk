# Shared helpers: config checks beyond the schema, trial lookups, target lists.
import importlib
import json
import re
from pathlib import Path

from snakemake.io import is_flagged, strip_wildcard_constraints

from animsynth.compare.settings import subject_sets
from animsynth.config import (TRIAL_FILE_KEYS, TRIAL_READ_KEYS, check_config, derive_seed, normalise_resequencing_trials,
                              trial_mirror, trial_setting)
from animsynth.families import FAMILIES, report_order
from animsynth.meshdetail.settings import mesh_sequences
from animsynth.sources import is_archive, is_url, mesh_source_name, missing_below, probe_source
from animsynth.workflow_utils import config_errors_stop_the_run


# Config checks beyond the schema, in one place: the shared ones, then the settings.check(config) of each family
# of the registry (animsynth.families; it names the offending config key).
# resequencing_trials may hold any subset of walk, run, dance: the studies without a trial of
# this config are left out with a note (the default's trial ids are not a user's).
import yaml as _yaml

with config_errors_stop_the_run():
    with open(Path(workflow.basedir) / "config" / "config.yaml") as _f:
        normalise_resequencing_trials(config, (_yaml.safe_load(_f) or {}).get("resequencing_trials") or {})
    check_config(config)
    for _family in FAMILIES:
        importlib.import_module(f"animsynth.{_family.name}.settings").check(config)
# On a user's data, every trial, subset or clip that a family's selection key leaves out is one line on stderr naming
# the key (a family's settings.left_out(config); the demo's own selections, e.g. compare.subsets: [r1], would
# otherwise leave a user's groups out silently).
if config["mocap_source"] == "user":
    from animsynth.config import unused_trials

    _left = unused_trials(config)
    for _family in FAMILIES:
        _left += getattr(importlib.import_module(f"animsynth.{_family.name}.settings"), "left_out", lambda c: [])(config)
    for _line in _left:
        print(f"animsynth: {_line}", file=sys.stderr)

TRIALS = {t["id"]: t for t in config["trials"]}
SUBSETS = {k: v for k, v in config["subsets"].items() if v}  # null drops a subset
RESEQ_TRIALS = dict(config["resequencing_trials"])
# Every trial the papers' experiments use (subsets first, in config order); the comparison's own per-subject
# trials (compare.subjects) join them below once their mirror is known to be readable (CMP_SUBJECT_TRIALS).
USED_TRIALS = list(dict.fromkeys([t for ids in SUBSETS.values() for t in ids] + list(RESEQ_TRIALS.values())))
CMP_SUBJECT_TRIALS = list(dict.fromkeys(t for ids in subject_sets(config).values() for t in ids))


wildcard_constraints:
    trial="|".join(sorted(TRIALS)) if TRIALS else "[A-Za-z0-9_-]+",
    dataset="|".join(sorted(SUBSETS)) if SUBSETS else "[a-z0-9]+",


SOURCE = config["mocap_source"]
# Where real trials come from: the CMU site or a mirror, or the user's folder; a CMU trial whose record sets
# mirror: many comes from cmu_many_mirror (cmu_mirror when that is null).
MOCAP_MIRROR = config["cmu_mirror"] if SOURCE == "cmu" else config["data_dir"]


def trial_source(trial):
    """The mirror or folder one real trial's files are read from (animsynth.config.trial_mirror)."""
    return trial_mirror(config, TRIALS[trial])


def trial_source_param(wildcards):
    """Params function: the mirror of the trial of one download job."""
    return trial_source(wildcards.trial)


BVH_TRIALS = {t for t, rec in TRIALS.items() if "bvh" in rec and "amc" not in rec}


def raw_trial_files(trial):
    """Raw files of one trial: ASF + AMC, or BVH."""
    if trial in BVH_TRIALS:
        return {"bvh": R(f"resources/mocap/{trial}.bvh")}
    return {
        "amc": R(f"resources/mocap/{trial}.amc"),
        "asf": R(f"resources/mocap/{trial}.asf"),
    }


def seed_for(*names):
    """Seed for one random choice, derived from config['seed'] and a name path."""
    return derive_seed(config["seed"], *names)


def trial_npz(trial):
    return R(f"data/trials/{trial}.npz")


def subset_npz(wildcards):
    return [trial_npz(t) for t in SUBSETS[wildcards.dataset]]


def job_benchmarks(rule_name, **wildcards):
    """Benchmark files of the jobs of one rule in this run (wildcard value lists zipped); the benchmark
    aggregation declares them as inputs, so it holds exactly this run's jobs, never a stale file of another run."""
    pattern = strip_wildcard_constraints(str(getattr(rules, rule_name).rule.benchmark))
    files = expand(pattern, zip, **wildcards) if wildcards else [pattern]
    if not files or any("{" in f for f in files):
        raise ValueError(f"benchmark files of {rule_name}: {pattern} with {wildcards} gave {files}")
    return files


def family_part(family, part):
    """What the .smk of a family defines by the naming convention of the registry (animsynth.families), that is
    <FAMILY>_<part> (TARGETS, SUMMARY, VERDICTS, FIGURES), or the function <family>_<part> (benchmarks)."""
    name = f"{family}_{part}" if part == "benchmarks" else f"{family.upper()}_{part}"
    if name not in globals():
        raise NameError(f"workflow/rules/{family}.smk defines no {name} (every family of animsynth.families does)")
    return globals()[name]


def family_targets():
    """Targets of the data layer and of every family that runs (a family whose data are unavailable is left out)."""
    targets = {"data": DATA_TARGETS, **{f.name: family_part(f.name, "TARGETS") for f in FAMILIES}}
    return [t for fam, ts in targets.items() if FAMILY_RAN[fam] for t in ts]


def all_targets():
    return family_targets() + REPORT_TARGETS


# ---- where this run's results live -------------------------------------
# results_dir (default "results") holds every output of this run; a run with
# another results_dir (the paper run: results/paper) also keeps its own logs
# and rule benchmarks below it, so two runs never share a file.
OUT = str(config["results_dir"]).rstrip("/")


def R(path):
    """Path of a result of this run: <results_dir>/<path>."""
    return f"{OUT}/{path}"


def L(path):
    """Log path: logs/<path>, or <results_dir>/logs/<path> for another results_dir."""
    return f"logs/{path}" if OUT == "results" else f"{OUT}/logs/{path}"


# Job benchmark files are outputs of the run: below its results folder, never beside the benchmark sources.
BENCH_ROOT = f"{OUT}/benchmarks/rules"


def B(path):
    """Benchmark file path (aggregated into rule_benchmarks.csv)."""
    return f"{BENCH_ROOT}/{path}"


# ---- which real data are reachable --------------------------------------
# With on_missing_data: skip (the paper run), a family whose real data cannot
# be read now (no network, no mirror, no mesh folder) is left out with one
# line on stderr, and the summary/report say which parts ran on what. With the
# default (fail) nothing is probed: a missing file fails the job that reads it.
ON_MISSING = config["on_missing_data"]


def _status(label, source=None, probe=None):
    """(label, available, reason) of one data source; probed only with on_missing_data: skip."""
    if source is None or ON_MISSING != "skip":
        return label, True, ""
    ok, why = probe_source(source, probe)
    return label, ok, why


# Mesh sequences of the hybrid mesh family: name -> {mesh_dir, mesh_sha256, mesh_fps, render_frames, rig}
# (the top-level mesh_dir or the synthetic character first, then meshdetail.sequences).
MD_SEQS = mesh_sequences(config)


def _family_status():
    if SOURCE == "synthetic":
        mocap = _status("synthetic mocap (generated by the workflow)")
    else:
        first = next((TRIALS[t] for t in USED_TRIALS if t in TRIALS), {})
        kind = "CMU mocap" if SOURCE == "cmu" else "user mocap"
        mocap = _status(f"{kind} from {MOCAP_MIRROR}", MOCAP_MIRROR, first.get("amc") or first.get("bvh"))
        # every file of the papers' trials (a local mirror): a subset or clip with a trial missing is not the paper's
        # study, so the mocap families are left out as for a mirror that cannot be read, naming the files
        gone = _missing_trial_files(USED_TRIALS) if mocap[1] and ON_MISSING == "skip" else {}
        if gone:
            mocap = (mocap[0], False, f"files missing below the mirror: {_listing(gone)}")
    mesh_src = config["mesh_dir"]
    mesh = _status(f"mesh sequence {mesh_src}", mesh_src) if mesh_src else _status(
        "synthetic skirt character (generated by the workflow)")
    # further mesh sequences (meshdetail.sequences): one that cannot be read now is left out
    for name in list(MD_SEQS)[1:] if mesh[1] else []:
        _label, ok, why = _status(name, MD_SEQS[name]["mesh_dir"])
        if not ok:
            print(f"animsynth: skipping mesh sequence {name}: data unavailable ({why})", file=sys.stderr)
            del MD_SEQS[name]
    if mesh[1] and len(MD_SEQS) > 1:
        mesh = ("mesh sequences " + ", ".join(f"{n} ({s['mesh_dir']})" for n, s in MD_SEQS.items()), True, "")
    ck = config["facegraph"]["ckplus_dir"]
    faces = _status(f"CK+ from {ck}", ck) if ck else _status("synthetic CK+-layout database (not real CK+)")
    # each family's data source, by the kind of data the registry gives it (the report's order)
    sources = {"mocap": mocap, "mesh": mesh, "faces": faces}
    status = {"data": mocap, **{f.name: sources[f.data] for f in report_order()}}
    _probe_other_mirrors(mocap[1])
    if not config["resequencing"]["datasets"]:  # resequencing_trials all null (or none of them in the run)
        status["resequencing"] = (mocap[0], False, "no trial in resequencing_trials")
    skipped = {}
    for fam, (_label, ok, why) in status.items():
        if not ok and fam != "data":
            skipped.setdefault(why, []).append(fam)
    for why, fams in skipped.items():
        print(f"animsynth: skipping {' and '.join(fams)}: data unavailable ({why})", file=sys.stderr)
    return status, {fam: ok for fam, (_label, ok, _why) in status.items()}


# Trials of the comparison whose mirror cannot be read now (on_missing_data: skip): the comparison leaves out
# every group holding one (animsynth.compare.settings.groups), the other families are unaffected.
CMP_MISSING = set()


def _missing_trial_files(ids):
    """``{trial: [its files that are not readable]}`` of the trials ``ids`` whose mirror is a local folder
    (animsynth.sources.missing_below: a link to a readable file counts as the file)."""
    gone = {}
    for t in ids:
        rec = TRIALS[t]
        miss = missing_below(trial_source(t), [rec[k] for k in TRIAL_FILE_KEYS if k in rec])
        if miss:
            gone[t] = miss
    return gone


def _listing(gone, most=4):
    """``{trial: [files]}`` as one short text: the first few trials and their files."""
    text = "; ".join(f"{t}: {', '.join(files)}" for t, files in list(gone.items())[:most])
    return text + (f"; and {len(gone) - most} more trial(s)" if len(gone) > most else "")


def _probe_other_mirrors(mocap_ok):
    """With on_missing_data: skip, probe the mirrors of the comparison's own trials (compare.subjects): a mirror other
    than the main one (cmu_many_mirror for records with mirror: many) that cannot be read, or is a file, leaves all of
    its trials out; a trial with a file missing below a local mirror (its ASF, AMC or BVH) leaves its set out. Only
    when the main mocap source is readable (otherwise every mocap family is skipped already); the trials left out
    go to CMP_MISSING, with one line per mirror naming them."""
    if SOURCE == "synthetic" or not mocap_ok or ON_MISSING != "skip":
        return
    by_mirror = {}
    for t in CMP_SUBJECT_TRIALS:
        by_mirror.setdefault(trial_source(t), []).append(t)
    for src, ids in by_mirror.items():
        if src != MOCAP_MIRROR:
            rec = TRIALS[ids[0]]
            _label, ok, why = _status(src, src, rec.get("amc") or rec.get("bvh"))
            if not ok:
                print(f"animsynth: compare: leaving out trials {' '.join(ids)} of mirror {src}: data unavailable "
                      f"({why})", file=sys.stderr)
                CMP_MISSING.update(ids)
                continue
        gone = _missing_trial_files(ids)
        if gone:
            sets = [n for n, members in subject_sets(config).items() if set(gone) & set(members)]
            print(f"animsynth: compare: leaving out set(s) {' '.join(sets)} of compare.subjects: files missing below "
                  f"mirror {src} ({_listing(gone)})", file=sys.stderr)
            CMP_MISSING.update(gone)


FAMILY_STATUS, FAMILY_RAN = _family_status()
# the comparison's own per-subject trials are fetched and parsed with the others when it runs (the sets none of
# whose trials is missing: the sets it compares); the papers' families never read them
if FAMILY_RAN["compare"]:
    USED_TRIALS = list(dict.fromkeys(USED_TRIALS + [t for ids in subject_sets(config).values()
                                                    if not CMP_MISSING & set(ids) for t in ids]))
# Real or synthetic data per family, from the data sources themselves (never from words in a table), by the kind
# of data the registry gives each family (the report's order).
_REAL = {
    "mocap": SOURCE != "synthetic",
    "mesh": all(s["mesh_dir"] for s in MD_SEQS.values()),  # every sequence of the run is real
    "faces": bool(config["facegraph"]["ckplus_dir"]),
}
FAMILY_REAL = {"data": _REAL["mocap"], **{f.name: _REAL[f.data] for f in report_order()}}


def provenance_rows():
    """What each family ran on, for the summary and the report's home page."""
    return [
        {"family": fam, "data": label, "status": "ran" if FAMILY_RAN[fam] else f"skipped: {why}"}
        for fam, (label, _ok, why) in FAMILY_STATUS.items()
        if fam != "data"
    ]


def report_outputs(wildcards=None):
    """Every output path pattern wrapped in report(...), for links from the report's home page."""
    return sorted({str(f) for r in workflow.rules for f in r.output if is_flagged(f, "report")})


# ---- per-family helpers (the functions live here; each family's file holds its rules) ----
def raw_trial_input(wildcards):
    """Raw files of the trial of one parse job (input function)."""
    return raw_trial_files(wildcards.trial)


# Benchmark files of this family's jobs (inputs of rule_benchmarks).
def data_benchmarks():
    if SOURCE == "synthetic":
        raw = job_benchmarks("synth_trial", trial=USED_TRIALS)
    else:
        amc = [t for t in USED_TRIALS if t not in BVH_TRIALS]
        bvh = [t for t in USED_TRIALS if t in BVH_TRIALS]
        raw = (job_benchmarks("download_trial", trial=amc) if amc else []) + (
            job_benchmarks("download_bvh_trial", trial=bvh) if bvh else []
        )
    return raw + job_benchmarks("parse_trial", trial=USED_TRIALS)


def mesh_data_benchmarks():
    """The mesh sequences' fetch and checksum jobs (in the run when the hybrid mesh family runs)."""
    fetch = job_benchmarks("mesh_fetch", meshsrc=list(MESH_FETCH)) if MESH_FETCH else []
    return fetch + (job_benchmarks("mesh_checksums", mdseq=list(MESH_CHECK)) if MESH_CHECK else [])


# ---- simplicial input functions ----
def simplicial_subset_ids(wildcards):
    """Trial ids of the subset of one fold or grid job, in config order (fold i holds trial i out)."""
    return SUBSETS[wildcards.dataset]


def simplicial_grid_cfg(wildcards):
    """The config keys one grid job (derivative or beyond) depends on."""
    return SIMP_GRID_CFG[wildcards.grid]


# Benchmark files of this family's jobs (inputs of rule_benchmarks).
def simplicial_benchmarks():
    grids = [(g, d) for g in ("derivative", "beyond") for d in SIMP_DATASETS]
    return (
        job_benchmarks("simplicial_table1")
        + job_benchmarks("simplicial_fold", dataset=SIMP_DATASETS)
        + job_benchmarks("simplicial_table")
        + job_benchmarks("simplicial_grid", grid=[g for g, _ in grids], dataset=[d for _, d in grids])
        + job_benchmarks("simplicial_summary")
        + job_benchmarks("simplicial_figures")
        + job_benchmarks("simplicial_walk")
    )


# ---- resequencing input functions ----
def reseq_trial(wildcards):
    """The trial id of a re-sequencing dataset (params of the analyse and explain jobs)."""
    return RESEQ_TRIALS[wildcards.rsdata]


def reseq_trial_npz(wildcards):
    """The parsed trial of a re-sequencing dataset (input of its analyse, explain and path jobs)."""
    return trial_npz(RESEQ_TRIALS[wildcards.rsdata])


def reseq_pairs_seed(wildcards):
    """Seed of a dataset's measured start/end pairs (the same for every method, metric and global flag)."""
    return seed_for("resequencing", "pairs", wildcards.rsdata)


def reseq_path_outputs(pattern):
    """One output per method x metric x global flag of a dataset (the order of RESEQ_PATH_CONFIGS)."""
    return [pattern.format(rsmethod=m, rsmetric=x, rsgdof=g) for m, x, g in RESEQ_PATH_CONFIGS]


# Benchmark files of this family's jobs (inputs of rule_benchmarks).
def resequencing_benchmarks():
    pairs = [(d, g) for d in RESEQ_DATASETS for g in RESEQ_GDOF]
    return (
        job_benchmarks("resequencing_analyse", rsdata=[d for d, _ in pairs], rsgdof=[g for _, g in pairs])
        + job_benchmarks("resequencing_explain", rsdata=RESEQ_DATASETS)
        + job_benchmarks("resequencing_path", rsdata=RESEQ_DATASETS)
        + job_benchmarks("resequencing_figures", rsdata=RESEQ_DATASETS)
        + job_benchmarks("resequencing_tables")
    )


# ---- facegraph input functions ----
# (the functions of workflow/rules/facegraph.smk; FG_* are defined there and looked up when called)
def fg_graph_outputs(names):
    """Per-configuration outputs of one graphs job, in the order of ``names``."""
    return dict(
        graphs=[R(f"facegraph/graphs/{n}.npz") for n in names],
        run=[R(f"facegraph/runs/{n}.json") for n in names],
        samples=[R(f"facegraph/runs/{n}_samples.csv") for n in names],
        sample_thresholds=[R(f"facegraph/runs/{n}_thresholds.csv") for n in names],
    )


def fg_mem_mb(mb):
    """Resource function of a facegraph rule: ``mb`` MB of memory, times the attempt on a retry."""

    def facegraph_mem_mb(wildcards, attempt):
        return mb * attempt

    return facegraph_mem_mb


def fg_runtime(minutes):
    """Resource function of a facegraph rule: ``minutes`` at the default database size, scaled by the
    database size (FG_SCALE) and by the attempt on a retry."""

    def facegraph_runtime(wildcards, attempt):
        return int(minutes * FG_SCALE * attempt)

    return facegraph_runtime


# Benchmark files of this family's jobs (inputs of rule_benchmarks).
def facegraph_benchmarks():
    rules_run = (["facegraph_synth_db"] if FG_SYNTHETIC else []) + ["facegraph_prepare", "facegraph_graphs"]
    rules_run += (["facegraph_sweep_graphs"] if FG_SWEEP_NAMES else []) + ["facegraph_table1"]
    rules_run += (["facegraph_sweep"] if FG_SWEEP_CONFIGS else []) + [
        "facegraph_baseline", "facegraph_uniqueness", "facegraph_figures", "facegraph_verdicts"]
    return [f for r in rules_run for f in job_benchmarks(r)]
# ---- end facegraph input functions ----


# ---- meshdetail input functions ----
def md_frames(wildcards):
    """The frames of a mesh sequence: its folder (or the synthetic character's main clip)."""
    return MD_FRAMES[wildcards.mdseq]


def md_edit_dirs(wildcards):
    """The synthetic character's edited clips (none for real meshes)."""
    if MD_SEQS[wildcards.mdseq]["mesh_dir"]:
        return []
    return [R(f"meshdetail/character/edit_{e}") for e in config["meshdetail"]["character"]["edits"]]


def md_checked(wildcards):
    """The checksum table of a real sequence with a SHA-256 list (none otherwise)."""
    return MESH_CHECK.get(wildcards.mdseq, [])


def md_fps(wildcards):
    return MD_SEQS[wildcards.mdseq]["mesh_fps"]


def md_rig(wildcards):
    """The sequence's rig block (meshdetail.rig with its own embedding)."""
    return MD_SEQS[wildcards.mdseq]["rig"]


def md_render_frames(wildcards):
    return MD_SEQS[wildcards.mdseq]["render_frames"]


def md_name(wildcards):
    return wildcards.mdseq


def md_data_source(wildcards):
    """What the job's sequence is, for its tables (params)."""
    return md_source(wildcards.mdseq)


def md_truth(wildcards):
    """The synthetic character's ground truth (none for real meshes)."""
    return [] if MD_SEQS[wildcards.mdseq]["mesh_dir"] else [R("meshdetail/character/truth.npz")]


def md_source(name):
    """What a mesh sequence is, for tables and captions."""
    d = MD_SEQS[name]["mesh_dir"]
    return f"mesh sequence {name} ({d})" if d else "synthetic skirt character generated by the workflow"


# Benchmark files of the hybrid mesh family's jobs (inputs of rule_benchmarks): one per rule and sequence.
def meshdetail_benchmarks():
    synthetic = [n for n in MD_NAMES if not MD_SEQS[n]["mesh_dir"]]
    per_seq = ["meshdetail_load", "meshdetail_rig", "meshdetail_main", "meshdetail_resolution",
               "meshdetail_representations", "meshdetail_dembones", "meshdetail_figures", "meshdetail_verdicts"]
    files = job_benchmarks("meshdetail_character") if synthetic else []
    files += [f for r in per_seq for f in job_benchmarks(r, mdseq=MD_NAMES)]
    return files + job_benchmarks("meshdetail_compare") + mesh_data_benchmarks()


# ---- compare input functions ----
def compare_subject_trial_ids(wildcards):
    """The trial ids of one subject's groups (its held-out trials and databases), in config order."""
    loo, split = CMP_BY_SUBJECT[wildcards.cmpsubj]
    return list(dict.fromkeys([t for ids in loo.values() for t in ids] + list(split.values())))


def compare_subject_trials(wildcards):
    """The parsed trials of one subject's groups (order of compare_subject_trial_ids)."""
    return [trial_npz(t) for t in compare_subject_trial_ids(wildcards)]


def compare_rows(wildcards, rows):
    """What one generator job runs, row by row (the script's params): ``[name, config, roles, output prefix,
    showcase]``; ``rows``: ``[(name, budget or None, prefix)]``. A budget's rows use the sweep's config (job_cfg) and
    the config's joint_roles; the rows at the default budget have their showcase (each trial's roles are stored on
    its skeleton)."""
    from animsynth.compare.settings import job_cfg, subject_showcase

    show = subject_showcase(config, wildcards.cmpsubj, CMP_MISSING)
    return [[name, job_cfg(config, name, budget=budget), config["joint_roles"] if budget else {}, prefix,
             None if budget else show] for name, budget, prefix in rows]


def compare_rows_of(rows):
    """The ``rows`` param of a job whose rows are fixed (``[(name, budget or None, prefix)]``, compare_rows) for
    each subject: a function of the wildcards bound to these rows (a method's job written in a loop, fairmotion's)."""
    return lambda wildcards: compare_rows(wildcards, rows)


# Benchmark files of this family's jobs (inputs of rule_benchmarks).
def compare_benchmarks():
    n = len(CMP_SUBJECTS)

    def per_subject(rule_name, gens):
        pairs = [(s, g) for s in CMP_SUBJECTS for g in gens]
        return (job_benchmarks(rule_name, cmpsubj=[s for s, _g in pairs], cmpgen=[g for _s, g in pairs])
                if pairs else [])

    return (
        job_benchmarks("compare_clips", cmpsubj=CMP_SUBJECTS)
        + per_subject("compare_run", CMP_OWN_JOB)
        + [f for m in CMP_METHOD_JOBS if n for f in job_benchmarks(f"compare_run_{m}", cmpsubj=CMP_SUBJECTS)]
        + (per_subject("compare_run_graph", CMP_SWEEP_GRAPH) if CMP_SWEEP_GRAPH else [])
        + (job_benchmarks("compare_run_fairmotion", cmpsubj=CMP_SUBJECTS) if CMP_FM and n else [])
        + job_benchmarks("compare_tables")
        + job_benchmarks("compare_figures")
        + (job_benchmarks("compare_sweep") if CMP_SWEEP and CMP_GRAPHS else [])
        + (job_benchmarks("compare_long_strips") if CMP_LONG_ON else [])
    )


def run_benchmark_files(wildcards=None):
    """The benchmark file of every job of this run (the families that run, the summary and the benchmarks)."""
    family_benchmarks = {"data": data_benchmarks, **{f.name: family_part(f.name, "benchmarks") for f in FAMILIES}}
    files = [f for fam, fn in family_benchmarks.items() if FAMILY_RAN[fam] for f in fn()]
    return files + [f for r in ("claims", "scoreboard", "summary", "benchmarks") for f in job_benchmarks(r)]


def published_path(family, table):
    """Absolute path of the published table ``published.<family>.<table>`` (relative config paths are
    resolved against the workflow's directory, so --directory keeps them); None when unset."""
    from animsynth.published import resolve

    return resolve(config["published"][family][table], workflow.basedir)


def published_input(family, table):
    """Input function: the published table as a list of one path when the file exists, else [] (the
    job then runs without paper values; animsynth.published logs the WARNING). Declaring it as an input
    reruns the jobs that show it when the file changes."""

    def published_file(wildcards):
        p = published_path(family, table)
        return [str(p)] if p is not None and p.is_file() else []

    published_file.__name__ = f"published_{family}_{table}"
    return published_file


# ---- data input functions ----
def trial_spec(wildcards):
    """The config record of one trial (synthetic generation parameters)."""
    return TRIALS[wildcards.trial]


def synthetic_trial_seed(wildcards):
    return seed_for("synthetic_mocap", config["synthetic_mocap"]["seed"], wildcards.trial)


def trial_settings(wildcards):
    """Params function: the per-trial reading settings of one trial (its own over the top-level ones),
    and the user's own file (named in error messages instead of the copy under resources/)."""
    rec = TRIALS[wildcards.trial]
    own = {k: rec[k] for k in ("amc", "asf", "bvh") if k in rec}
    root = trial_source(wildcards.trial) if SOURCE != "synthetic" else None
    return {
        **{key: trial_setting(config, rec, key) for key in TRIAL_READ_KEYS},
        "source_files": {k: (f"{root.rstrip('/')}/{v}" if root else v) for k, v in own.items()},
        # only when the record sets it, so the settings (a rerun trigger) of every other trial stay as they were
        **({"first_frame": rec["first_frame"]} if rec.get("first_frame") else {}),
        **({"bvh_root": rec["bvh_root"]} if rec.get("bvh_root") else {}),
    }


def trial_field(field, required=True):
    """Params function: one field of a trial's config record (None when optional and absent)."""

    def trial_value(wildcards):
        rec = TRIALS[wildcards.trial]
        return rec[field] if required else rec.get(field)

    trial_value.__name__ = f"trial_{field}"
    return trial_value


def mesh_fetch_sums(wildcards):
    return MESH_FETCH_SUMS[wildcards.meshsrc]


def mesh_fetch_source(wildcards):
    return MESH_FETCH[wildcards.meshsrc]


def mesh_sequence_frames(wildcards):
    return MD_FRAMES[wildcards.mdseq]


def mesh_sequence_sums(wildcards):
    return MD_SEQS[wildcards.mdseq]["mesh_sha256"]


# ---- scale input functions ----
def scale_point_seed(wildcards):
    return seed_for("scale", wildcards.scfamily, wildcards.scpoint)


def scale_point_mem_mb(wildcards):
    """Memory of one cost-curve point: the re-sequencing budget from config, 3 GB for the others."""
    return SCALE["resequencing"]["mem_mb"] if wildcards.scfamily == "resequencing" else 3000


def landmark_vs_exact_seed(wildcards):
    return seed_for("scale", "landmark_vs_exact", wildcards.scn)
