# Threads, memory and run time of every job, computed from the job's size and a measured
# cost per unit of work, so that the requests follow the config (grid, objects, synergy
# sets, shards, closure model) instead of going stale. docs/cluster.md gives the method.
import math

from synergrasp.config import grid_axis_deg, synergy_sets

# Measured cost of one job: fixed wall time (s) and memory (MB) of the job itself (imports,
# reading inputs), plus wall time and memory per unit of work. From results/benchmarks/*.tsv
# (columns s, cpu_time and max_rss) of the default study and of tests/config/small.yaml on a
# 2-core x86_64 machine running two jobs at a time; the slope is between the two sizes. The
# closure's cost per pose is CPU time per pose of the closure to the end of S1 (docs/cluster.md).
#   unit = pose (closure, contact selection), pose x synergy set (optimisation, minima, Fig. 4, tables), none (figures)
JOB_COST = {
    "simulate_contacts": {
        "fixed_s": 1.5,
        "unit_s": 4.5e-2,
        "fixed_mb": 178,
        "unit_mb": 7.6e-3,
    },
    "select_contacts": {
        "fixed_s": 1.0,
        "unit_s": 5.0e-4,
        "fixed_mb": 150,
        "unit_mb": 7.6e-3,
    },
    "optimise_shard": {
        "fixed_s": 2.2,
        "unit_s": 6.1e-5,
        "fixed_mb": 271,
        "unit_mb": 1.1e-3,
    },
    "aggregate_gfo": {
        "fixed_s": 0.6,
        "unit_s": 2.0e-6,
        "fixed_mb": 134,
        "unit_mb": 6.0e-4,
    },
    "local_minima": {
        "fixed_s": 0.6,
        "unit_s": 1.35e-5,
        "fixed_mb": 136,
        "unit_mb": 6.0e-4,
    },
    "fig4_force_maps": {
        "fixed_s": 4.3,
        "unit_s": 5.1e-6,
        "fixed_mb": 257,
        "unit_mb": 4.0e-4,
    },
    "study_tables": {
        "fixed_s": 2.3,
        "unit_s": 3.2e-6,
        "fixed_mb": 231,
        "unit_mb": 2.2e-4,
    },
    "sensitivity_summary": {
        "fixed_s": 5.0,
        "unit_s": 0.0,
        "fixed_mb": 300,
        "unit_mb": 0.0,
    },
    "grasp_realism": {
        "fixed_s": 4.0,
        "unit_s": 1.1e-5,  # with the equilibrium checks: ~0.5 ms per grasp over 75 sets
        "fixed_mb": 300,
        "unit_mb": 3.0e-4,
    },
    "fig1_synergy_postures": {
        "fixed_s": 3.0,
        "unit_s": 0.0,
        "fixed_mb": 565,
        "unit_mb": 0.0,
    },
    "fig2_example_grasps": {
        "fixed_s": 2.3,
        "unit_s": 0.0,
        "fixed_mb": 311,
        "unit_mb": 0.0,
    },
    "fig3_rulegraph": {"fixed_s": 5.3, "unit_s": 0.0, "fixed_mb": 380, "unit_mb": 0.0},
    "fig5_hierarchy": {"fixed_s": 9.6, "unit_s": 0.0, "fixed_mb": 268, "unit_mb": 0.0},
}
# Closure cost per pose relative to the kinematic closure measured above, per closure model;
# a model not listed is charged CLOSURE_UNMEASURED_FACTOR until its cost is measured.
CLOSURE_COST_FACTOR = {"kinematic": 1.0, "dynamic": 1.8}
CLOSURE_UNMEASURED_FACTOR = 20.0
# A cold compiled-solver cache (a node whose CPU model has no cached build) compiles the
# solver once in the job: about 50 s and 150 MB on the measuring machine.
SOLVER_COMPILE_S, SOLVER_COMPILE_MB = 60.0, 150
# Requests are the measured cost times a margin (slower nodes, shared file systems),
# rounded up to whole minutes and to 100 MB.
RUNTIME_MARGIN, MEMORY_MARGIN = 3.0, 1.5


def job_size(step, cfg):
    """Units of work of one job of rule ``step`` under the scenario configuration ``cfg``
    (see JOB_COST): the closure's cost follows the scenario's grid and closure model, the
    optimisation's its grid, synergy sets and shards."""
    n_poses = len(grid_axis_deg(cfg["grid"]["alpha_deg"])) * len(
        grid_axis_deg(cfg["grid"]["beta_deg"])
    )
    n_sets = len(synergy_sets(cfg["synergy_sets"]))
    factor = CLOSURE_COST_FACTOR.get(cfg["closure"]["model"], CLOSURE_UNMEASURED_FACTOR)
    return {
        "simulate_contacts": n_poses * factor,
        "select_contacts": n_poses,
        "optimise_shard": math.ceil(n_poses / cfg["solver"]["pose_shards"]) * n_sets,
        "aggregate_gfo": n_poses * n_sets,
        "local_minima": n_poses * n_sets,
        "fig4_force_maps": n_poses * n_sets,
        "study_tables": len(cfg["objects"]) * n_poses * n_sets,
        "grasp_realism": len(cfg["objects"]) * n_poses * n_sets,
    }.get(step, 0)


def _job_config(wildcards):
    """The configuration of the job's scenario (the default for the jobs outside any root)."""
    return scenario_config(wildcards) if "root" in wildcards.keys() else STUDY


def runtime_min(step):
    """Wall-time request of one job of rule ``step`` in its scenario, in whole minutes (at least 1)."""

    def request(wildcards):
        cost = JOB_COST[step]
        seconds = cost["fixed_s"] + cost["unit_s"] * job_size(step, _job_config(wildcards))
        if step == "optimise_shard":
            seconds += SOLVER_COMPILE_S
        return max(1, math.ceil(RUNTIME_MARGIN * seconds / 60.0))

    return request


def mem_mb(step):
    """Memory request of one job of rule ``step`` in its scenario, in MB rounded up to 100 MB."""

    def request(wildcards):
        cost = JOB_COST[step]
        mb = cost["fixed_mb"] + cost["unit_mb"] * job_size(step, _job_config(wildcards))
        if step == "optimise_shard":
            mb += SOLVER_COMPILE_MB
        return 100 * math.ceil(MEMORY_MARGIN * mb / 100.0)

    return request


# Jobs of a few seconds and a few hundred MB for the default study run where Snakemake runs:
# submitting them would cost more queue time than they take.
localrules:
    select_contacts,
    aggregate_gfo,
    sensitivity_summary,
    local_minima,
    study_tables,
    grasp_realism,
    fig1_synergy_postures,
    fig2_example_grasps,
    fig3_rulegraph,
    fig4_force_maps,
    fig5_hierarchy,
