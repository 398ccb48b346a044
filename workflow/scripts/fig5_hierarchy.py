"""Fig. 5A/5B: success rate and paired force ratio of every set {S_k, S_i, S_j}, mean over objects."""

import pandas as pd

from synergrasp.figures.study_figures import FIG5B_RATIO_RANGE, Fig5Params, figure_hierarchy
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    p, out = Fig5Params.from_config(snakemake.params.cfg), snakemake.output
    first, success = p.hierarchy_first, p.success
    matrices = pd.read_csv(snakemake.input.hierarchy)
    figure_hierarchy(matrices, "success_rate", first, f"Fig. 5A: success rate (%, {success}), mean over objects",
                     ".0f", (0.0, 100.0), "success rate (%)", out.success_png, out.success_pdf)
    figure_hierarchy(matrices, "force_ratio_median", first,
                     "Fig. 5B: optimal force / full set's optimal force on the same pose "
                     "(median per object, mean over objects)", ".2f", FIG5B_RATIO_RANGE,
                     "paired force ratio (log scale)", out.force_png, out.force_pdf, log_scale=True)
