"""Fig. 5A/5B: success rate and mean force of every set {S_k, S_i, S_j}, averaged over objects."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.analysis.summaries import hierarchy_matrices, mean_over_objects
from synergrasp.config import step_params
from synergrasp.figures.study_figures import figure_hierarchy

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    first, out = step_params(snakemake.params.cfg, "fig5").hierarchy_first, snakemake.output
    matrices = hierarchy_matrices(mean_over_objects(pd.read_csv(snakemake.input.rates)), first)
    figure_hierarchy(matrices, "success_rate", first, "Fig. 5A: success rate (%), mean over objects",
                     ".0f", out.success_png, out.success_pdf)
    figure_hierarchy(matrices, "mean_force", first, "Fig. 5B: mean optimal force (N), mean over objects (log grey scale)",
                     ".1f", out.force_png, out.force_pdf, log_scale=True)
