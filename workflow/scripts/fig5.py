"""Fig. 5A/5B: success rate of every set {S_k, S_i, S_j} in both views of "averaged over
objects", and its paired force ratio to the full set pooled over its successes, with counts."""

import pandas as pd

from synergrasp.figures.fig4_fig5_forces_hierarchy import FIG5B_RATIO_RANGE, Fig5Params, figure_hierarchy
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    p, out = Fig5Params.from_config(snakemake.params.cfg), snakemake.output
    first, success = p.hierarchy_first, p.success
    matrices = pd.read_csv(snakemake.input.hierarchy)
    for column, view, png, pdf in (
        ("success_rate", "per-object view (the study's)", out.success_png, out.success_pdf),
        ("success_rate_pooled", "pooled view", out.pooled_png, out.pooled_pdf),
    ):
        figure_hierarchy(
            matrices,
            column,
            first,
            f"Fig. 5A: success rate (%, {success}), {view}",
            ".0f",
            (0.0, 100.0),
            "success rate (%)",
            png,
            pdf,
        )
    figure_hierarchy(
        matrices,
        "force_ratio_median",
        first,
        "Fig. 5B: optimal force / full set's optimal force on the same pose "
        "(median over every object's successes; below: distinct poses)",
        ".2f",
        FIG5B_RATIO_RANGE,
        "paired force ratio (log scale)",
        out.force_png,
        out.force_pdf,
        log_scale=True,
        counts="n_force_poses",
    )
