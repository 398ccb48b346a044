"""The closure models side by side on a sample of poses: contacts, equilibrium checks, timing.

    .venv/bin/python tools/closure_sample.py OUT_DIR [EVERY] [MODEL ...]
    .venv/bin/python tools/closure_sample.py --pictures OUT_DIR PNG POSE_obj1 POSE_obj2 …
    .venv/bin/python tools/closure_sample.py --summary OUT_DIR

For every object of the default configuration, closes the hand at the poses 0, EVERY,
2·EVERY, … (default 6: 300 of the 1800 poses) at the default study's placement (a searched
target is read from ``results/objects/<object>/placement.csv``: the study's search runs
first) with each MODEL (``kinematic``, ``dynamic``: a
free box, ``dynamic_held``: ``closure.dynamic.object: held``; default all three), writes the
contacts that count (the ``contacts`` step's choice) to ``OUT_DIR/<model>/<object>.parquet``
and prints the closure's CPU seconds. ``--summary``: the grasp-realism table of each model's
sample (force closure from the optimisation with the full set only), with the median residual
over all 19 joints (those moving no box contact counted as unbalanced) and the CPU seconds of
the equilibrium checks (docs/closure.md, "Is the end state an equilibrium?").
With ``--pictures``: one row per object at the given pose (of the sample), one panel per model
found under OUT_DIR, drawn as in Fig. 2, the checks in each panel's title.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp import table_contracts
from synergrasp.analysis.realism import RealismParams, realism_of
from synergrasp.config import defaults, validate_config
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium
from synergrasp.optimisation.optimise import OptimiseParams, gfo_table
from synergrasp.optimisation.problem import SynergySets
from synergrasp.simulation.closure import SimulateParams, simulate_object
from synergrasp.simulation.contacts import ContactsParams, load_carrying_contacts
from synergrasp.simulation.placement import pose_grid, searched_placement

MODELS = {"kinematic": ("kinematic", "free"), "dynamic": ("dynamic", "free"), "dynamic_held": ("dynamic", "held")}


def _all_joints(checks: pd.DataFrame) -> pd.Series:
    """The residual over all 19 joints, the joints moving no box contact counted as unbalanced:
    √(r² ‖τ_B‖² + ‖τ_other‖²) / √(‖τ_B‖² + ‖τ_other‖²) (no second solve: Jᵀ f is 0 off B)."""
    box, other = checks["torque_box_Nmm"], checks["torque_other_Nmm"]
    return ((checks["torque_residual"] * box) ** 2 + other**2) ** 0.5 / (box**2 + other**2) ** 0.5


def _searches(config: dict, results: Path) -> dict[str, Path]:
    """Each object's placement table of the default study (``results/objects/<object>/
    placement.csv``) where its placement is searched; SystemExit naming every one missing."""
    files = {
        name: results / "objects" / name / "placement.csv"
        for name in config["objects"]
        if SimulateParams.from_config(config, name).placement.mode == "searched"
    }
    missing = [str(path) for path in files.values() if not path.is_file()]
    if missing:
        raise SystemExit(
            f"closure_sample: the searched placements {missing} are not there: run the study's search first "
            f"(make study, or snakemake -j2 {' '.join(missing)})"
        )
    return files


def simulate(out: Path, every: int, models: list[str], results: Path = Path("results")) -> None:
    """Close the hand at every ``every``-th pose with each model, at the default study's
    placements (its searched targets read from ``results``); write the contacts that count
    (the ``contacts`` step's choice) and print the closure's CPU seconds."""
    config = defaults()
    searches = _searches(config, results)
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    for name in config["objects"]:
        for label in models:
            model, held = MODELS[label]
            closure = {**config["closure"], "model": model, "dynamic": {**config["closure"]["dynamic"], "object": held}}
            scenario = validate_config({**config, "closure": closure})
            sim = SimulateParams.from_config(scenario, name)
            placement = sim.placement
            if name in searches:
                placement = searched_placement(placement, table_contracts.read_csv(table_contracts.PLACEMENT, searches[name]))
            start = time.process_time()
            contacts = simulate_object(
                hand,
                synergies,
                sim.object,
                placement,
                sim.closure,
                poses=range(0, pose_grid(sim.placement).n_poses, every),
                mechanics=sim.mechanics,
            )
            print(f"{name} {label}: closure {time.process_time() - start:.1f} CPU s", flush=True)
            select = ContactsParams.from_config(scenario, name)
            if select.drop_unloaded:
                contacts = load_carrying_contacts(contacts, select.load_threshold_N)
            (out / label).mkdir(parents=True, exist_ok=True)
            table_contracts.write(table_contracts.CONTACTS, contacts, out / label / f"{name}.parquet")


def summary(out: Path) -> None:
    """The grasp-realism table of every model's sample (the optimisation with the full set
    only), its equilibrium columns, the residual over all joints and the checks' CPU seconds."""
    config = defaults()
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    realism = RealismParams.from_config(config)
    checks_params = EquilibriumParams.of(hand, synergies, realism.k_ss_Nmm_per_rad, realism.mu)
    full = tuple(range(1, config["synergy_sets"]["incremental_max"] + 1))
    parts, extra = [], []
    for label in (m for m in MODELS if (out / m).is_dir()):
        contacts = pd.concat(
            [table_contracts.read(table_contracts.CONTACTS, out / label / f"{name}.parquet") for name in config["objects"]],
            ignore_index=True,
        )
        gfo = pd.concat(
            [
                gfo_table(part, SynergySets(synergies.matrix, (full,)), OptimiseParams.from_config(config, name).gfo)
                for name, part in contacts.groupby("object", sort=False)
            ],
            ignore_index=True,
        )
        gfo["closure_model"] = label
        start = time.process_time()
        checks = grasp_equilibrium(contacts, checks_params, synergies.columns([1])[:, 0])
        extra.append(checks.assign(cpu_s=time.process_time() - start, all_joints=_all_joints(checks)))
        parts.append(realism_of(contacts, gfo, checks, hand, realism, realism.grasp_types))
    table = pd.concat(parts, ignore_index=True)
    more = (
        pd.concat(extra)
        .groupby(["object", "closure_model"])
        .agg(median_residual_all_joints=("all_joints", "median"), checks_cpu_s=("cpu_s", "first"))
    )
    columns = [
        "object",
        "closure_model",
        "simulated",
        "dropped_by",
        "contacts_median",
        "pct_thumb",
        "pct_palm",
        "pct_index",
        "pct_force_closure",
        "median_force_per_weight",
        "median_torque_residual",
        "pct_s1_outside_cone",
    ]
    print(
        table[columns]
        .merge(more.reset_index(), on=["object", "closure_model"], how="left")
        .sort_values(["object", "closure_model"])
        .to_markdown(index=False, floatfmt=".3g")
    )


