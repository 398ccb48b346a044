"""Grasp-force optimisation of one shard of an object's poses, for every synergy set."""

from synergrasp import tables
from synergrasp.config import step_params
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.problem import SynergySets
from synergrasp.optimisation.study import optimise_shard

with job_log(snakemake.log[0]):
    opt = step_params(snakemake.params.cfg, "optimise", snakemake.wildcards.object)
    synergies = SynergySets(load_synergies(opt.synergies).matrix, tuple(opt.sets.values()))
    contacts = tables.read(tables.CONTACTS, snakemake.input.contacts)
    gfo = optimise_shard(contacts, int(snakemake.wildcards.shard), opt.pose_shards, synergies, opt.gfo)
    tables.write(tables.GFO, gfo, snakemake.output[0])
