# Threads, memory and run time of every job, computed from the job's size and the measured
# cost per unit of work of its rule (synergrasp.steps.STEPS), so that the requests follow the
# config (grid, objects, synergy sets, shards, closure model) instead of going stale.
# docs/cluster.md gives the method.
import math

from synergrasp.config import grid_axis_deg
from synergrasp.ids import synergy_sets
from synergrasp.steps import rule_costs

JOB_COST = rule_costs()
# Closure cost per pose relative to the kinematic closure measured in STEPS, per closure
# model (docs/cluster.md); a model not listed is charged CLOSURE_UNMEASURED_FACTOR until its
# cost is measured.
CLOSURE_COST_FACTOR = {"kinematic": 1.0, "dynamic": 9.0}
CLOSURE_UNMEASURED_FACTOR = 20.0
# A cold compiled-solver cache (a node whose CPU model has no cached build) compiles the
# solver once in the job: about 50 s and 150 MB on the measuring machine.
SOLVER_COMPILE_S, SOLVER_COMPILE_MB = 60.0, 150
# Requests are the measured cost times a margin (slower nodes, shared file systems),
# rounded up to whole minutes and to 100 MB.
RUNTIME_MARGIN, MEMORY_MARGIN = 3.0, 1.5


def job_size(rule, cfg):
    """Units of work (synergrasp.steps.UNITS) of one job of ``rule`` under the scenario
    configuration ``cfg``: the closure's cost follows the scenario's grid and closure model,
    the optimisation's its grid, synergy sets and shards."""
    n_poses = len(grid_axis_deg(cfg["grid"]["alpha_deg"])) * len(
        grid_axis_deg(cfg["grid"]["beta_deg"])
    )
    n_sets = len(synergy_sets(cfg["synergy_sets"]))
    factor = CLOSURE_COST_FACTOR.get(cfg["closure"]["model"], CLOSURE_UNMEASURED_FACTOR)
    return {
        "none": 0,
        "pose": n_poses,
        "closure_pose": n_poses * factor,
        "shard_pose_set": math.ceil(n_poses / cfg["solver"]["pose_shards"]) * n_sets,
        "pose_set": n_poses * n_sets,
        "object_pose_set": len(cfg["objects"]) * n_poses * n_sets,
    }[JOB_COST[rule].unit]


def _job_config(wildcards):
    """The configuration of the job's scenario (the default for the jobs outside any root)."""
    return scenario_config(wildcards) if "root" in wildcards.keys() else STUDY


def _compiles(rule):
    """Whether a job of ``rule`` may compile the solver (a cold cache on its node)."""
    return rule in ("optimise_shard", "search_placement")


def runtime_min(rule):
    """Wall-time request of one job of ``rule`` in its scenario, in whole minutes (at least 1)."""

    def request(wildcards):
        cost = JOB_COST[rule]
        seconds = cost.fixed_s + cost.unit_s * job_size(rule, _job_config(wildcards))
        if _compiles(rule):
            seconds += SOLVER_COMPILE_S
        return max(1, math.ceil(RUNTIME_MARGIN * seconds / 60.0))

    return request


def mem_mb(rule):
    """Memory request of one job of ``rule`` in its scenario, in MB rounded up to 100 MB."""

    def request(wildcards):
        cost = JOB_COST[rule]
        mb = cost.fixed_mb + cost.unit_mb * job_size(rule, _job_config(wildcards))
        if _compiles(rule):
            mb += SOLVER_COMPILE_MB
        return 100 * math.ceil(MEMORY_MARGIN * mb / 100.0)

    return request


# Jobs of a few seconds and a few hundred MB for the default study run where Snakemake runs:
# submitting them would cost more queue time than they take (Cost.local).
workflow.localrules(*(rule for rule, cost in JOB_COST.items() if cost.local))
