"""The placement search of one object (docs/placement_search.md, version 3: the grasp types
this hand can make, with the fallback chain); write its placement.csv."""

from synergrasp import table_contracts
from synergrasp.analysis.periods import alpha_period_deg
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.optimisation.grasp_type_search import fallback_line, search_object_types
from synergrasp.optimisation.placement_search import SearchStepParams
from synergrasp.simulation.reach import read_hand_reach

with job_log(snakemake.log[0]) as log:
    sim = SearchStepParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    synergies = load_synergies(sim.synergies, joint_names=hand.joint_names)
    period = alpha_period_deg(sim.placement, sim.object.shape, hand.palm_normal)
    reach = read_hand_reach(snakemake.input.reach, hand)
    result = search_object_types(hand, synergies, sim, period, processes=snakemake.threads, reach=reach)
    table_contracts.write_csv(table_contracts.PLACEMENT, result.table(sim.distinct_mm), snakemake.output[0])
    line = fallback_line(result)
    if line:  # on the console and in the job's log
        print(f"WARNING: {line}")
        print(f"WARNING: {line}", file=log)
