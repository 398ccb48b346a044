# synergrasp: incrementality and hierarchy of postural synergies in grasp-force planning.
#   snakemake -j2 figures            every table and figure of the study
#   snakemake -j2 object_obj4        one object's own outputs (contacts, forces, minima, Fig. 4)
#   snakemake --report results/report.html   (or results/report.zip)
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/resources.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/optimise.smk"
include: "workflow/rules/analyse.smk"
include: "workflow/rules/figures.smk"


rule all:
    default_target: True
    input:
        study_targets(),


rule figures:
    input:
        study_targets(),


# One target per object: `snakemake -j2 object_obj4` (re)makes obj4's outputs only.
for _name in OBJECTS:

    rule:
        name:
            f"object_{_name}"
        input:
            object_targets(_name),
