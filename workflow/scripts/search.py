"""The placement search of one object (docs/placement_search.md); write its placement.csv."""

from synergrasp import tables
from synergrasp.analysis.periods import alpha_period_deg
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.placement_search import SearchStepParams, full_synergy_set, search_object

with job_log(snakemake.log[0]):
    sim = SearchStepParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    synergies = load_synergies(sim.synergies, joint_names=hand.joint_names)
    period = alpha_period_deg(sim.placement, sim.object.shape, hand.palm_normal)
    result = search_object(hand, synergies, sim.object, sim.placement, sim.closure, sim.gfo,
                           full_synergy_set(synergies.matrix, sim.full_set_size), sim.search, period,
                           processes=snakemake.threads, opposition=sim.opposition)
    tables.write_csv(tables.PLACEMENT, result.table(sim.distinct_mm), snakemake.output[0])
