# Shared helpers: config checks beyond the schema, trial lookups, target lists.
import json

from animsynth.config import check_config, derive_seed


check_config(config)

TRIALS = {t["id"]: t for t in config["trials"]}
SUBSETS = {k: v for k, v in config["subsets"].items() if v}  # null drops a subset
RESEQ_TRIALS = dict(config["resequencing_trials"])
# Every trial any experiment uses (subsets first, in config order).
USED_TRIALS = list(dict.fromkeys([t for ids in SUBSETS.values() for t in ids] + list(RESEQ_TRIALS.values())))


wildcard_constraints:
    trial="|".join(sorted(TRIALS)) if TRIALS else "[A-Za-z0-9_-]+",
    dataset="|".join(sorted(SUBSETS)) if SUBSETS else "[a-z0-9]+",


SOURCE = config["mocap_source"]
# Where real trials come from: the CMU site or a mirror, or the user's folder.
MOCAP_MIRROR = config["cmu_mirror"] if SOURCE == "cmu" else config.get("data_dir")
BVH_TRIALS = {t for t, rec in TRIALS.items() if "bvh" in rec and "amc" not in rec}


def raw_trial_files(wildcards):
    """Raw files of one trial: ASF + AMC, or BVH."""
    if wildcards.trial in BVH_TRIALS:
        return {"bvh": f"resources/mocap/{wildcards.trial}.bvh"}
    return {
        "amc": f"resources/mocap/{wildcards.trial}.amc",
        "asf": f"resources/mocap/{wildcards.trial}.asf",
    }


def seed_for(*names):
    """Seed for one random choice, derived from config['seed'] and a name path."""
    return derive_seed(config["seed"], *names)


def trial_npz(trial):
    return f"results/data/trials/{trial}.npz"


def subset_npz(wildcards):
    return [trial_npz(t) for t in SUBSETS[wildcards.dataset]]


def all_targets():
    return (
        DATA_TARGETS
        + SIMPLICIAL_TARGETS
        + RESEQUENCING_TARGETS
        + FACEGRAPH_TARGETS
        + MESHDETAIL_TARGETS
        + REPORT_TARGETS
    )
