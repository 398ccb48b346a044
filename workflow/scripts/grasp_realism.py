"""The grasp-realism table and figure: how the simulated grasps touch the boxes."""

import pandas as pd

from synergrasp import tables
from synergrasp.analysis.realism import RealismParams, grasp_realism
from synergrasp.figures.grasp_realism import figure_grasp_realism
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = RealismParams.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    contacts = pd.concat([tables.read(tables.CONTACTS, p) for p in snakemake.input.contacts], ignore_index=True)
    gfo = pd.concat([tables.read(tables.GFO, p) for p in snakemake.input.gfo], ignore_index=True)
    table = grasp_realism(contacts, gfo, hand.link_names, hand.link_finger, params.full_set_id, params.weights_N,
                          params.load_threshold_N)
    tables.write_study_table(table, snakemake.output.csv, snakemake.output.md, title="Grasp realism")
    figure_grasp_realism(table, snakemake.output.png, snakemake.output.pdf)
