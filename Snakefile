# animsynth: reproduce four data-driven character-animation methods.
# Run:  snakemake --cores 2            (embedded synthetic default, offline)
#       snakemake --cores 2 --configfile config/cmu.yaml --config cmu_mirror=../shared/data/cmu_mocap
from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "config/config.yaml"


validate(config, "config/schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/simplicial.smk"
include: "workflow/rules/resequencing.smk"
include: "workflow/rules/facegraph.smk"
include: "workflow/rules/meshdetail.smk"
include: "workflow/rules/report.smk"


rule all:
    input:
        all_targets(),
    default_target: True
