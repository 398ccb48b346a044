"""The study's tables from every object's optimisation results and local minima."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.analysis.summaries import study_tables
from synergrasp.config import step_params
from synergrasp.figures.study_figures import write_table

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    params = step_params(snakemake.params.cfg, "tables")
    gfo = pd.concat([pd.read_parquet(p) for p in snakemake.input.gfo], ignore_index=True)
    minima = pd.concat([pd.read_parquet(p) for p in snakemake.input.minima], ignore_index=True)
    tables = study_tables(gfo, minima, params.synergy_sets, params.table2_k_max, params.minima_radius_deg)
    for name, (title, table) in tables.items():
        write_table(table, snakemake.output[f"{name}_csv"], snakemake.output[f"{name}_md"], title=title)
