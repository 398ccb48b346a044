"""Benchmark of one random mesh object through the per-object steps (docs/random_objects.md):
the placement search (one process), the closure at every pose of the grid at the searched
target, the optimisation of every (pose, set) and the planner, each in this one process, as
the workflow's jobs run them; prints the CPU time of each (`time.process_time`, one core,
compiled code loaded before) and a digest of each step's table, so that two versions of the
code can be compared on the same object (the same digests: the same results). The objects are
those `config/examples/random_objects.yaml` draws with `n_objects: 3` (seed 2018): rand_139
(the default), rand_305, rand_486. The lines `object_<step>_cpu_s_<object>: N` are machine-read.

    .venv/bin/python benchmarks/bench_object.py [rand_139 ...]
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from synergrasp import table_contracts  # noqa: E402
from synergrasp.analysis.periods import alpha_period_deg  # noqa: E402
from synergrasp.analysis.plan_study import PlanParams, plan_object  # noqa: E402
from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.input_checks import checked_scenario, read_overlays  # noqa: E402
from synergrasp.optimisation.gfo import warm_up  # noqa: E402
from synergrasp.optimisation.optimise import OptimiseParams, optimise_shard  # noqa: E402
from synergrasp.optimisation.placement_search import SearchStepParams, full_synergy_set, search_object  # noqa: E402
from synergrasp.optimisation.problem import SynergySets  # noqa: E402
from synergrasp.simulation import closure  # noqa: E402
from synergrasp.simulation.placement import searched_placement  # noqa: E402
from synergrasp.simulation.random_objects import add_random_objects  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: What the steps are called in the machine-read lines, in the order they run.
STEPS = ("search", "closure", "optimise", "plan")


def study_config() -> dict:
    """The example's configuration with three objects drawn (the workflow's own checks)."""
    config = read_overlays([ROOT / "config" / "config.yaml", ROOT / "config" / "examples" / "random_objects.yaml"])
    config["random_objects"]["n_objects"] = 3
    add_random_objects(config, ROOT)
    return checked_scenario(config, "default")[0]


def digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def run_object(cfg: dict, name: str, folder: Path) -> dict[str, tuple[float, str]]:
    """Each step of one object: (CPU s, digest of its table), tables passed on through files."""
    out: dict[str, tuple[float, str]] = {}
    clock = time.process_time()
    sim = SearchStepParams.from_config(cfg, name)
    hand = load_hand(sim.hand)
    synergies = load_synergies(sim.synergies, joint_names=hand.joint_names)
    period = alpha_period_deg(sim.placement, sim.object.shape, hand.palm_normal)
    result = search_object(
        hand,
        synergies,
        sim.object,
        sim.placement,
        sim.closure,
        sim.gfo,
        full_synergy_set(synergies.matrix, sim.full_set_size),
        sim.search,
        period,
        processes=1,
        opposition=sim.opposition,
    )
    table_contracts.write_csv(table_contracts.PLACEMENT, result.table(sim.distinct_mm), folder / "placement.csv")
    out["search"] = (time.process_time() - clock, digest((folder / "placement.csv").read_text()))

    clock = time.process_time()
    params = closure.SimulateParams.from_config(cfg, name)
    placement = params.placement
    if placement.mode == "searched":
        placement = searched_placement(placement, table_contracts.read_csv(table_contracts.PLACEMENT, folder / "placement.csv"))
    contacts = closure.simulate_object(
        hand, params.synergies(hand.joint_names), params.object, placement, params.closure, mechanics=params.mechanics
    )
    table_contracts.write(table_contracts.CONTACTS, contacts, folder / "contacts.parquet")
    out["closure"] = (time.process_time() - clock, digest(contacts.to_json()))

    clock = time.process_time()
    opt = OptimiseParams.from_config(cfg, name)
    sets = SynergySets(synergies.matrix, tuple(opt.sets.values()))
    gfo = optimise_shard(table_contracts.read(table_contracts.CONTACTS, folder / "contacts.parquet"), 0, 1, sets, opt.gfo)
    table_contracts.write(table_contracts.GFO, gfo, folder / "gfo.parquet")
    out["optimise"] = (time.process_time() - clock, digest(gfo.to_json()))

    clock = time.process_time()
    plan_params = PlanParams.from_config(cfg, name)
    plan = plan_object(
        table_contracts.read(table_contracts.CONTACTS, folder / "contacts.parquet"),
        table_contracts.read(table_contracts.GFO, folder / "gfo.parquet"),
        synergies.matrix,
        plan_params,
    )
    out["plan"] = (time.process_time() - clock, digest(plan.table.to_csv() + plan.enrollment.to_csv()))
    return out


def main(objects: list[str]) -> None:
    cfg = study_config()
    warm_up()
    closure.warm_up()
    for name in objects or ["rand_139"]:
        with tempfile.TemporaryDirectory() as folder:
            steps = run_object(cfg, name, Path(folder))
        total = sum(cpu for cpu, _ in steps.values())
        print(
            f"{name}: "
            + ", ".join(f"{step} {cpu:.1f} s (tables {tag})" for step, (cpu, tag) in steps.items())
            + f"; load average {os.getloadavg()[0]:.1f}",
            flush=True,
        )
        for step in STEPS:
            print(f"object_{step}_cpu_s_{name}: {steps[step][0]:.1f}  ({name}: CPU s of the {step} step, one process)")
        print(f"object_cpu_s_{name}: {total:.1f}  ({name}: CPU s of the four steps)", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
