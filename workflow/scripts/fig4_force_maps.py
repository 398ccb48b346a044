"""Fig. 4 for one object: force maps over (alpha, beta) and exploded views."""

import pandas as pd

from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.figures.study_figures import figure_exploded_views, figure_force_maps
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    success = snakemake.params.success
    gfo = with_verdicts(pd.read_parquet(snakemake.input.gfo), success)
    minima = pd.read_parquet(snakemake.input.minima)
    fig4, name, out = snakemake.params.fig4, snakemake.wildcards.object, snakemake.output
    figure_force_maps(gfo, minima, fig4["panel_k"], name, out.maps_png, out.maps_pdf, success)
    figure_exploded_views(gfo, fig4["panel_k"], fig4["alpha_slice_deg"], fig4["beta_slice_deg"],
                          name, out.exploded_png, out.exploded_pdf, success)
