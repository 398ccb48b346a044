"""One object's gfo table from its optimisation shards, in pose order."""

from synergrasp import tables
from synergrasp.job_log import job_log
from synergrasp.optimisation.shards import merge_shards

with job_log(snakemake.log[0]):
    shards = [tables.read(tables.GFO, path) for path in snakemake.input.shards]
    tables.write(tables.GFO, merge_shards(shards), snakemake.output[0])
