# animsynth: reproduce four data-driven character-animation methods.
# Run:  snakemake --cores 2            (embedded synthetic default, offline)
#       snakemake --cores 2 --configfile config/cmu.yaml --config cmu_mirror=../shared/data/cmu_mocap
import os
import sys

from snakemake.utils import min_version, validate

min_version("9.0")

# The animsynth library lives in src/: make it importable here and in every
# job (also inside a conda env built from workflow/envs/animsynth.yaml).
SRC = os.path.join(workflow.basedir, "src")
sys.path.insert(0, SRC)
os.environ.update(PYTHONPATH=os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH")) if p))


configfile: "config/config.yaml"


validate(config, "config/schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/simplicial.smk"
include: "workflow/rules/resequencing.smk"
include: "workflow/rules/facegraph.smk"
include: "workflow/rules/meshdetail.smk"
include: "workflow/rules/report.smk"


# Scale study (config/scale.yaml): opt-in; when enabled the run builds only its outputs.
SCALE_ON = bool(config.get("scale", {}).get("enabled", False))
if SCALE_ON:

    include: "workflow/rules/scale.smk"


rule all:
    input:
        SCALE_TARGETS if SCALE_ON else all_targets(),
    default_target: True
