"""Close the hand on one object at every pose of the grid; write its contacts table."""

from synergrasp.config import step_params
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.simulation.closure import simulate_object
from synergrasp.simulation.contacts import write_contacts

with job_log(snakemake.log[0]):
    sim = step_params(snakemake.params.cfg, "simulate", snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    synergies = load_synergies(sim.synergies, joint_names=hand.joint_names)
    table = simulate_object(hand, synergies, sim.object, sim.placement, sim.closure, mechanics=sim.mechanics)
    write_contacts(table, snakemake.output[0])
