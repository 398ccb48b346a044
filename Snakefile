# synergrasp: incrementality and hierarchy of postural synergies in grasp-force planning.
#   snakemake -j2 figures            every table and figure of the study
#   snakemake -j2 object_obj4        one object's own outputs (contacts, forces, minima, Fig. 4)
#   snakemake -j2 scenario_<name>    one scenario of `scenarios:` (config/README.md); `scenarios`: all
#   snakemake -j2 sensitivity        the summary across every scenario, and what it reads (docs/sensitivity.md)
#   snakemake -j2 placement_claims   the claims at every target of the placement search (~15 min)
#   snakemake -j2 plans              the incremental planner on every object (docs/planner.md)
#   snakemake -j2 across_objects     the study across its objects, with the planner (docs/random_objects.md)
#   snakemake --report results/report.html   (or results/report.zip)
from snakemake.utils import min_version

min_version("9.0")


# The study's configuration. `--configfile my.yaml` is an overlay on it (config/README.md:
# mappings merge key by key, other values replace, null removes a key).
configfile: f"{workflow.basedir}/config/config.yaml"
# The default sensitivity sweep (docs/sensitivity.md): scenarios only, one factor at a time.
configfile: f"{workflow.basedir}/config/sensitivity.yaml"


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/steps.smk"


rule all:
    default_target: True
    input:
        W.scenario_targets(),


rule figures:
    input:
        W.scenario_targets(),


# One target per object: `snakemake -j2 object_obj4` (re)makes obj4's outputs only.
for _name in OBJECTS:

    rule:
        name:
            f"object_{_name}"
        input:
            W.object_targets(_name),


# One target per scenario (config/README.md): `snakemake -j2 scenario_<name>`; `scenarios`
# builds them all. scenario_default is the same study as `figures`. A scenario's configuration
# is read and checked only when one of these targets asks for it.
for _scenario in SCENARIOS:

    rule:
        name:
            f"scenario_{_scenario}"
        input:
            lambda wildcards, name=_scenario: W.scenario_targets(name),


rule scenarios:
    input:
        lambda wildcards: [f for name in SCENARIOS for f in W.scenario_targets(name)],


# The study's claims at every target the placement search scored (docs/placement_search.md).
rule placement_claims:
    input:
        lambda wildcards: W.searched_targets("summarise_target_claims", "placement_claims"),


# The incremental planner against the exhaustive search, every object (docs/planner.md).
rule plans:
    input:
        W.optional_object_targets("plan"),


# The study across its objects with the planner (docs/random_objects.md), and what it reads.
rule across_objects:
    input:
        W.optional_targets("objects_summary"),


# A failed job keeps the outputs of the run before (synergrasp.snakemake_adapter).
adapter.keep_outputs_until_replaced(workflow)
