"""What a study of many random objects asks of a SLURM cluster through profiles/slurm: the sbatch
jobs with and without the profile's groups, what one group job asks for (CPUs, memory, time
limit) as Snakemake lays its jobs within the profile's node size (``snakemake_adapter.group_request``),
the node-hours those requests reserve, and the CPU the submitted jobs use by the measured
per-object costs (benchmarks/results/random_objects.csv: search 26.0, closure 9.5, the
optimisation's shard 3.8 and the mesh's parts about 2 CPU s an object). Nothing is run: the
requests are the step registry's (``synergrasp.wiring``) under config/examples/random_objects.yaml.

    .venv/bin/python benchmarks/bench_cluster_groups.py [N_STUDIED] [CORES MEM_MB]

N_STUDIED: objects studied (default 977, of 1,000 drawn: benchmarks/bench_dry_run.py); CORES and
MEM_MB: the node size (default the profile's ``cores`` and ``resources: mem_mb``).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import yaml

from synergrasp.config import defaults, overlay
from synergrasp.snakemake_adapter import group_request
from synergrasp.steps import rule_costs
from synergrasp.wiring import mem_mb, runtime_min

ROOT = Path(__file__).resolve().parents[1]
#: CPU s an object of the submitted rules measured on the hundred random objects (random_objects.csv).
MEASURED_CPU_S = {"mesh_parts": 2.0, "search": 26.0, "simulate": 9.5, "optimise_shard": 3.8}


def profile() -> tuple[list[str], int, int, int]:
    """profiles/slurm's grouped rules (in the order their jobs depend on each other), objects a
    group job, cores and mem_mb."""
    settings = yaml.safe_load((ROOT / "profiles" / "slurm" / "config.yaml").read_text())
    rules = [entry.split("=")[0] for entry in settings["groups"]]
    (components,) = [int(entry.split("=")[1]) for entry in settings["group-components"]]
    return rules, components, int(settings["cores"]), int(settings["resources"]["mem_mb"])


def main(argv: list[str]) -> None:
    n = int(argv[0]) if argv else 977
    rules, per_job, cores, node_mb = profile()
    if len(argv) >= 3:
        cores, node_mb = int(argv[1]), int(argv[2])
    example = yaml.safe_load((ROOT / "config" / "examples" / "random_objects.yaml").read_text())
    cfg = overlay(defaults(), {key: value for key, value in example.items() if key != "objects"})
    cfg["objects"] = {f"rand_{k:04d}": {} for k in range(n)}  # the study-wide jobs' size
    shards = cfg["solver"]["pose_shards"]
    job = {r: {"threads": rule_costs()[r].threads, "mem_mb": mem_mb(r, cfg), "runtime": runtime_min(r, cfg)} for r in rules}
    jobs_per_object = {r: shards if r == "optimise_shard" else 1 for r in rules}

    groups = math.ceil(n / per_job)
    full = group_request([[job[r]] * (per_job * jobs_per_object[r]) for r in rules], cores, node_mb)
    rest = n - (groups - 1) * per_job
    last = group_request([[job[r]] * (rest * jobs_per_object[r]) for r in rules], cores, node_mb)
    unlimited = group_request([[job[r]] * (per_job * jobs_per_object[r]) for r in rules], None, None)
    reserved_h = ((groups - 1) * full["runtime"] + last["runtime"]) / 60.0
    cpu_h = n * sum(MEASURED_CPU_S[r] for r in rules) / 3600.0
    group_cpu_s = per_job * sum(MEASURED_CPU_S[r] for r in rules)
    local = {r: mem_mb(r, cfg) for r in ("tables", "realism")}

    print(f"objects: {n}  (studied; the profile puts {per_job} objects in a group job)")
    print(f"node_cores: {cores}  (CPUs a group job is laid within: the profile's cores)")
    print(f"node_mem_mb: {node_mb}  (MB a group job is laid within: the profile's resources mem_mb)")
    print(f"sbatch_jobs_grouped: {groups}  ({n} objects, {per_job} a job)")
    print(f"sbatch_jobs_ungrouped: {n * sum(jobs_per_object.values())}  ({n} x {', '.join(rules)})")
    for r in rules:
        print(f"request_{r}_mem_mb: {job[r]['mem_mb']}  (one job: {job[r]['threads']} threads, {job[r]['runtime']} min)")
    print(f"group_cpus: {full['threads']}  (CPUs a group job of {per_job} objects asks for)")
    print(f"group_mem_mb: {full['mem_mb']}  (its memory, MB: the largest layer of jobs side by side)")
    print(f"group_runtime_min: {full['runtime']}  (its time limit, min: its layers one after another)")
    print(f"group_cpus_unlimited: {unlimited['threads']}  (CPUs the same group asks for without the node size)")
    print(f"group_mem_mb_unlimited: {unlimited['mem_mb']}  (its memory without the node size, MB)")
    print(f"node_hours_reserved: {reserved_h:.1f}  (the group jobs' time limits, each holding {cores} CPUs)")
    print(f"group_cpu_s_measured: {group_cpu_s:.0f}  (CPU s a group job of {per_job} objects uses, measured costs)")
    print(f"group_wall_min_measured: {group_cpu_s / cores / 60.0:.1f}  (the same on {cores} CPUs kept busy, min)")
    print(f"submitted_core_hours_measured: {cpu_h:.1f}  (CPU of every submitted job, measured costs)")
    for r, request in local.items():
        print(f"local_{r}_mem_mb: {request}  (the study-wide {r} job's request where Snakemake runs, MB)")


if __name__ == "__main__":
    main(sys.argv[1:])
