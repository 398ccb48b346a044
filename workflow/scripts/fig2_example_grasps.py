"""Fig. 2: example simulated grasps of every object (hand and box drawn together)."""

import pandas as pd

from synergrasp.hand.kinematics import load_hand
from synergrasp.simulation.objects import boxes_from_config
from synergrasp.figures.hand_drawing import figure_example_grasps
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    boxes = boxes_from_config([{k: v for k, v in o.items() if k != "placement"} for o in snakemake.params.objects])
    tables = [pd.read_parquet(path) for path in snakemake.input.contacts]
    figure_example_grasps(load_hand(snakemake.params.hand), boxes, tables, snakemake.params.poses,
                          snakemake.output.png, snakemake.output.pdf)
