"""Fig. 2: representative simulated grasps of every object, chosen by rule from its contacts."""

from synergrasp import tables
from synergrasp.figures.hand_figures import figure_example_grasps
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.simulation.objects import boxes_from_config

with job_log(snakemake.log[0]):
    boxes = boxes_from_config([{k: v for k, v in o.items() if k != "placement"} for o in snakemake.params.objects])
    contacts = [tables.read(tables.CONTACTS, path) for path in snakemake.input.contacts]
    figure_example_grasps(load_hand(snakemake.params.hand), boxes, contacts, snakemake.output.png,
                          snakemake.output.pdf)
