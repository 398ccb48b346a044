# Shared wiring: the configuration checked before any job runs, and what every rule is made
# of (outputs, log, benchmark, threads, requests, inputs, targets), all answered by
# synergrasp.wiring from the step registry (synergrasp.steps.STEPS). No logic lives here.
import sys

from snakemake.exceptions import WorkflowError
from snakemake.logging import logger

from synergrasp.preflight import accept_configured_wildcards, configfile_problems, slurm_problems
from synergrasp.preflight import keep_outputs_until_replaced, outdate_failed_outputs, refuse
from synergrasp.steps import rule_costs
from synergrasp.wiring import RuleFiles, Wiring, cancel_scheduler_timers, report_archive

# Snakemake read the configuration files itself and kept a repeated key's last value.
refuse(configfile_problems(workflow.configfiles))

# A results folder of an older version (a table with a renamed column) is refused before any job.
from synergrasp.study_checks import older_results_problems
refuse(older_results_problems("results"))

#: The study: its scenarios (each checked when a target first needs it) and their files.
W = Wiring(config, workflow.basedir, error=WorkflowError, warn=logger.warning, stop=refuse)
ROOT = W.root
OBJECTS = W.objects
SCENARIOS = W.scenarios
SHIPPED_DATA = W.shipped_data()
_ARCHIVE = report_archive(sys.argv)


def outputs(rule):
    """A rule's outputs, from the registry, with Snakemake's report/directory/temp flags."""
    return RuleFiles(rule).snakemake_outputs(report, directory, temp, _ARCHIVE)


def log_file(rule):
    return RuleFiles(rule).log()


def benchmark_file(rule):
    return RuleFiles(rule).benchmark()


def threads(rule):
    return rule_costs()[rule].threads


# Wildcards match the configured names exactly, so Snakemake's guard against endless
# recursion may accept a configured name ending in a repeated character (obj_000...0).
accept_configured_wildcards([*W.object_names(), *W.scenario_root.values()])


wildcard_constraints:
    root=W.exactly(W.scenario_root.values()),
    object=W.exactly(W.object_names()),
    shard=r"\d+",


# Jobs of a few seconds and a few hundred MB run where Snakemake runs: submitting them
# would cost more queue time than they take (Cost.local).
workflow.localrules(*(rule for rule, cost in rule_costs().items() if cost.local))


onstart:
    # A cluster profile on a machine or shell that cannot submit: one line, before any job.
    if workflow.executor_plugin.name == "slurm":
        _raw = {k: r.raw for k, r in workflow.resource_settings.default_resources.items()}
        _problems = slurm_problems(workflow.executor_settings, _raw)
        if _problems:
            raise WorkflowError(
                "The SLURM profile cannot submit from this shell, nothing was run: "
                + "; ".join(_problems)
            )


onsuccess:
    cancel_scheduler_timers()


onerror:
    cancel_scheduler_timers()
    outdate_failed_outputs(workflow)
