"""Regenerate the shipped synergy tables (src/synergrasp/data/synergies_<name>.csv) from the
human synergies and each mapping, and the Shadow and Inspire hands' (data/hands/*/synergies.csv)
by ``synergies map`` from the study's hand and table (docs/synergies.md); tests/test_synergies.py
and tests/test_synergy_map.py check that the shipped files equal a fresh mapping.

    .venv/bin/python tools/synergy_tables.py
"""

from __future__ import annotations

from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergy_map import map_synergies
from synergrasp.hand.synergies import (
    SHIPPED_TABLES,
    load_human_synergies,
    load_synergies,
    load_synergy_mapping,
    map_human_synergies,
    shadow_hand_files,
    shipped_hand_table,
    shipped_path,
    write_synergies,
)

if __name__ == "__main__":
    for table in SHIPPED_TABLES:
        write_synergies(map_human_synergies(load_human_synergies(), load_synergy_mapping(table)), shipped_path(table))
        print(f"wrote {shipped_path(table)}")
    hand_path, _, table_path = shadow_hand_files()
    fit, _ = map_synergies(load_hand(None), load_synergies(None), load_hand(hand_path))
    write_synergies(fit.synergies, table_path)
    print(f"wrote {table_path}")
    # the Inspire hand's table the same way (docs/hand.md, "The shipped Inspire dexterous hand")
    fit, _ = map_synergies(load_hand(None), load_synergies(None), load_hand("inspire_hand"))
    write_synergies(fit.synergies, shipped_hand_table("inspire_hand"))
    print(f"wrote {shipped_hand_table('inspire_hand')}")
