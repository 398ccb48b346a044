"""Fig. 2: example simulated grasps of every object (hand and box drawn together)."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.config import step_params
from synergrasp.figures.hand_drawing import figure_example_grasps
from synergrasp.hand.kinematics import load_hand

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    params = step_params(snakemake.params.cfg, "fig2")
    tables = [pd.read_parquet(path) for path in snakemake.input.contacts]
    figure_example_grasps(load_hand(params.hand), params.boxes, tables, params.fig2_poses_deg,
                          snakemake.output.png, snakemake.output.pdf)
