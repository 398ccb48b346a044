"""The closure models side by side on a sample of poses: contacts, equilibrium checks, timing.

    .venv/bin/python tools/closure_sample.py OUT_DIR [EVERY] [MODEL ...]
    .venv/bin/python tools/closure_sample.py --pictures OUT_DIR PNG POSE_obj1 POSE_obj2 …

For every object of the default configuration, closes the hand at the poses 0, EVERY,
2·EVERY, … (default 6: 300 of the 1800 poses) with each MODEL (``kinematic``, ``dynamic``: a
free box, ``dynamic_held``: ``closure.dynamic.object: held``; default all three), writes the
contacts table to ``OUT_DIR/<model>/<object>.parquet`` and prints, per object and model, the
closure's CPU seconds, the grasps, the median relative torque residual (and the same over all
19 joints, those moving no box contact counted as unbalanced), the share of grasps
with a contact S1 pushes outside its cone and the share touching with the index finger
(docs/closure.md, "Is the end state an equilibrium?"), and the CPU seconds of the checks.
With ``--pictures``: one row per object at the given pose (of the sample), one panel per model
found under OUT_DIR, drawn as in Fig. 2, the checks in each panel's title.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from synergrasp import tables
from synergrasp.analysis.realism import link_categories
from synergrasp.config import defaults, step_params, validate_config
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium
from synergrasp.simulation.closure import simulate_object
from synergrasp.simulation.placement import pose_grid

MODELS = {"kinematic": ("kinematic", "free"), "dynamic": ("dynamic", "free"), "dynamic_held": ("dynamic", "held")}


def _all_joints(checks: pd.DataFrame) -> pd.Series:
    """The residual over all 19 joints, the joints moving no box contact counted as unbalanced:
    √(r² ‖τ_B‖² + ‖τ_other‖²) / √(‖τ_B‖² + ‖τ_other‖²) (no second solve: Jᵀ f is 0 off B)."""
    box, other = checks["torque_box_Nmm"], checks["torque_other_Nmm"]
    return ((checks["torque_residual"] * box) ** 2 + other ** 2) ** 0.5 / (box ** 2 + other ** 2) ** 0.5


def main(out: Path, every: int, models: list[str]) -> None:
    config = defaults()
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    mech = config["mechanics"]
    checks_params = EquilibriumParams.of(hand, synergies, mech["k_ss_Nmm_per_rad"], mech["mu"])
    index = link_categories(hand.link_names, hand.link_finger)["index"]
    rows = []
    for name in config["objects"]:
        for label in models:
            model, held = MODELS[label]
            closure = {**config["closure"], "model": model, "dynamic": {**config["closure"]["dynamic"], "object": held}}
            sim = step_params(validate_config({**config, "closure": closure}), "simulate", name)
            poses = range(0, pose_grid(sim.placement).n_poses, every)
            start = time.process_time()
            contacts = simulate_object(hand, synergies, sim.box, sim.placement, sim.closure, poses=poses,
                                       mechanics=sim.mechanics)
            closure_s = time.process_time() - start
            (out / label).mkdir(parents=True, exist_ok=True)
            tables.write(tables.CONTACTS, contacts, out / label / f"{name}.parquet")
            start = time.process_time()
            checks = grasp_equilibrium(contacts, checks_params, synergies.columns([1])[:, 0])
            checks_s = time.process_time() - start
            grasps = contacts[contacts["status"] == "grasp"]
            rows.append({"object": name, "model": label, "poses": len(contacts), "grasps": len(grasps),
                         "closure_cpu_s": round(closure_s, 1), "checks_cpu_s": round(checks_s, 2),
                         "median_residual": checks["torque_residual"].median(),
                         "median_residual_all_joints": _all_joints(checks).median(),
                         "pct_s1_outside": 100.0 * (checks["s1_outside_cone"] > 0).mean(),
                         "pct_index": 100.0 * grasps["contact_link"].map(lambda ls: any(int(i) in index for i in ls)).mean()})
            print(pd.DataFrame(rows[-1:]).to_string(index=False, header=len(rows) == 1), flush=True)
    print(pd.DataFrame(rows).to_markdown(index=False, floatfmt=".3g"))


def pictures(out: Path, png: Path, poses: list[int]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from synergrasp.figures.hand_figures import PANEL_PX, _bare, _box_of, _fit, _frame, _touching_words
    from synergrasp.figures.hand_pictures import PALM_CAMERA, render

    config = defaults()
    hand = load_hand(config["hand"])
    synergies = load_synergies(config["synergies"], joint_names=hand.joint_names)
    mech = config["mechanics"]
    params = EquilibriumParams.of(hand, synergies, mech["k_ss_Nmm_per_rad"], mech["mu"])
    labels = [m for m in MODELS if (out / m).is_dir()]
    names = list(config["objects"])
    fig, axes = plt.subplots(len(names), len(labels), figsize=(2.7 * len(labels), 2.9 * len(names)), squeeze=False)
    for r, (name, pose) in enumerate(zip(names, poses)):
        size = config["objects"][name]["size_mm"]
        rows = [tables.read(tables.CONTACTS, out / m / f"{name}.parquet").set_index("pose").loc[pose] for m in labels]
        camera = _fit(PALM_CAMERA, hand, [np.asarray(row["q"], dtype=float) for row in rows],
                      [_box_of(row, size) for row in rows])
        drawn = []
        for c, (label, row) in enumerate(zip(labels, rows)):
            ax = axes[r, c]
            _bare(ax)
            links = [int(i) for i in row["contact_link"]]
            picture = render(hand, np.asarray(row["q"], dtype=float), camera, PANEL_PX, box=_box_of(row, size),
                             touching=links)
            ax.imshow(picture.rgb, interpolation="antialiased")
            drawn.append(picture)
            check = grasp_equilibrium(pd.DataFrame([{**row.to_dict(), "pose": pose}]), params,
                                      synergies.columns([1])[:, 0])
            words = (f"r = {100 * check['torque_residual'].iloc[0]:.0f} %, S1 outside: {check['s1_outside_cone'].iloc[0]}"
                     if len(check) else row["status"])
            ax.set_title(f"{name} {label}, pose {pose}\n{int(row['n_contacts'])} contacts, {words}", fontsize=8)
            ax.set_xlabel(_touching_words(hand, links), fontsize=7)
        _frame(axes[r], drawn)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    if sys.argv[1] == "--pictures":
        pictures(Path(sys.argv[2]), Path(sys.argv[3]), [int(v) for v in sys.argv[4:]])
        sys.exit()
    main(Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 6, sys.argv[3:] or list(MODELS))
