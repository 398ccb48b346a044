"""Concatenate one object's optimisation shards into its gfo table, in pose order (sets keep their configured order)."""
import pandas as pd

from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    table = pd.concat([pd.read_parquet(path) for path in snakemake.input.shards], ignore_index=True)
    table.sort_values("pose", kind="stable").to_parquet(snakemake.output[0], index=False)
