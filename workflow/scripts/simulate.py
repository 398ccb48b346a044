"""Close the hand on one object at every pose of the grid; write its contacts table."""

from synergrasp import table_contracts
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.simulation.closure import SimulateParams, simulate_object
from synergrasp.simulation.placement import searched_placement

with job_log(snakemake.log[0]):
    sim = SimulateParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    placement = sim.placement
    if placement.mode == "searched":
        placement = searched_placement(placement, table_contracts.read_csv(table_contracts.PLACEMENT, snakemake.input.search))
    table = simulate_object(hand, sim.synergies(hand.joint_names), sim.object, placement, sim.closure, mechanics=sim.mechanics)
    table_contracts.write(table_contracts.CONTACTS, table, snakemake.output[0])
