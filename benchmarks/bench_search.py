"""Benchmark of the placement search (docs/placement_search.md): the default study's search
(version 3: the hand's reach for the gate, then the search of each grasp type the fallback
chain reaches) of each object (or of the objects named on the command line), with 2 processes; prints the
wall time, the CPU time of the search's processes, the number of targets scored and the
machine's load average (the targets: at most 30 s wall per object on 2 quiet cores); the
lines `search_wall_s_<object>: N` and `search_cpu_s_<object>: N` are machine-read.

    .venv/bin/python benchmarks/bench_search.py [obj1 obj2 ...]
"""

from __future__ import annotations

import os
import resource
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

from synergrasp.analysis.periods import alpha_period_deg  # noqa: E402
from synergrasp.config import defaults  # noqa: E402
from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.optimisation.gfo import warm_up  # noqa: E402
from synergrasp.optimisation.grasp_type_search import search_object_types  # noqa: E402
from synergrasp.optimisation.placement_search import SearchStepParams  # noqa: E402


def _cpu_s() -> float:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def main(objects: list[str], processes: int = 2) -> None:
    study = defaults()
    warm_up()
    for name in objects or list(study["objects"]):
        sim = SearchStepParams.from_config(study, name)
        hand = load_hand(sim.hand)
        synergies = load_synergies(sim.synergies, joint_names=hand.joint_names)
        period = alpha_period_deg(sim.placement, sim.object.shape, hand.palm_normal)
        wall, cpu = time.perf_counter(), _cpu_s()
        result = search_object_types(hand, synergies, sim, period, processes)  # the gate and the chain too
        wall, cpu = time.perf_counter() - wall, _cpu_s() - cpu
        n_poses = result.chosen.n_poses
        print(
            f"{name}: {len(result.ranked)} targets x {n_poses} poses, {processes} processes: wall {wall:.1f} s, "
            f"CPU {cpu:.1f} s ({1e3 * cpu / (len(result.ranked) * n_poses):.1f} ms per grasp), "
            f"load average {os.getloadavg()[0]:.1f}; chosen {result.chosen.target_mm}",
            flush=True,
        )
        print(f"search_wall_s_{name}: {wall:.1f}  ({name}: wall s of the search, {processes} processes)")
        print(
            f"search_cpu_s_{name}: {cpu:.1f}  ({name}: CPU s of the search's processes, {len(result.ranked)} targets x "
            f"{n_poses} poses)",
            flush=True,
        )


if __name__ == "__main__":
    main(sys.argv[1:])
