"""Fig. 4 for one object: force maps over (alpha, beta) and exploded views."""

from synergrasp import table_contracts
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.figures.fig4_fig5_forces_hierarchy import Fig4Params, figure_exploded_views, figure_force_maps
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    p = Fig4Params.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    weights = {snakemake.wildcards.object: p.weight_N} if p.weight_N is not None else None
    gfo = with_verdicts(table_contracts.read(table_contracts.GFO, snakemake.input.gfo), p.success, weights, p.bound_multiple)
    minima = table_contracts.read(table_contracts.MINIMA, snakemake.input.minima)
    name, out, panel_k = snakemake.wildcards.object, snakemake.output, list(p.panel_k)
    figure_force_maps(gfo, minima, panel_k, name, out.maps_png, out.maps_pdf, p.success)
    figure_exploded_views(gfo, panel_k, p.alpha_slice_deg, p.beta_slice_deg, name, out.exploded_png, out.exploded_pdf, p.success)
