"""Closure cost and contact statistics per study box (one core).

Prints per object the median and 90th-percentile time per grasp over a spread of poses,
the status counts, the contact-count distribution and how many poses have at least two
fingers in contact; for the dynamic closure model (``closure.model: dynamic``, on fewer
poses: it costs more) the same, then ``closure_dynamic_median_ms: N``. Last line:
``closure_median_ms: N`` (kinematic model) over all objects.

Usage: bench_closure.py [poses per object, kinematic (300)] [poses per object, dynamic (60)]
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.simulation.closure import ClosureParams, closure_model, place_box  # noqa: E402
from synergrasp.simulation.scene import HandScene  # noqa: E402
from synergrasp.simulation.objects import STUDY_BOXES  # noqa: E402
from synergrasp.simulation.placement import Placement, pose_grid  # noqa: E402


#: Per-object placements: the study's default (approach to the palm centre); obj4 with its
#: 100 x 100 face toward the palm (config/config.yaml).
PLACEMENTS = {"obj4": Placement(box_axes=(1, 0, 2))}


def study_mechanics() -> dict:
    """The study's mechanics block (config/config.yaml): k_ss, μ and gravity of the dynamic model."""
    import yaml

    with open(Path(__file__).resolve().parents[1] / "config" / "config.yaml", encoding="utf-8") as handle:
        return yaml.safe_load(handle)["mechanics"]


def main(n_poses: int = 300, params: ClosureParams = ClosureParams(), key: str = "closure_median_ms") -> None:
    hand = load_hand()
    synergies = load_synergies(None, joint_names=hand.joint_names)
    placement = Placement()
    grid = pose_grid(placement)
    poses = np.linspace(0, grid.n_poses - 1, n_poses).round().astype(int)
    mechanics = study_mechanics() if params.model == "dynamic" else None
    print(f"closure model: {params.model}")
    closer = closure_model(hand, synergies, params, mechanics)
    placer = HandScene(hand)
    all_times = []
    try:
        for box in STUDY_BOXES:
            size = np.asarray(box.size_mm, dtype=float)
            placement = PLACEMENTS.get(box.name, Placement())
            times, placing, statuses, counts, two_fingers = [], [], [], [], 0
            for pose in poses:
                t0 = time.perf_counter()
                placed = place_box(placer, closer.q_open, placement, size, *grid.angles_deg(int(pose)))
                t1 = time.perf_counter()
                result = closer.grasp(size, placed)
                times.append(time.perf_counter() - t0)
                placing.append(t1 - t0)
                statuses.append(result.status)
                counts.append(len(result.links))
                two_fingers += sum(s == "contact" for s in result.finger_state) >= 2
            t = np.array(times) * 1e3
            all_times.extend(t)
            status, n_status = np.unique(statuses, return_counts=True)
            m, n_m = np.unique(counts, return_counts=True)
            print(f"{box.name} {tuple(size.tolist())} {placement.mode} axes {placement.box_axes}: {len(poses)} poses, median {np.median(t):.2f} ms, "
                  f"p90 {np.percentile(t, 90):.2f} ms per grasp "
                  f"(placement median {1e3 * np.median(placing):.2f} ms)")
            print(f"  status: {dict(zip(status.tolist(), n_status.tolist()))}")
            print(f"  contacts m: {dict(zip(m.tolist(), n_m.tolist()))}")
            print(f"  poses with >= 2 fingers in contact: {two_fingers} / {len(poses)}")
    finally:
        closer.close()
        placer.close()
    print(f"{key}: {np.median(all_times):.2f}")


if __name__ == "__main__":
    main(int(sys.argv[2]) if len(sys.argv) > 2 else 60, ClosureParams(model="dynamic"), "closure_dynamic_median_ms")
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 300)
