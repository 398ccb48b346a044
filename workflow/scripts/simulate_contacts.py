"""Close the hand on one object at every pose of the grid; write its contacts table."""

from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.simulation.closure import SimulateParams, simulate_object
from synergrasp.simulation.contacts import write_contacts

with job_log(snakemake.log[0]):
    sim = SimulateParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    table = simulate_object(hand, sim.synergies(hand.joint_names), sim.object, sim.placement, sim.closure,
                            mechanics=sim.mechanics)
    write_contacts(table, snakemake.output[0])
