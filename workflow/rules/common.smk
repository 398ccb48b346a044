# Shared wiring: the configuration checked before any job runs, and the study's Wiring, which
# answers from the step registry (synergrasp.steps.STEPS) what every rule is made of (inputs,
# outputs, log, benchmark, threads, requests, params, targets; workflow/rules/steps.smk makes
# the rules). No logic lives here.
# Snakemake's internals are used through synergrasp.snakemake_adapter alone.
import sys

from snakemake.exceptions import WorkflowError
from snakemake.logging import logger

from synergrasp import snakemake_adapter as adapter

# The adapter was written for one Snakemake release series: any other stops here, one line.
adapter.check_version()

from synergrasp.preflight import configfile_problems, group_problems, refuse, slurm_problems
from synergrasp.steps import RESULTS, rule_costs
from synergrasp.input_checks import older_results_problems
from synergrasp.wiring import RuleFiles, Wiring, report_archive

# Snakemake read the configuration files itself and kept a repeated key's last value.
refuse(configfile_problems(adapter.config_files(workflow)))

# A results folder of an older version (a table with a renamed column) is refused before any job.
refuse(older_results_problems(RESULTS))

#: The study: its scenarios (each checked when a target first needs it) and their files.
W = Wiring(config, workflow.basedir, error=WorkflowError, warn=logger.warning, stop=refuse)
OBJECTS = W.objects
SCENARIOS = W.scenarios
_ARCHIVE = report_archive(sys.argv)


# Wildcards match the configured names exactly, so Snakemake's guard against endless
# recursion may accept a configured name ending in a repeated character (obj_000...0).
adapter.accept_configured_wildcards([*W.object_names(), *W.scenario_root.values()])


wildcard_constraints:
    root=W.exactly(W.scenario_root.values()),
    object=W.exactly(W.object_names()),
    shard=r"\d+",


# Jobs of a few seconds and a few hundred MB run where Snakemake runs: submitting them
# would cost more queue time than they take (Cost.local).
adapter.run_locally(workflow, [rule for rule, cost in rule_costs().items() if cost.local])


onstart:
    # A cluster profile on a machine or shell that cannot submit, or whose group jobs would
    # ask for more than a node has: one line, before any job.
    _slurm = adapter.slurm_settings(workflow)
    if _slurm is not None:
        _problems = slurm_problems(*_slurm) + group_problems(
            *adapter.group_limits(workflow), W.memory_requests(), _slurm[1]
        )
        if _problems:
            raise WorkflowError(
                "The SLURM profile cannot run this workflow here, nothing was run: "
                + "; ".join(_problems)
            )


onsuccess:
    adapter.cancel_scheduler_timers()


onerror:
    adapter.cancel_scheduler_timers()
    adapter.outdate_failed_outputs(workflow)
