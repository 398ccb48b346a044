"""Local minima of the optimal force over one object's (alpha, beta) grid, every set."""

from synergrasp import table_contracts
from synergrasp.analysis.minima import MinimaParams, minima_table
from synergrasp.analysis.verdicts import with_verdicts
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = MinimaParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    weights = {snakemake.wildcards.object: params.weight_N} if params.weight_N is not None else None
    gfo = with_verdicts(
        table_contracts.read(table_contracts.GFO, snakemake.input.gfo), params.success, weights, params.bound_multiple
    )
    table_contracts.write(table_contracts.MINIMA, minima_table(gfo, radius_deg=params.radius_deg), snakemake.output[0])
