# animsynth: reproduce four data-driven character-animation methods.
# Run:  snakemake --cores 2            (embedded synthetic default, offline)
#       snakemake --cores 2 --configfile config/cmu.yaml --config cmu_mirror=../shared/data/cmu_mocap
import os
import sys

from snakemake.utils import min_version

min_version("9.0")

# The animsynth library lives in src/: make it importable here and in every
# job (also inside a conda env built from workflow/envs/animsynth.yaml).
SRC = os.path.join(workflow.basedir, "src")
sys.path.insert(0, SRC)
os.environ.update(PYTHONPATH=os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH")) if p))


configfile: "config/config.yaml"


# A wrong type or unknown key stops the run with a few lines: the key, where
# it is, and the closest valid key (plus defaults filled in from the schema).
from animsynth.config import validate_config

validate_config(config, os.path.join(workflow.basedir, "config", "schema.yaml"))


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/simplicial.smk"
include: "workflow/rules/resequencing.smk"
include: "workflow/rules/facegraph.smk"
include: "workflow/rules/meshdetail.smk"
include: "workflow/rules/report.smk"


# The target rule runs nothing: it is local, so it needs no threads/resources.
rule all:
    input:
        all_targets(),
    default_target: True
    localrule: True
