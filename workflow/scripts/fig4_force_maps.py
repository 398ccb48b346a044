"""Fig. 4 for one object: force maps over (alpha, beta) and exploded views."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.config import step_params
from synergrasp.figures.study_figures import figure_exploded_views, figure_force_maps

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    params = step_params(snakemake.params.cfg, "fig4")
    gfo = pd.read_parquet(snakemake.input.gfo)
    minima = pd.read_parquet(snakemake.input.minima)
    name, out = snakemake.wildcards.object, snakemake.output
    figure_force_maps(gfo, minima, list(params.fig4_panel_k), name, out.maps_png, out.maps_pdf)
    figure_exploded_views(gfo, list(params.fig4_panel_k), params.fig4_alpha_slice_deg,
                          params.fig4_beta_slice_deg, name, out.exploded_png, out.exploded_pdf)
