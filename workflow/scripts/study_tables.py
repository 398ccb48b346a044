"""The study's tables from every object's optimisation results and local minima."""

import pandas as pd

from synergrasp.analysis.summaries import study_tables
from synergrasp.tables import write_study_table
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    gfo = pd.concat([pd.read_parquet(p) for p in snakemake.input.gfo], ignore_index=True)
    minima = pd.concat([pd.read_parquet(p) for p in snakemake.input.minima], ignore_index=True)
    tables = study_tables(gfo, minima, snakemake.params.sets, snakemake.params.table2_k_max,
                          snakemake.params.radius_deg)
    for name, (title, table) in tables.items():
        write_study_table(table, snakemake.output[f"{name}_csv"], snakemake.output[f"{name}_md"], title=title)
