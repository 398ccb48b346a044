"""Fig. 2: representative simulated grasps of every object, chosen by rule from its contacts."""

from synergrasp import tables
from synergrasp.figures.hand_figures import Fig2Params, figure_example_grasps
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = Fig2Params.from_config(snakemake.params.cfg)
    contacts = [tables.read(tables.CONTACTS, path) for path in snakemake.input.contacts]
    figure_example_grasps(load_hand(params.hand), params.objects, contacts, snakemake.output.png,
                          snakemake.output.pdf)
