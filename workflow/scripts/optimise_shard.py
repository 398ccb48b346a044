"""Grasp-force optimisation of one shard of an object's poses, for every synergy set."""

from synergrasp import tables
from synergrasp.config import gfo_params
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.problem import SynergySets
from synergrasp.optimisation.study import optimise_shard

with job_log(snakemake.log[0]):
    opt = snakemake.params.opt
    synergies = SynergySets(load_synergies(opt["synergies"]).matrix, tuple(opt["sets"].values()))
    contacts = tables.read(tables.CONTACTS, snakemake.input.contacts)
    gfo = optimise_shard(contacts, opt["shard"], snakemake.params.n_shards, synergies,
                         gfo_params(opt["mechanics"], opt["mass_kg"]))
    tables.write(tables.GFO, gfo, snakemake.output[0])
