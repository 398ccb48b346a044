"""The dynamic closure against a reference on the closure benchmark's poses: per pose the
status and the full synergy set's force-closure verdict, and the CPU per grasp.

    .venv/bin/python tools/closure_agreement.py run OUT.csv [N] [--set KEY=VALUE ...] [--shift-um D] [--engine NAME=VALUE ...]
    .venv/bin/python tools/closure_agreement.py compare REF.csv OTHER.csv ...
    .venv/bin/python tools/closure_agreement.py distribution OTHER.csv COPY.csv COPY.csv ... [--z Z]

``run`` closes the hand with the dynamic model (the configuration's defaults, the approach
placement, as ``benchmarks/bench_closure.py``) at N poses per study box (default 60, the
benchmark's), drops the contacts below the load threshold (the contacts step), optimises
each grasp with all synergies and writes one row per pose: object, pose, status,
n_contacts, force_closure (rank(G) = 6 and the strict internal-force test, the study's
verdict), cpu_ms (the closure alone, ``time.process_time``), steps. ``--set`` overrides a
configuration key (dotted path, YAML value), e.g. ``closure.dynamic.solver_iterations=49``;
``--shift-um D`` moves every placed box by D µm along the palm's x axis: the reference's own
reproducibility under a change far below any tolerance; ``--engine NAME=VALUE`` sets a
pybullet engine parameter (``setPhysicsEngineParameter``, e.g. ``solverResidualThreshold=1e-4``)
on the model's client after the model's own settings: engine variants that are no config key.

``compare`` prints one markdown row per OTHER: median ms per grasp, % of poses with the
same status as REF, % with the same verdict, and the counts of grasps and verdicts.

``distribution`` judges OTHER by the counts the reference's own copies reach (the closure of a
free box is chaotic: the reference with its box moved by a few µm agrees with itself on only
91–95 % of the statuses, so pose-by-pose agreement cannot exceed that): per object, OTHER's
number of ``grasp`` statuses and of force-closure verdicts against the range the COPY tables
span (e.g. the reference and its copies with the box moved by −1, 1, 2, 5 µm), widened on
each side by Z (default 1) binomial standard errors; prints one row per object and count.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import yaml  # noqa: E402

from synergrasp.analysis.verdicts import verdict_columns  # noqa: E402
from synergrasp.config import defaults, overlay, validate_config  # noqa: E402
from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.optimisation.problem import SynergySets  # noqa: E402
from synergrasp.optimisation.optimise import OptimiseParams, gfo_table  # noqa: E402
from synergrasp.simulation.closure import SimulateParams, closure_model, place_object  # noqa: E402
from synergrasp.simulation.contacts import ContactsParams, contacts_row, contacts_table, load_carrying_contacts  # noqa: E402
from synergrasp.simulation.placement import pose_grid  # noqa: E402
from synergrasp.simulation.scene import HandScene  # noqa: E402


def study(changes: list[str]) -> dict:
    """The benchmark's configuration (dynamic model, approach placement) with ``KEY=VALUE`` changes."""
    over: dict = {"closure": {"model": "dynamic"}, "placement": {"mode": "approach"}}
    for change in changes:
        key, _, value = change.partition("=")
        node = over
        *parents, leaf = key.split(".")
        for part in parents:
            node = node.setdefault(part, {})
        node[leaf] = yaml.safe_load(value)
    return validate_config(overlay(defaults(), over))


def run(out: str, n_poses: int, changes: list[str], shift_um: float, engine: dict | None = None) -> pd.DataFrame:
    config = study(changes)
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    full = SynergySets(synergies.matrix, (tuple(range(1, synergies.matrix.shape[1] + 1)),))
    placer = HandScene(hand)
    parts = []
    for name in config["objects"]:
        sim = SimulateParams.from_config(config, name)
        grid = pose_grid(sim.placement)
        closer = closure_model(hand, sim.synergies(hand.joint_names), sim.closure, sim.mechanics, sim.object.weight_N)
        if engine:
            import pybullet

            pybullet.setPhysicsEngineParameter(physicsClientId=closer.client, **engine)
        rows, cpu, steps = [], [], []
        try:
            for pose in np.linspace(0, grid.n_poses - 1, n_poses).round().astype(int):
                angles = grid.angles_deg(int(pose))
                placed = place_object(placer, closer.q_open, sim.placement, sim.object.shape, *angles)
                placed = dataclasses.replace(placed, center_mm=placed.center_mm + [1e-3 * shift_um, 0.0, 0.0])
                start = time.process_time()
                result = closer.grasp(placed)
                cpu.append(1e3 * (time.process_time() - start))
                steps.append(getattr(closer, "steps", 0))
                rows.append(contacts_row(name, int(pose), *angles, result, placed))
        finally:
            closer.close()
        contacts = load_carrying_contacts(contacts_table(rows), ContactsParams.from_config(config, name).load_threshold_N)
        verdict = verdict_columns(gfo_table(contacts, full, OptimiseParams.from_config(config, name).gfo))
        parts.append(
            pd.DataFrame(
                {
                    "object": name,
                    "pose": contacts["pose"],
                    "status": contacts["status"],
                    "n_contacts": contacts["n_contacts"],
                    "force_closure": verdict["force_closure"].values,
                    "cpu_ms": cpu,
                    "steps": steps,
                }
            )
        )
    placer.close()
    table = pd.concat(parts, ignore_index=True)
    table.to_csv(out, index=False)
    return table


