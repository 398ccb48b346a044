"""The grasp-realism table and figure: how the simulated grasps touch the boxes and whether
their end states are equilibria of the soft-synergy hand; which links touch; the
graspable-objects table, and one line per object that can never be grasped. One object's
rows at a time (``realism_by_object``)."""

from synergrasp import table_contracts
from synergrasp.analysis.graspability import fallback_lines, grasp_types_of, ungraspable_lines, with_left_out
from synergrasp.analysis.realism import RealismParams, realism_by_object
from synergrasp.figures.grasp_realism import figure_grasp_realism
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.simulation.random_objects import left_out

with job_log(snakemake.log[0]) as log:
    params = RealismParams.from_config(snakemake.params.cfg)
    # the effective grasp type of a searched object (docs/placement_search.md, version 3)
    types = grasp_types_of(
        params.grasp_types, [table_contracts.read_csv(table_contracts.PLACEMENT, p) for p in snakemake.input.placements]
    )
    files = list(zip(snakemake.input.contacts, snakemake.input.gfo))
    table, links, graspable = realism_by_object(files, load_hand(params.hand), params, types)
    table_contracts.write_study_table(table, snakemake.output.csv, snakemake.output.md, title="Grasp realism")
    table_contracts.write_study_table(
        links, snakemake.output.links_csv, snakemake.output.links_md, title="Which links touch the box (% of simulated grasps)"
    )
    figure_grasp_realism(table, snakemake.output.png, snakemake.output.pdf)
    graspable = with_left_out(graspable, left_out(params.random_objects, snakemake.input.manifest))
    table_contracts.write_study_table(
        graspable, snakemake.output.graspable_csv, snakemake.output.graspable_md, title="Graspable objects"
    )
    for line in ungraspable_lines(graspable) + fallback_lines(graspable):  # on the console and in the job's log
        print(f"WARNING: {line}")
        print(f"WARNING: {line}", file=log)
