# Shared helpers: config checks beyond the schema, trial lookups, target lists.
import json

from animsynth.config import check_config, derive_seed


check_config(config)

TRIALS = {t["id"]: t for t in config["trials"]}
SUBSETS = {k: v for k, v in config["subsets"].items()}
RESEQ_TRIALS = dict(config["resequencing_trials"])
# Every trial any experiment uses (subsets first, in config order).
USED_TRIALS = list(dict.fromkeys([t for ids in SUBSETS.values() for t in ids] + list(RESEQ_TRIALS.values())))


wildcard_constraints:
    trial="|".join(sorted(TRIALS)) if TRIALS else "[A-Za-z0-9_-]+",
    dataset="|".join(sorted(SUBSETS)) if SUBSETS else "[a-z0-9]+",


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
