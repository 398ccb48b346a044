"""The study's tables from every object's optimisation results and local minima."""
from contextlib import redirect_stderr

import pandas as pd

from synergrasp.figures.study_figures import write_table
from synergrasp.analysis.summaries import study_tables

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    gfo = pd.concat([pd.read_parquet(p) for p in snakemake.input.gfo], ignore_index=True)
    minima = pd.concat([pd.read_parquet(p) for p in snakemake.input.minima], ignore_index=True)
    tables = study_tables(gfo, minima, snakemake.params.sets, snakemake.params.table2_k_max,
                          snakemake.params.radius_deg)
    for name, (title, table) in tables.items():
        write_table(table, snakemake.output[f"{name}_csv"], snakemake.output[f"{name}_md"], title=title)
