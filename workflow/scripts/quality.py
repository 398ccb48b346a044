"""Quality indices of every pose of one object (table) and their maps over (α, β)."""

from synergrasp import table_contracts
from synergrasp.figures.quality_maps import figure_quality_maps
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.mechanics import read_grasps
from synergrasp.optimisation.quality import QualityParams, quality_table
from synergrasp.simulation.opposition import HandAxes

with job_log(snakemake.log[0]):
    params = QualityParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    contacts = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    gfo = table_contracts.read(table_contracts.GFO, snakemake.input.gfo)
    hand = load_hand(params.hand)
    matrix = load_synergies(params.synergies, joint_names=hand.joint_names).matrix
    quality = quality_table(contacts, gfo, read_grasps(contacts), matrix, params, HandAxes.from_hand(hand))
    table_contracts.write(table_contracts.QUALITY, quality, snakemake.output.table)
    figure_quality_maps(quality, snakemake.wildcards.object, snakemake.output.png, snakemake.output.pdf)