def compare(reference: str, others: list[str]) -> None:
    ref = pd.read_csv(reference)
    print("| table | ms per grasp (median) | same status | same verdict | grasps | force closure |")
    print("|---|---|---|---|---|---|")
    for path in others:
        other = pd.read_csv(path)
        if not (other[["object", "pose"]].values == ref[["object", "pose"]].values).all():
            raise SystemExit(f"{path}: not the poses of {reference}")
        same = 100 * (other["status"] == ref["status"]).mean()
        verdict = 100 * (other["force_closure"] == ref["force_closure"]).mean()
        print(
            f"| {path} | {other['cpu_ms'].median():.1f} | {same:.1f} % | {verdict:.1f} % | "
            f"{(other['status'] == 'grasp').sum()} of {len(other)} | {other['force_closure'].sum()} |"
        )


def distribution_agreement(other: pd.DataFrame, copies: list[pd.DataFrame], z: float = 1.0) -> pd.DataFrame:
    """Per object and count (``grasps``: status ``grasp``; ``force_closure``: the verdict), OTHER's
    count, the least and greatest count of the COPIES, the band and whether OTHER lies in it.

    The band is [lo − z·se(lo), hi + z·se(hi)] with se(k) = √(n·p(1 − p)) the binomial
    standard error of a count k of n poses at p = (k + ½)/(n + 1) (so a count of 0 or n has a
    band too); ``agrees`` is true if OTHER's count lies inside it.
    """
    if not copies:
        raise ValueError("distribution_agreement needs at least one copy of the reference")

    def counts(table: pd.DataFrame) -> pd.DataFrame:
        grouped = table.assign(grasps=table["status"] == "grasp").groupby("object", sort=True)
        return pd.DataFrame(
            {"n": grouped.size(), "grasps": grouped["grasps"].sum(), "force_closure": grouped["force_closure"].sum()}
        )

    mine, theirs = counts(other), [counts(c) for c in copies]
    rows = []
    for name in mine.index:
        n = int(mine.at[name, "n"])
        for column in ("grasps", "force_closure"):
            values = [int(c.at[name, column]) for c in theirs]
            lo, hi = min(values), max(values)
            se = [math.sqrt(n * p * (1 - p)) for p in ((lo + 0.5) / (n + 1), (hi + 0.5) / (n + 1))]
            low, high = lo - z * se[0], hi + z * se[1]
            count = int(mine.at[name, column])
            rows.append(
                {
                    "object": name,
                    "count": column,
                    "n": n,
                    "value": count,
                    "copies_min": lo,
                    "copies_max": hi,
                    "band_low": low,
                    "band_high": high,
                    "agrees": bool(low <= count <= high),
                }
            )
    return pd.DataFrame(rows)


def distribution(other: str, copies: list[str], z: float) -> None:
    table = distribution_agreement(pd.read_csv(other), [pd.read_csv(path) for path in copies], z)
    print(f"{other} against {len(copies)} copies, band ± {z:g} se: agrees in distribution: {bool(table['agrees'].all())}")
    print("| object | count | of | value | copies | band | agrees |")
    print("|---|---|---|---|---|---|---|")
    for row in table.itertuples():
        print(
            f"| {row.object} | {row.count} | {row.n} | {row.value} | {row.copies_min}–{row.copies_max} | "
            f"{row.band_low:.1f}–{row.band_high:.1f} | {'yes' if row.agrees else 'no'} |"
        )


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["compare"]:
        compare(args[1], args[2:])
    elif args[:1] == ["distribution"] and len(args) > 2:
        z = float(args[args.index("--z") + 1]) if "--z" in args else 1.0
        paths = [a for i, a in enumerate(args[1:], 1) if a != "--z" and args[i - 1] != "--z"]
        distribution(paths[0], paths[1:], z)
    elif args[:1] == ["run"]:
        sets = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
        shift = float(args[args.index("--shift-um") + 1]) if "--shift-um" in args else 0.0
        pairs = (args[i + 1].partition("=") for i, a in enumerate(args) if a == "--engine")
        engine = {k: int(v) if v.lstrip("-").isdigit() else float(v) for k, _, v in pairs}
        options = ("--set", "--shift-um", "--engine")
        rest = [a for i, a in enumerate(args[2:], 2) if not a.startswith("--") and args[i - 1] not in options]
        run(args[1], int(rest[0]) if rest else 60, sets, shift, engine)
    else:
        raise SystemExit(__doc__)