def pictures(out: Path, png: Path, poses: list[int]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp.figures.fig1_fig2_postures_grasps import PANEL_PX, _bare, _fit, _frame, _object_of, _touching_words
    from synergrasp.figures.hand_pictures import PALM_CAMERA, render

    config = defaults()
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    realism = RealismParams.from_config(config)
    params = EquilibriumParams.of(hand, synergies, realism.k_ss_Nmm_per_rad, realism.mu)
    labels = [m for m in MODELS if (out / m).is_dir()]
    names = list(config["objects"])
    fig, axes = plt.subplots(len(names), len(labels), figsize=(2.7 * len(labels), 2.9 * len(names)), squeeze=False)
    for r, (name, pose) in enumerate(zip(names, poses)):
        shape = SimulateParams.from_config(config, name).object.shape
        rows = [
            table_contracts.read(table_contracts.CONTACTS, out / m / f"{name}.parquet").set_index("pose").loc[pose]
            for m in labels
        ]
        camera = _fit(
            PALM_CAMERA, hand, [np.asarray(row["q"], dtype=float) for row in rows], [_object_of(row, shape) for row in rows]
        )
        drawn = []
        for c, (label, row) in enumerate(zip(labels, rows)):
            ax = axes[r, c]
            _bare(ax)
            links = [int(i) for i in row["contact_link"]]
            picture = render(
                hand, np.asarray(row["q"], dtype=float), camera, PANEL_PX, shape=_object_of(row, shape), touching=links
            )
            ax.imshow(picture.rgb, interpolation="antialiased")
            drawn.append(picture)
            check = grasp_equilibrium(pd.DataFrame([{**row.to_dict(), "pose": pose}]), params, synergies.columns([1])[:, 0])
            words = (
                f"r = {100 * check['torque_residual'].iloc[0]:.0f} %, S1 outside: {check['s1_outside_cone'].iloc[0]}"
                if len(check)
                else row["status"]
            )
            ax.set_title(f"{name} {label}, pose {pose}\n{int(row['n_contacts'])} contacts, {words}", fontsize=8)
            ax.set_xlabel(_touching_words(hand, links), fontsize=7)
        _frame(axes[r], drawn)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def _main(argv: list[str]) -> None:
    """The three modes of the module's docstring; a malformed command line exits naming the
    argument, before any work."""
    usage = __doc__.split("\n\n")[1]

    def number(text: str, what: str, least: int = 1) -> int:
        if not text.isdigit() or int(text) < least:
            raise SystemExit(f"closure_sample: {what} must be a whole number of at least {least}, not {text!r}\n{usage}")
        return int(text)

    if not argv or (argv[0] in ("--pictures", "--summary") and len(argv) < (4 if argv[0] == "--pictures" else 2)):
        raise SystemExit(usage)
    if argv[0] == "--pictures":
        pictures(Path(argv[1]), Path(argv[2]), [number(v, "POSE", 0) for v in argv[3:]])
    elif argv[0] == "--summary":
        summary(Path(argv[1]))
    else:
        models = argv[2:] or list(MODELS)
        unknown = [m for m in models if m not in MODELS]
        if unknown:
            raise SystemExit(f"closure_sample: MODEL {unknown} unknown; one of {list(MODELS)}")
        simulate(Path(argv[0]), number(argv[1], "EVERY") if len(argv) > 1 else 6, models)


if __name__ == "__main__":
    _main(sys.argv[1:])
