"""Close the hand on one object at every pose of the grid; write its contacts table."""

from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.simulation.closure import ClosureParams, simulate_object
from synergrasp.simulation.contacts import write_contacts
from synergrasp.simulation.objects import boxes_from_config
from synergrasp.simulation.placement import Placement

with job_log(snakemake.log[0]):
    sim = snakemake.params.sim
    obj = dict(sim["object"])
    placement = Placement.from_config(obj.pop("placement"), sim["grid"])
    (box,) = boxes_from_config([obj])
    hand = load_hand(sim["hand"])
    synergies = load_synergies(sim["synergies"], joint_names=hand.joint_names)
    table = simulate_object(hand, synergies, box, placement, ClosureParams.from_config(sim["closure"]),
                            mechanics=sim.get("mechanics"))
    write_contacts(table, snakemake.output[0])
