"""One object's gfo table from its optimisation shards, in pose order."""

from synergrasp import table_contracts
from synergrasp.job_log import job_log
from synergrasp.optimisation.shards import merge_shards

with job_log(snakemake.log[0]):
    shards = [table_contracts.read(table_contracts.GFO, path) for path in snakemake.input.shards]
    table_contracts.write(table_contracts.GFO, merge_shards(shards), snakemake.output[0])
