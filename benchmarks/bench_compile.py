"""First compile of the GFO kernel and of the closure's distance queries, and loading them from a new checkout path.

Child processes run `gfo.warm_up()`: the first with an empty cache directory
(`NUMBA_CACHE_DIR` set to a new temporary directory: the kernel's first compile, as on a
fresh clone), the others from a copy of the package in another directory with the same
cache (a new clone path: it must load, not compile). Then the same for the kinematic
closure of one pose of the default box (what a closure job compiles: the capsules' and the
shapes' queries). CPU seconds of each child (user + system,
`resource.getrusage(RUSAGE_CHILDREN)`), median of `--repeats` for the load. Run on one core
with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1. The last four lines are machine-read.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import synergrasp

WARM_UP = "from synergrasp.optimisation.gfo import warm_up; warm_up()"
CLOSE_ONE_POSE = """
from dataclasses import replace
from synergrasp.config import defaults
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.simulation.closure import SimulateParams, closure_model, place_object
from synergrasp.simulation.placement import pose_grid
from synergrasp.simulation.scene import HandScene
study, hand = defaults(), load_hand()
sim = SimulateParams.from_config(study, next(iter(study["objects"])))
sim = replace(sim, placement=replace(sim.placement, mode="approach"))
closer, placer = closure_model(hand, load_synergies(None, joint_names=hand.joint_names), sim.closure), HandScene(hand)
closer.grasp(place_object(placer, closer.q_open, sim.placement, sim.object.shape, *pose_grid(sim.placement).angles_deg(7)))
"""


def child_cpu(env: dict[str, str], code: str = WARM_UP) -> float:
    """CPU seconds of one child running ``code`` (the kernel's warm-up)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", code], env=env, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeats", type=int, default=5, help="loads from the new path; the median is reported")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "cache"))
        first = child_cpu(env)
        clone = Path(tmp) / "clone"
        shutil.copytree(Path(synergrasp.__file__).parent, clone / "synergrasp", ignore=shutil.ignore_patterns("__pycache__"))
        env["PYTHONPATH"] = str(clone)
        loads = [child_cpu(env) for _ in range(args.repeats)]
        cached = sorted(p.name for p in (Path(tmp) / "cache").rglob("*.nbi"))
        del env["PYTHONPATH"]
        closure_first = child_cpu(env, CLOSE_ONE_POSE)
        env["PYTHONPATH"] = str(clone)
        closure_loads = [child_cpu(env, CLOSE_ONE_POSE) for _ in range(args.repeats)]
    print(f"first compile (empty cache, one process): {first:.1f} CPU s; {len(cached)} compiled functions cached")
    print(
        f"warm-up from a copy in a new path, same cache (median of {args.repeats}): {statistics.median(loads):.2f} CPU s"
        f" (runs {min(loads):.2f}-{max(loads):.2f})"
    )
    print(
        f"closure of one pose, empty cache: {closure_first:.1f} CPU s; from a new path, same cache (median of "
        f"{args.repeats}): {statistics.median(closure_loads):.2f} CPU s (runs {min(closure_loads):.2f}-"
        f"{max(closure_loads):.2f})"
    )
    print(f"first_compile_s: {first:.1f}  (the compiled kernel's first compile with an empty cache, CPU s of one process)")
    print(
        f"new_path_load_s: {statistics.median(loads):.2f}  (the warm-up from a new checkout path with the same "
        f"cache, CPU s, median of {args.repeats})"
    )
    print(
        f"closure_first_compile_s: {closure_first - statistics.median(closure_loads):.1f}  (the closure's distance "
        f"queries' first compile: one pose closed with an empty cache less with the cache loaded, CPU s)"
    )
    print(
        f"closure_new_path_load_s: {statistics.median(closure_loads):.2f}  (one pose closed from a new checkout path "
        f"with the same cache, CPU s, median of {args.repeats})"
    )


if __name__ == "__main__":
    main()
