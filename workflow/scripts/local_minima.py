"""Local minima of the optimal force over one object's (alpha, beta) grid, every set."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.analysis.minima import minima_table

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    gfo = pd.read_parquet(snakemake.input.gfo)
    minima_table(gfo, radius_deg=snakemake.params.radius_deg).to_parquet(snakemake.output[0], index=False)
