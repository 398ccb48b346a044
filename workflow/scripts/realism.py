"""The grasp-realism table and figure: how the simulated grasps touch the boxes and whether
their end states are equilibria of the soft-synergy hand; which links touch; the
graspable-objects table, and one line per object that can never be grasped."""

import pandas as pd

from synergrasp import tables
from synergrasp.analysis.graspability import fallback_lines, grasp_types_of, graspable_objects, ungraspable_lines, with_left_out
from synergrasp.analysis.realism import RealismParams, grasp_labels, grasp_realism, link_shares
from synergrasp.figures.grasp_realism import figure_grasp_realism
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.optimisation.grasp_type_search import type_family
from synergrasp.optimisation.equilibrium import EquilibriumParams, grasp_equilibrium
from synergrasp.simulation.opposition import HandAxes
from synergrasp.simulation.random_objects import left_out

with job_log(snakemake.log[0]) as log:
    params = RealismParams.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    synergies = params.synergies(hand.joint_names)
    contacts = pd.concat([tables.read(tables.CONTACTS, p) for p in snakemake.input.contacts], ignore_index=True)
    gfo = pd.concat([tables.read(tables.GFO, p) for p in snakemake.input.gfo], ignore_index=True)
    checks = grasp_equilibrium(
        contacts, EquilibriumParams.of(hand, synergies, params.k_ss_Nmm_per_rad, params.mu), synergies.columns([1])[:, 0]
    )
    labels = grasp_labels(contacts, HandAxes.from_hand(hand), params.opposition, params.shapes)
    # the effective grasp type of a searched object (docs/placement_search.md, version 3)
    types = grasp_types_of(params.grasp_types, [tables.read_csv(tables.PLACEMENT, p) for p in snakemake.input.placements])
    table = grasp_realism(
        contacts,
        gfo,
        checks,
        hand.link_names,
        hand.link_finger,
        params.full_set_id,
        params.weights_N,
        params.load_threshold_N,
        labels,
        {name: type_family(effective) for name, (_, effective, _) in types.items()},
    )
    tables.write_study_table(table, snakemake.output.csv, snakemake.output.md, title="Grasp realism")
    tables.write_study_table(
        link_shares(contacts, hand.link_names, hand.link_finger),
        snakemake.output.links_csv,
        snakemake.output.links_md,
        title="Which links touch the box (% of simulated grasps)",
    )
    figure_grasp_realism(table, snakemake.output.png, snakemake.output.pdf)
    graspable = with_left_out(
        graspable_objects(contacts, gfo, params.full_set_id, types), left_out(params.random_objects, snakemake.input.manifest)
    )
    tables.write_study_table(graspable, snakemake.output.graspable_csv, snakemake.output.graspable_md, title="Graspable objects")
    for line in ungraspable_lines(graspable) + fallback_lines(graspable):  # on the console and in the job's log
        print(f"WARNING: {line}")
        print(f"WARNING: {line}", file=log)
