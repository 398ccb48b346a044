"""Where the thumb ends in a study's grasps (docs/synergies.md, "The thumb-opposition check"):
per object, the share of grasps whose contacts include a thumb link, and the share whose thumb
ended blocked by the hand ("self") with one of its links on the palm (a thumb link whose pair
with the palm is not ignored by design, within the closure's contact distance of the palm's
boxes). Reads results/objects/<object>/contacts.parquet of a finished study.

    .venv/bin/python tools/thumb_in_grasps.py [--configfile config/examples/shadow_hand.yaml] [--results results]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from synergrasp import table_contracts
from synergrasp.hand.kinematics import load_hand
from synergrasp.input_checks import checked_scenario, read_overlays
from synergrasp.simulation.capsules import HandCapsules, pair_gaps

if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configfile", nargs="*", default=[])
    parser.add_argument("--results", default="results")
    args = parser.parse_args()
    cfg, _ = checked_scenario(read_overlays(args.configfile))
    hand = load_hand(cfg["hand"])
    caps = HandCapsules.of(hand)
    row = {int(link): i for i, link in enumerate(caps.links)}
    ignored = {tuple(sorted(p)) for p in hand.ignored_link_pairs}
    thumb_links = [link for link in hand.finger_links[0] if link in row]
    on_palm = [link for link in thumb_links if (0, link) not in ignored]
    first = np.array([row[link] for link in on_palm], dtype=np.int64)
    second = -np.ones(len(on_palm), dtype=np.int64)
    distance = float(cfg["closure"]["contact_distance_mm"])
    print(f"{'object':<8} {'grasps':>7} {'thumb touches %':>16} {'thumb blocked by the palm %':>28}")
    for obj in cfg["objects"]:
        contacts = table_contracts.read(table_contracts.CONTACTS, Path(args.results) / "objects" / obj / "contacts.parquet")
        grasps = contacts[contacts.status == "grasp"]
        touches = blocked = 0
        for r in grasps.itertuples():
            touches += bool(set(np.asarray(r.contact_link).tolist()) & set(thumb_links))
            if r.finger_state[0] == "self":
                p0, p1 = caps.segments(np.asarray(r.q, dtype=float))
                gaps = pair_gaps(p0, p1, caps.radius, first, second, caps.palm_rotation, caps.palm_centre, caps.palm_half)
                blocked += bool(np.any(gaps <= distance))
        n = len(grasps)
        print(f"{obj:<8} {n:>7} {100 * touches / max(n, 1):>16.1f} {100 * blocked / max(n, 1):>28.1f}")
