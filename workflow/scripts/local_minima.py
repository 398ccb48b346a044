"""Local minima of the optimal force over one object's (alpha, beta) grid, every set."""
import pandas as pd

from synergrasp.analysis.minima import minima_table
from synergrasp.config import step_params

params = step_params(snakemake.params.cfg, "minima")
gfo = pd.read_parquet(snakemake.input.gfo)
minima_table(gfo, radius_deg=params.radius_deg).to_parquet(snakemake.output[0], index=False)
