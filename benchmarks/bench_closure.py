"""Closure cost and contact statistics per study box (one core).

Prints per object the median (CPU time, `time.process_time`) and 90th-percentile time per grasp over a spread of poses,
the status counts, the contact-count distribution and how many poses have at least two
fingers in contact; for the dynamic closure model (``closure.model: dynamic``, on fewer
poses: it costs more) the same, then ``closure_dynamic_median_ms: N``; then
``closure_median_ms: N`` (kinematic model) over all objects. Last, the kinematic closure on
each kind of shape (docs/shapes.md) beside a box of the same size, with the study's placement
and closure settings on the same poses: the median per grasp and its ratio to the box's
(``closure_shape_median_ms_<kind>: N`` and ``closure_shape_ratio_<kind>: N``; issue 25 asks ≤ 1.5 for the sphere and
the cylinder, ≤ 3
for a convex mesh of 1000 faces; a non-convex mesh, the duck of the example study, is
reported on its own line).

Usage: bench_closure.py [poses per object, kinematic (300)] [poses per object, dynamic (60)]
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from synergrasp.config import defaults, validate_config  # noqa: E402
from synergrasp.hand.kinematics import load_hand  # noqa: E402
from synergrasp.hand.synergies import load_synergies  # noqa: E402
from synergrasp.simulation.closure import SimulateParams, closure_model, place_object  # noqa: E402
from synergrasp.simulation.placement import pose_grid  # noqa: E402
from synergrasp.simulation.scene import HandScene  # noqa: E402
from synergrasp.simulation.shapes import Box, Cylinder, Mesh, Sphere  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: The shapes timed against the box: (name, shape, placement.box_axes, key of its ratio line).
SHAPES = (
    ("box 60 mm", Box((60.0, 60.0, 60.0)), (0, 1, 2), "box"),
    ("sphere r 30 mm", Sphere(30.0), (0, 1, 2), "sphere"),
    ("cylinder r 30 x 120 mm, axis along the fingers", Cylinder(30.0, 120.0), (0, 1, 2), "cylinder"),
    ("cylinder r 30 x 120 mm, axis along the palm normal", Cylinder(30.0, 120.0), (2, 0, 1), "cylinder"),
    (
        "convex mesh of 1000 faces, 60 mm (tests/data/rounded_cube_1000.stl)",
        Mesh(str(ROOT / "tests" / "data" / "rounded_cube_1000.stl"), 1.0),
        (0, 1, 2),
        "mesh_convex_1000",
    ),
    (
        "non-convex mesh: the duck, 83 x 77 x 58 mm, 5 convex parts (config/examples/meshes/duck.obj)",
        Mesh(str(ROOT / "config" / "examples" / "meshes" / "duck.obj"), 50.0),
        (0, 1, 2),
        "mesh_nonconvex_duck",
    ),
)


def main(n_poses: int = 300, model: str = "kinematic", key: str = "closure_median_ms") -> None:
    """The study's boxes and closure settings (the configuration's defaults), each box placed
    by the approach preset (the palm centre; a searched target needs the search's output),
    closed by ``model``."""
    study = validate_config(
        {
            **defaults(),
            "closure": {**defaults()["closure"], "model": model},
            "placement": {**defaults()["placement"], "mode": "approach"},
        }
    )
    hand = load_hand()
    synergies = load_synergies(None, joint_names=hand.joint_names)
    first = SimulateParams.from_config(study, next(iter(study["objects"])))
    grid = pose_grid(first.placement)
    poses = np.linspace(0, grid.n_poses - 1, n_poses).round().astype(int)
    print(f"closure model: {model}")
    closer = closure_model(hand, synergies, first.closure, first.mechanics, first.object.mass_kg)
    placer = HandScene(hand)
    all_times = []
    try:
        for name in study["objects"]:
            sim = SimulateParams.from_config(study, name)
            obj, placement = sim.object, sim.placement
            times, placing, statuses, counts, two_fingers = [], [], [], [], 0
            for pose in poses:
                t0 = time.process_time()
                placed = place_object(placer, closer.q_open, placement, obj.shape, *grid.angles_deg(int(pose)))
                t1 = time.process_time()
                result = closer.grasp(placed)
                times.append(time.process_time() - t0)
                placing.append(t1 - t0)
                statuses.append(result.status)
                counts.append(len(result.links))
                two_fingers += sum(s == "contact" for s in result.finger_state) >= 2
            t = np.array(times) * 1e3
            all_times.extend(t)
            status, n_status = np.unique(statuses, return_counts=True)
            m, n_m = np.unique(counts, return_counts=True)
            print(
                f"{obj.name} {obj.shape.kind} {obj.shape.label} {placement.mode} axes {placement.box_axes}: "
                f"{len(poses)} poses, median {np.median(t):.2f} ms, "
                f"p90 {np.percentile(t, 90):.2f} ms per grasp "
                f"(placement median {1e3 * np.median(placing):.2f} ms)"
            )
            print(f"  status: {dict(zip(status.tolist(), n_status.tolist()))}")
            print(f"  contacts m: {dict(zip(m.tolist(), n_m.tolist()))}")
            print(f"  poses with >= 2 fingers in contact: {two_fingers} / {len(poses)}")
    finally:
        closer.close()
        placer.close()
    print(
        f"{key}: {np.median(all_times):.2f}  ({model} closure, median CPU ms per grasp over {len(poses)} poses of each study box)"
    )


def shapes(n_poses: int = 300) -> None:
    """The kinematic closure per kind of shape, against the box, on the same poses (one core)."""
    from dataclasses import replace

    study = defaults()
    hand = load_hand()
    synergies = load_synergies(None, joint_names=hand.joint_names)
    sim = SimulateParams.from_config(study, next(iter(study["objects"])))
    sim = replace(sim, placement=replace(sim.placement, mode="approach"))  # the palm centre: no search output needed
    grid = pose_grid(sim.placement)
    poses = np.linspace(0, grid.n_poses - 1, n_poses).round().astype(int)
    closer = closure_model(hand, synergies, sim.closure)
    placer = HandScene(hand)
    medians = {}
    try:
        for name, shape, axes, _ in SHAPES:
            placement = replace(sim.placement, box_axes=axes)
            times, contacts = [], []
            for pose in poses:
                t0 = time.process_time()
                placed = place_object(placer, closer.q_open, placement, shape, *grid.angles_deg(int(pose)))
                result = closer.grasp(placed)
                times.append(time.process_time() - t0)
                contacts.append(len(result.links))
            medians[name] = float(np.median(times)) * 1e3
            print(
                f"{name}: {len(poses)} poses, median {medians[name]:.2f} ms, p90 {1e3 * np.percentile(times, 90):.2f} ms "
                f"per grasp, median {np.median(contacts):g} contacts"
            )
    finally:
        closer.close()
        placer.close()
    box = medians[SHAPES[0][0]]
    for name, _, _, key in SHAPES:
        print(f"closure_shape_median_ms_{key}: {medians[name]:.2f}  ({name}, median CPU ms per grasp)")
        if name != SHAPES[0][0]:
            print(f"closure_shape_ratio_{key}: {medians[name] / box:.2f}  ({name}, against the box)")


if __name__ == "__main__":
    main(int(sys.argv[2]) if len(sys.argv) > 2 else 60, "dynamic", "closure_dynamic_median_ms")
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 300)
    shapes(int(sys.argv[1]) if len(sys.argv) > 1 else 300)
