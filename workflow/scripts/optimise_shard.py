"""Grasp-force optimisation of one shard of an object's poses, for every synergy set."""

from synergrasp import table_contracts
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.optimise import OptimiseParams, optimise_shard
from synergrasp.optimisation.problem import SynergySets

with job_log(snakemake.log[0]):
    opt = OptimiseParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    table = load_synergies(opt.synergies, joint_names=load_hand(opt.hand).joint_names)
    synergies = SynergySets(table.matrix, tuple(opt.sets.values()))
    contacts = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    gfo = optimise_shard(contacts, int(snakemake.wildcards.shard), opt.pose_shards, synergies, opt.gfo)
    table_contracts.write(table_contracts.GFO, gfo, snakemake.output[0])
