"""One object's gfo table from its optimisation shards, in pose order."""
from contextlib import redirect_stderr

from synergrasp import tables
from synergrasp.optimisation.study import merge_shards

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    shards = [tables.read(tables.GFO, path) for path in snakemake.input.shards]
    tables.write(tables.GFO, merge_shards(shards), snakemake.output[0])
