"""The placement map of one object: the search's score over its targets and grasps at the chosen one."""

from synergrasp import tables
from synergrasp.figures.placement_map import figure_placement_map
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.optimisation.placement_search import SearchStepParams

with job_log(snakemake.log[0]):
    sim = SearchStepParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    figure_placement_map(load_hand(sim.hand), sim.object, tables.read_csv(tables.PLACEMENT, snakemake.input.placement),
                         tables.read(tables.CONTACTS, snakemake.input.contacts), sim.search.spacing_mm,
                         snakemake.output.png, snakemake.output.pdf)
